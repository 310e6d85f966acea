#include "core/compare/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/Error.h"
#include "core/compare/CompareConstants.h"
#include "core/compare/Ssim.h"

namespace volref::compare {

namespace {

void check_same_shape(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height || a.channel_count() != b.channel_count())
        throw Error("images differ in size or channels: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                    "x" + std::to_string(a.channel_count()) + " and " + std::to_string(b.width) + "x" +
                    std::to_string(b.height) + "x" + std::to_string(b.channel_count()));
}

}  // namespace

double psnr_db(double mse) {
    if (mse <= 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(kPsnrPeak * kPsnrPeak / mse);
}

ImageMetrics measure_difference(const Image& a, const Image& b, const std::vector<double>& tolerance,
                                bool with_ssim) {
    check_same_shape(a, b);
    const std::size_t nc = a.channel_count();
    const std::size_t pixels = std::size_t(a.width) * std::size_t(a.height);
    if (!tolerance.empty() && tolerance.size() != pixels * nc)
        throw Error("tolerance map has " + std::to_string(tolerance.size()) + " values for " +
                    std::to_string(pixels * nc));

    ImageMetrics m;
    m.pixels = long(pixels);
    m.channels.resize(nc);
    std::vector<double> sum_abs(nc, 0.0), sum_sq(nc, 0.0);
    for (std::size_t p = 0; p < pixels; ++p) {
        bool any_over = false;
        for (std::size_t c = 0; c < nc; ++c) {
            const std::size_t i = p * nc + c;
            const double d = std::abs(a.pixels[i] - b.pixels[i]);
            ChannelMetrics& cm = m.channels[c];
            cm.max_abs = std::max(cm.max_abs, d);
            sum_abs[c] += d;
            sum_sq[c] += d * d;
            const double tol = tolerance.empty() ? 0.0 : tolerance[i];
            // NaN differences count as over the tolerance (!(d <= tol)).
            if (!(d <= tol)) {
                ++cm.over;
                any_over = true;
            }
            if (std::isnan(d)) cm.max_abs = d;
        }
        if (any_over) ++m.overall.over;
    }
    double total_abs = 0.0, total_sq = 0.0, ssim_sum = 0.0;
    bool have_ssim = with_ssim;
    for (std::size_t c = 0; c < nc; ++c) {
        ChannelMetrics& cm = m.channels[c];
        cm.name = a.channels[c];
        cm.mean_abs = sum_abs[c] / double(pixels);
        const double mse = sum_sq[c] / double(pixels);
        cm.rmse = std::sqrt(mse);
        cm.psnr = psnr_db(mse);
        if (with_ssim) cm.ssim = ssim(a, b, c);
        if (cm.ssim) ssim_sum += *cm.ssim;
        else have_ssim = false;
        m.overall.max_abs = std::isnan(cm.max_abs) ? cm.max_abs : std::max(m.overall.max_abs, cm.max_abs);
        total_abs += sum_abs[c];
        total_sq += sum_sq[c];
    }
    m.overall.name = "all";
    const double n = double(pixels) * double(nc);
    m.overall.mean_abs = total_abs / n;
    m.overall.rmse = std::sqrt(total_sq / n);
    m.overall.psnr = psnr_db(total_sq / n);
    if (have_ssim && nc > 0) m.overall.ssim = ssim_sum / double(nc);
    return m;
}

std::vector<double> max_abs_difference_map(const Image& a, const Image& b) {
    check_same_shape(a, b);
    const std::size_t nc = a.channel_count();
    const std::size_t pixels = std::size_t(a.width) * std::size_t(a.height);
    std::vector<double> out(pixels, 0.0);
    for (std::size_t p = 0; p < pixels; ++p)
        for (std::size_t c = 0; c < nc; ++c) {
            const double d = std::abs(a.pixels[p * nc + c] - b.pixels[p * nc + c]);
            out[p] = std::isnan(d) ? d : std::max(out[p], d);
        }
    return out;
}

}  // namespace volref::compare
