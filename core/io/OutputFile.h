// What every writer of volref does before and while writing a file (images, volumes): fail early on a
// bad output folder, and write under a temporary name in the same folder, renamed into place when
// complete, so a failed or interrupted run never leaves a partial file under the requested name.
#pragma once
#include <filesystem>

namespace volref {

// Throws Error unless the folder of `path` exists and is writable and `path` is not a folder.
void check_output_folder(const std::filesystem::path& path);

// ".NAME.volref-tmp-PID.EXT" beside `path`: hidden, unique per process, same extension (OIIO picks
// the format by it).
std::filesystem::path temporary_output_path(const std::filesystem::path& path);

// Puts the finished temporary file `tmp` in place as `path` (rename(2): atomic within one folder, so a
// reader, or a second writer of the same path, only ever sees a whole file). If a cancel was requested
// while writing (core/Cancellation.h) the file is not put in place: `tmp` is removed and Cancelled is
// thrown. A failed rename removes `tmp` and throws Error "PATH: cannot move the finished file into place".
void commit_output(const std::filesystem::path& tmp, const std::filesystem::path& path);

}  // namespace volref
