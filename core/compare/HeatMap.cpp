#include "core/compare/HeatMap.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "core/film/ImageWriter.h"
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
    // Opaque RGBA through volref's own PNG writer (atomic; over an opaque pixel the background does not
    // matter; each value stored as round(255 v)).
    Image image(width, height, {"R", "G", "B", "A"});
    for (std::size_t p = 0; p < difference.size(); ++p) {
        const double d = difference[p];
        const auto c = hot_colour(std::isnan(d) ? 1.0 : (scale > 0.0 ? d / scale : 0.0));
        for (std::size_t k = 0; k < 3; ++k) image.pixels[p * 4 + k] = c[k];
        image.pixels[p * 4 + 3] = 1.0;
    }
    write_image(image, path, glm::dvec4(0.0));
}

}  // namespace volref::compare
