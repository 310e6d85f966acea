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

}  // namespace volref
