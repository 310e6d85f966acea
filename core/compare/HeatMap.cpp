#include "core/compare/HeatMap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "core/Error.h"
#include "core/io/OutputFile.h"

namespace volref::compare {

namespace fs = std::filesystem;

std::array<double, 3> hot_colour(double t) {
    t = std::clamp(t, 0.0, 1.0);
    return {std::min(1.0, 3.0 * t), std::clamp(3.0 * t - 1.0, 0.0, 1.0), std::clamp(3.0 * t - 2.0, 0.0, 1.0)};
}

void check_heatmap_path(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".png") throw Error(path.string() + ": --heatmap writes PNG: use a .png name");
    check_output_folder(path);
}

void write_heatmap(const std::vector<double>& difference, int width, int height, double scale, const fs::path& path) {
    check_heatmap_path(path);
    std::vector<std::uint8_t> rgb(std::size_t(width) * std::size_t(height) * 3);
    for (std::size_t p = 0; p < difference.size(); ++p) {
        const double d = difference[p];
        const double t = std::isnan(d) ? 1.0 : (scale > 0.0 ? d / scale : 0.0);
        const auto c = hot_colour(t);
        for (int k = 0; k < 3; ++k) rgb[p * 3 + std::size_t(k)] = std::uint8_t(std::lround(c[std::size_t(k)] * 255.0));
    }
    const fs::path tmp = temporary_output_path(path);
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw Error(path.string() + ": cannot create an image writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    std::error_code ec;
    if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) || !out->close()) {
        const std::string why = out->geterror();
        fs::remove(tmp, ec);
        throw Error(path.string() + ": cannot write the heat map: " + why);
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error(path.string() + ": cannot move the finished heat map into place: " + ec.message());
    }
}

}  // namespace volref::compare
