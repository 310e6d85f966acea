// The image-file module, libvolref_image_files.so: the only code that calls OpenImageIO. It is a
// plugin (a CMake MODULE), loaded by libvolref_tools the first time an image file is written or read
// (ImageFileModule.h), so that a process which writes no image (volref --help, info, trace, a render to
// .img, the unit tests) starts without OpenImageIO's 260 libraries: linking them cost 0.4 s a process
// start (0.8 s under the sanitizers) on the development machine (docs/performance.md, "Start-up").
//
// The interface is two C entry points over the plain structs below; the formats' conventions (which
// pixels, which channels, premultiplied or not) stay in libvolref_tools (ImageWriter.cpp,
// ComparedImage.cpp), so the module only moves pixels between memory and a file.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace volref::image_files {

// The interface's version: the loader refuses a module that reports another.
inline constexpr int kInterfaceVersion = 1;

enum class SampleKind : int { Float32 = 0, UInt8 = 1, UInt16 = 2 };

// An image to write: width x height pixels of `channels` interleaved samples of `kind`, row 0 at the top.
struct WriteRequest {
    const char* path = nullptr;                // the file to create (the caller's temporary name)
    int width = 0, height = 0, channels = 0;
    const char* const* channel_names = nullptr;  // `channels` names
    SampleKind kind = SampleKind::Float32;
    const void* pixels = nullptr;
    int alpha_channel = -1, z_channel = -1;    // -1: none
    int unassociated_alpha = 0;                // 1: colour stored divided by alpha (PNG, TIFF)
    const char* compression = nullptr;         // e.g. "zip" (EXR); nullptr: the format's default
};

// An image read: every channel as double, in the file's channel order. 8- and 16-bit samples are
// read as stored and scaled here in double, v / (2^bits - 1) (OpenImageIO's own conversion to double
// goes through float: errors of 6e-8 on 8-bit values); anything else is converted by OpenImageIO.
struct ReadResult {
    int width = 0, height = 0;
    // Filled by the module through these callbacks (so that no allocator crosses the boundary).
    void* owner = nullptr;
    void (*add_channel_name)(void* owner, const char* name) = nullptr;
    double* (*pixels)(void* owner, std::size_t count) = nullptr;  // storage for `count` doubles
    int bits = 0;                 // bits per integer sample (8 for PNG), 0 for floating point
    int unassociated_alpha = 0;   // the file stores colour divided by alpha
};

// A C entry point's message: `message` copied into error[0, size), cut to fit, NUL-terminated (the
// plugin's entry points and ImageWriter.h's volref_check_output_path / volref_write_image).
inline void copy_message(std::string_view message, char* error, std::size_t size) {
    if (size == 0) return;
    const std::size_t n = std::min(size - 1, message.size());
    std::copy(message.begin(), message.begin() + std::ptrdiff_t(n), error);
    error[n] = '\0';
}

}  // namespace volref::image_files

// Each returns 0, or 1 with a one-line message in error[0, size) (NUL-terminated, cut to fit).
extern "C" int volref_image_files_version();
extern "C" int volref_image_files_write(const volref::image_files::WriteRequest* request, char* error, std::size_t size);
extern "C" int volref_image_files_read(const char* path, volref::image_files::ReadResult* result, char* error,
                                       std::size_t size);
