// volref-mpi's output, written by rank 0: OUT ending in ".img" is the pixels as doubles (the tests'
// format) and is written here; any other format goes through libvolref_tools (core/film/ImageWriter.h),
// loaded at run time on rank 0 only. So no rank links OpenImageIO, whose 280 libraries take a rank
// longer to load than a small frame takes to render (docs/performance.md, "Two ranks
// against one").
#pragma once
#include <string>

#include <glm/vec4.hpp>

#include "core/film/Image.h"

namespace volref::mpi {

// Throws Error unless OUT can be written (".img", or a format libvolref_tools writes to a writable folder).
void check_output(const std::string& path);
// Writes the image (to a temporary name, renamed into place); throws Error naming OUT on failure.
void write_output(const Image& image, const std::string& path, const glm::dvec4& background);

}  // namespace volref::mpi
