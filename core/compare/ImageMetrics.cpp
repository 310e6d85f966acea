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

bool finite_pixel(const Image& im, std::size_t p, std::size_t nc) {
    for (std::size_t c = 0; c < nc; ++c)
        if (!std::isfinite(im.pixels[p * nc + c])) return false;
    return true;
}

// Both NaN, or both the same infinity.
bool non_finite_agree(double x, double y) { return (std::isnan(x) && std::isnan(y)) || (std::isinf(x) && x == y); }

}  // namespace

void finite_copies(const Image& a, const Image& b, Image& a_out, Image& b_out) {
    check_same_shape(a, b);
    a_out = a;
    b_out = b;
    const std::size_t nc = a.channel_count(), pixels = std::size_t(a.width) * std::size_t(a.height);
    for (std::size_t p = 0; p < pixels; ++p)
        if (!finite_pixel(a, p, nc) || !finite_pixel(b, p, nc))
            for (std::size_t c = 0; c < nc; ++c) a_out.pixels[p * nc + c] = b_out.pixels[p * nc + c] = 0.0;
}

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
    std::vector<double> sum_abs(nc, 0.0), sum_sq(nc, 0.0), finite(nc, 0.0);
    for (std::size_t p = 0; p < pixels; ++p) {
        bool any_over = false, disagree = false;
        if (!finite_pixel(a, p, nc)) ++m.non_finite_a;
        if (!finite_pixel(b, p, nc)) ++m.non_finite_b;
        for (std::size_t c = 0; c < nc; ++c) {
            const std::size_t i = p * nc + c;
            ChannelMetrics& cm = m.channels[c];
            if (!std::isfinite(a.pixels[i]) || !std::isfinite(b.pixels[i])) {  // never in the sums
                if (!non_finite_agree(a.pixels[i], b.pixels[i])) {
                    ++cm.over;
                    any_over = disagree = true;
                }
                continue;
            }
            finite[c] += 1.0;
            const double d = std::abs(a.pixels[i] - b.pixels[i]);
            cm.max_abs = std::max(cm.max_abs, d);
            sum_abs[c] += d;
            sum_sq[c] += d * d;
            const double tol = tolerance.empty() ? 0.0 : tolerance[i];
            // NaN differences count as over the tolerance (!(d <= tol)).
            if (!(d <= tol)) {
                ++cm.over;
                any_over = true;
            }
        }
        if (any_over) ++m.overall.over;
        if (disagree) ++m.non_finite_disagree;
    }
    const bool any_non_finite = m.non_finite_a > 0 || m.non_finite_b > 0;
    Image fa, fb;
    if (with_ssim && any_non_finite) finite_copies(a, b, fa, fb);
    const Image& sa = with_ssim && any_non_finite ? fa : a;
    const Image& sb = with_ssim && any_non_finite ? fb : b;
    double total_abs = 0.0, total_sq = 0.0, ssim_sum = 0.0;
    bool have_ssim = with_ssim;
    for (std::size_t c = 0; c < nc; ++c) {
        ChannelMetrics& cm = m.channels[c];
        cm.name = a.channels[c];
        cm.mean_abs = finite[c] > 0.0 ? sum_abs[c] / finite[c] : 0.0;
        const double mse = finite[c] > 0.0 ? sum_sq[c] / finite[c] : 0.0;
        cm.rmse = std::sqrt(mse);
        cm.psnr = psnr_db(mse);
        if (with_ssim) cm.ssim = ssim(sa, sb, c);
        if (cm.ssim) ssim_sum += *cm.ssim;
        else have_ssim = false;
        m.overall.max_abs = std::max(m.overall.max_abs, cm.max_abs);
        total_abs += sum_abs[c];
        total_sq += sum_sq[c];
    }
    m.overall.name = "all";
    double n = 0.0;
    for (double f : finite) n += f;
    n = std::max(n, 1.0);
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
            const double x = a.pixels[p * nc + c], y = b.pixels[p * nc + c];
            if (!std::isfinite(x) || !std::isfinite(y)) {
                if (!non_finite_agree(x, y)) out[p] = std::numeric_limits<double>::quiet_NaN();  // white
                continue;
            }
            if (!std::isnan(out[p])) out[p] = std::max(out[p], std::abs(x - y));
        }
    return out;
}

}  // namespace volref::compare
