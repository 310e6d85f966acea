#include "core/compare/Ssim.h"

#include <cmath>

#include "core/compare/CompareConstants.h"

namespace volref::compare {

std::vector<double> ssim_window_1d() {
    const int half = kSsimWindow / 2;
    std::vector<double> g(static_cast<std::size_t>(kSsimWindow));
    double sum = 0.0;
    for (int k = -half; k <= half; ++k) {
        g[std::size_t(k + half)] = std::exp(-double(k) * double(k) / (2.0 * kSsimSigma * kSsimSigma));
        sum += g[std::size_t(k + half)];
    }
    for (double& v : g) v /= sum;
    return g;
}

std::optional<double> ssim(const Image& a, const Image& b, std::size_t channel) {
    const int n = kSsimWindow;
    const int w = a.width, h = a.height;
    if (w < n || h < n) return std::nullopt;
    const std::vector<double> g = ssim_window_1d();
    const int ow = w - n + 1, oh = h - n + 1;  // "valid" window positions

    // The five weighted moments sum w f for f = a, b, a^2, b^2, a b, by separable filtering:
    // rows first (valid in x), then columns (valid in y).
    enum { kA, kB, kAA, kBB, kAB, kMoments };
    auto value = [&](int x, int y, int m) {
        const double va = a.at(x, y, channel), vb = b.at(x, y, channel);
        switch (m) {
            case kA: return va;
            case kB: return vb;
            case kAA: return va * va;
            case kBB: return vb * vb;
            default: return va * vb;
        }
    };
    std::vector<double> rows(std::size_t(kMoments) * std::size_t(ow) * std::size_t(h));
    auto row_at = [&](int m, int x, int y) -> double& {
        return rows[(std::size_t(m) * std::size_t(h) + std::size_t(y)) * std::size_t(ow) + std::size_t(x)];
    };
    for (int m = 0; m < kMoments; ++m)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < ow; ++x) {
                double s = 0.0;
                for (int k = 0; k < n; ++k) s += g[std::size_t(k)] * value(x + k, y, m);
                row_at(m, x, y) = s;
            }

    const double c1 = (kSsimK1 * kSsimDynamicRange) * (kSsimK1 * kSsimDynamicRange);
    const double c2 = (kSsimK2 * kSsimDynamicRange) * (kSsimK2 * kSsimDynamicRange);
    double total = 0.0;
    for (int y = 0; y < oh; ++y)
        for (int x = 0; x < ow; ++x) {
            double mom[kMoments];
            for (int m = 0; m < kMoments; ++m) {
                double s = 0.0;
                for (int k = 0; k < n; ++k) s += g[std::size_t(k)] * row_at(m, x, y + k);
                mom[m] = s;
            }
            const double mu_a = mom[kA], mu_b = mom[kB];
            const double var_a = mom[kAA] - mu_a * mu_a, var_b = mom[kBB] - mu_b * mu_b;
            const double cov = mom[kAB] - mu_a * mu_b;
            total += (2.0 * mu_a * mu_b + c1) * (2.0 * cov + c2) /
                     ((mu_a * mu_a + mu_b * mu_b + c1) * (var_a + var_b + c2));
        }
    return total / (double(ow) * double(oh));
}

}  // namespace volref::compare
