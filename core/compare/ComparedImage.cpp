#include "core/compare/ComparedImage.h"
#include "core/film/Background.h"

#include <algorithm>
#include <cstdint>

#include "core/Error.h"
#include "core/film/ImageFileModule.h"
#include "core/InputFile.h"

namespace volref::compare {

namespace {

int find_channel(const image_files::ReadImage& image, const std::string& name) {
    for (std::size_t c = 0; c < image.channels.size(); ++c)
        if (image.channels[c] == name) return int(c);
    return -1;
}

}  // namespace

std::string ComparedImage::description() const {
    std::string s = std::to_string(rgba.width) + "x" + std::to_string(rgba.height) + ", ";
    s += bits > 0 ? std::to_string(bits) + "-bit" : std::string("float");
    s += unassociated ? ", unassociated alpha (premultiplied here)" : ", premultiplied";
    if (!error.empty()) s += ", error channel";
    return s;
}

ComparedImage read_compared_image(const std::filesystem::path& path, const std::optional<glm::dvec4>& background) {
    const std::string name = path.string();
    io::check_input_file(path, name);  // a FIFO or /dev/zero is refused before OpenImageIO opens it
    // The stored values (unassociated alpha not premultiplied: done here in double); 8- and 16-bit
    // samples scaled in double (ImageFiles.h).
    const image_files::ReadImage file = image_files::read(name);
    const int w = file.width, h = file.height, n = int(file.channels.size());
    const std::vector<double>& data = file.pixels;

    int rgb[3] = {find_channel(file, "R"), find_channel(file, "G"), find_channel(file, "B")};
    if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
        const int y = find_channel(file, "Y");
        if (y < 0) throw Error(name + ": no R, G, B (or Y) channels to compare");
        rgb[0] = rgb[1] = rgb[2] = y;
    }
    const int a = find_channel(file, "A");
    const int e = find_channel(file, "error");
    const int fault = find_channel(file, "fault");

    ComparedImage out;
    out.path = path;
    out.bits = file.bits;
    out.unassociated = a >= 0 && file.unassociated_alpha;
    out.rgba = Image(w, h, {"R", "G", "B", "A"});
    if (out.unassociated && out.bits > 0) out.stored.resize(std::size_t(w) * std::size_t(h) * 4);
    if (e >= 0) out.error.resize(std::size_t(w) * std::size_t(h));
    if (fault >= 0) out.fault.resize(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const double* px = &data[p * std::size_t(n)];
            const double alpha = a >= 0 ? px[a] : 1.0;
            double c[4] = {px[rgb[0]], px[rgb[1]], px[rgb[2]], alpha};
            if (!out.stored.empty())
                for (int k = 0; k < 4; ++k) out.stored[p * 4 + std::size_t(k)] = c[k];
            if (out.unassociated)
                for (int k = 0; k < 3; ++k) c[k] *= alpha;  // C = u a
            else if (background)  // composite an associated input
                composite_over_background(c, *background);
            for (int k = 0; k < 4; ++k) out.rgba.at(x, y, std::size_t(k)) = c[k];
            if (e >= 0) out.error[p] = px[e];
            if (fault >= 0) out.fault[p] = px[fault] != 0.0;
        }
    return out;
}

std::vector<std::array<int, 2>> exclude_faults(ComparedImage& a, ComparedImage& b) {
    std::vector<std::array<int, 2>> out;
    if (a.fault.empty() && b.fault.empty()) return out;
    const int w = std::min(a.rgba.width, b.rgba.width), h = std::min(a.rgba.height, b.rgba.height);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
            if (!((!a.fault.empty() && a.fault[p]) || (!b.fault.empty() && b.fault[p]))) continue;
            out.push_back({x, y});
            for (std::size_t c = 0; c < 4; ++c) a.rgba.at(x, y, c) = b.rgba.at(x, y, c) = 0.0;
            if (!a.error.empty()) a.error[p] = 0.0;
            if (!b.error.empty()) b.error[p] = 0.0;
        }
    return out;
}

}  // namespace volref::compare
