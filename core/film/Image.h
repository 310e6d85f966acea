// Image: the rendered pixels in double, channels interleaved: R, G, B, A (premultiplied) and any
// extra channels (e.g. "Z" for first-hit depth). Row 0 is the top row.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace volref {

struct Image {
    int width = 0, height = 0;
    std::vector<std::string> channels{"R", "G", "B", "A"};
    std::vector<double> pixels;  // width * height * channels.size()

    Image() = default;
    Image(int w, int h, std::vector<std::string> names)
        : width(w), height(h), channels(std::move(names)), pixels(std::size_t(w) * std::size_t(h) * channels.size(), 0.0) {}

    std::size_t channel_count() const { return channels.size(); }
    double& at(int x, int y, std::size_t c) {
        return pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels.size() + c];
    }
    double at(int x, int y, std::size_t c) const {
        return pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels.size() + c];
    }
};

}  // namespace volref
