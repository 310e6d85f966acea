// Loads libvolref_image_files.so (ImageFiles.h) at the first image file written or read, from the
// folder libvolref_tools itself was loaded from (the build folder, or the installed lib/ folder),
// and calls it. Part of libvolref_tools.
#pragma once
#include <string>
#include <vector>

#include "core/film/ImageFiles.h"

namespace volref::image_files {

// Loads the module now (once per process); throws Error("<shown_path>: ...") when it cannot.
void require(const std::string& shown_path);

// Writes `request` (its path included); throws Error("<shown_path>: <the module's message>").
void write(const WriteRequest& request, const std::string& shown_path);

// A file's channels and pixels (ReadResult's fields, owned).
struct ReadImage {
    int width = 0, height = 0;
    std::vector<std::string> channels;
    std::vector<double> pixels;  // width * height * channels.size(), interleaved
    int bits = 0;
    bool unassociated_alpha = false;
};
// Reads `path`; throws Error("<path>: <the module's message>").
ReadImage read(const std::string& path);

}  // namespace volref::image_files
