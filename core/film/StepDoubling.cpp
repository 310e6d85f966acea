#include "core/film/StepDoubling.h"

#include <algorithm>
#include <cmath>

#include "core/Conventions.h"
#include "core/Error.h"

namespace volref {

double step_doubling_bound(double difference) {
    return conventions::kStepDoublingSafety * (4.0 / 3.0) * std::fabs(difference);
}

Image with_step_doubling_error(const Image& coarse, const Image& fine) {
    if (coarse.width != fine.width || coarse.height != fine.height || coarse.channel_count() < 4 ||
        fine.channel_count() < 4)
        throw Error("step doubling: the images at h and h / 2 differ in size");
    std::vector<std::string> names = coarse.channels;
    names.push_back("error");
    Image out(coarse.width, coarse.height, names);
    const std::size_t n = coarse.channel_count();
    const int W = coarse.width, H = coarse.height;
    std::vector<double> d(std::size_t(W) * std::size_t(H), 0.0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            double& m = d[std::size_t(y) * std::size_t(W) + std::size_t(x)];
            for (std::size_t c = 0; c < 4; ++c) m = std::max(m, std::fabs(coarse.at(x, y, c) - fine.at(x, y, c)));
            for (std::size_t c = 0; c < n; ++c) out.at(x, y, c) = coarse.at(x, y, c);
        }
    // The largest difference over the pixel's 3 x 3 neighbourhood (kStepDoublingNeighbourhood).
    const int r = conventions::kStepDoublingNeighbourhood;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            double m = 0.0;
            for (int yy = std::max(0, y - r); yy <= std::min(H - 1, y + r); ++yy)
                for (int xx = std::max(0, x - r); xx <= std::min(W - 1, x + r); ++xx)
                    m = std::max(m, d[std::size_t(yy) * std::size_t(W) + std::size_t(xx)]);
            out.at(x, y, n) = step_doubling_bound(m);
        }
    return out;
}

}  // namespace volref
