// Writing images through OpenImageIO (conventions section 10; the plugin of ImageFiles.h), by the output's extension:
//   .exr          linear float, premultiplied RGBA plus the extra channels (Z, ...)
//   .png          8-bit RGBA, .tif/.tiff 16-bit RGBA: the image composited over the background
//                 (premultiplied: C' = C + (1 - A) bg_a bg_rgb, A' = A + (1 - A) bg_a), stored as
//                 PNG/TIFF store it, unassociated: rgb = C' / A' (0 where A' = 0), alpha = A';
//                 q = round(clamp(v, 0, 1) * (2^bits - 1)). Extra channels are not written.
// The file is written to a temporary name in the same folder and renamed into place, so a failed
// or interrupted run never leaves a partial file under the requested name.
#pragma once
#include <cstddef>
#include <filesystem>

#include <glm/vec4.hpp>

#include "core/film/Image.h"

namespace volref {

// Throws Error unless `path` has a supported extension, its folder exists and is writable, and the
// image-file plugin loads (ImageFileModule.h).
// Called before rendering so that a bad output path fails fast.
void check_output_path(const std::filesystem::path& path);

void write_image(const Image& image, const std::filesystem::path& path, const glm::dvec4& background);

}  // namespace volref

// The two functions above with C names, for a program that loads libvolref_tools at run time instead of
// linking it (volref-mpi: cli/mpi/ImageOutput.cpp; its ranks then start without OpenImageIO's 280
// libraries). Each returns 0, or 1 with the Error's message in `error` (NUL-terminated, cut to `size`).
extern "C" int volref_check_output_path(const char* path, char* error, std::size_t size);
extern "C" int volref_write_image(const volref::Image* image, const char* path, const double background[4], char* error,
                                  std::size_t size);
