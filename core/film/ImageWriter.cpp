#include "core/film/ImageWriter.h"

#include "core/film/Background.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <system_error>

#include "core/Error.h"
#include "core/film/ImageFileModule.h"
#include "core/io/OutputFile.h"

namespace volref {

namespace fs = std::filesystem;

namespace {

enum class Format { Exr, Png, Tiff };

Format format_of(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".exr") return Format::Exr;
    if (ext == ".png") return Format::Png;
    if (ext == ".tif" || ext == ".tiff") return Format::Tiff;
    throw Error(path.string() + ": unsupported output extension '" + ext + "' (use .exr, .png, .tif or .tiff)");
}

// 8/16-bit pixels: composited over the background, unassociated alpha, quantised.
template <typename T>
std::vector<T> quantised_over_background(const Image& image, const glm::dvec4& bg) {
    constexpr double kMax = double(std::numeric_limits<T>::max());
    auto q = [](double v) { return T(std::lround(std::clamp(v, 0.0, 1.0) * kMax)); };
    std::vector<T> out(std::size_t(image.width) * std::size_t(image.height) * 4);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            double px[4] = {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2), image.at(x, y, 3)};
            composite_over_background(px, bg);  // Background.h
            const double a = px[3];
            T* p = &out[(std::size_t(y) * std::size_t(image.width) + std::size_t(x)) * 4];
            for (int c = 0; c < 3; ++c) p[c] = q(a > 0.0 ? px[c] / a : 0.0);
            p[3] = q(a);
        }
    return out;
}

}  // namespace

void check_output_path(const fs::path& path) {
    format_of(path);
    check_output_folder(path);
    image_files::require(path.string());  // before a render, not after it
}

void write_image(const Image& image, const fs::path& path, const glm::dvec4& background) {
    check_output_path(path);
    const Format format = format_of(path);
    const fs::path tmp = temporary_output_path(path);

    image_files::WriteRequest rq;
    const std::string tmp_name = tmp.string();
    rq.path = tmp_name.c_str();
    rq.width = image.width;
    rq.height = image.height;
    rq.alpha_channel = 3;
    std::vector<const char*> names;
    std::vector<float> floats;
    std::vector<std::uint8_t> bytes;
    std::vector<std::uint16_t> words;
    if (format == Format::Exr) {
        rq.channels = int(image.channel_count());
        for (std::size_t c = 0; c < image.channels.size(); ++c) {
            names.push_back(image.channels[c].c_str());
            if (image.channels[c] == "Z") rq.z_channel = int(c);
        }
        rq.kind = image_files::SampleKind::Float32;
        rq.compression = "zip";
        floats.assign(image.pixels.begin(), image.pixels.end());
        rq.pixels = floats.data();
    } else {
        const bool png = format == Format::Png;
        rq.channels = 4;
        names = {"R", "G", "B", "A"};
        rq.unassociated_alpha = 1;
        rq.kind = png ? image_files::SampleKind::UInt8 : image_files::SampleKind::UInt16;
        if (png) {
            bytes = quantised_over_background<std::uint8_t>(image, background);
            rq.pixels = bytes.data();
        } else {
            words = quantised_over_background<std::uint16_t>(image, background);
            rq.pixels = words.data();
        }
    }
    rq.channel_names = names.data();
    // (The module writes no clock into the file: the same render gives the same bytes.)
    try {
        image_files::write(rq, path.string());
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    commit_output(tmp, path);
}

}  // namespace volref

namespace {
// Runs f; 0, or 1 with the exception's message copied into error[0, size).
template <class F>
int with_message(F&& f, char* error, std::size_t size) {
    try {
        f();
        return 0;
    } catch (const std::exception& e) {
        volref::image_files::copy_message(e.what(), error, size);
        return 1;
    }
}
}  // namespace

extern "C" int volref_check_output_path(const char* path, char* error, std::size_t size) {
    return with_message([&] { volref::check_output_path(path); }, error, size);
}

extern "C" int volref_write_image(const volref::Image* image, const char* path, const double background[4], char* error,
                                  std::size_t size) {
    return with_message([&] {
        volref::write_image(*image, path, glm::dvec4(background[0], background[1], background[2], background[3]));
    }, error, size);
}
