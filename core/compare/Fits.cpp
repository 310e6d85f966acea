// Debian's Ceres is built with 16-byte Eigen alignment; objects shared with it must agree.
#ifndef EIGEN_MAX_ALIGN_BYTES
#define EIGEN_MAX_ALIGN_BYTES 16
#endif

#include "core/compare/Fits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>
#include <glog/logging.h>

#include "core/Error.h"
#include "core/compare/CompareConstants.h"
#include "core/compare/ImageMetrics.h"

namespace volref::compare {

namespace {

// Ceres logs through glog: keep it silent (only errors that abort would print).
void quiet_logging() {
    static std::once_flag once;
    std::call_once(once, [] { FLAGS_minloglevel = google::GLOG_FATAL; });
}

ceres::Solver::Options solver_options() {
    ceres::Solver::Options o;
    o.linear_solver_type = ceres::DENSE_QR;
    o.logging_type = ceres::SILENT;
    o.minimizer_progress_to_stdout = false;
    o.max_num_iterations = 200;
    o.function_tolerance = 1e-16;
    o.gradient_tolerance = 1e-16;
    o.parameter_tolerance = 1e-14;
    o.num_threads = 1;  // deterministic
    return o;
}

void solve(ceres::Problem& problem) {
    quiet_logging();
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options(), &problem, &summary);
    if (summary.termination_type == ceres::FAILURE)
        throw Error("least-squares fit failed: " + summary.message);
}

std::size_t pixel_count(const Image& a) { return std::size_t(a.width) * std::size_t(a.height); }

// Every k-th pixel, k = ceil(N / kFitMaxPixels): at most kFitMaxPixels pixels enter a fit.
std::size_t fit_stride(std::size_t n) {
    const std::size_t max = std::size_t(kFitMaxPixels);
    return std::max<std::size_t>(1, (n + max - 1) / max);
}

std::string format(const char* fmt, double a, double b = 0.0) {
    char buf[128];
    std::snprintf(buf, sizeof buf, fmt, a, b);
    return buf;
}

// ---- gain: B_rgb = g A_rgb --------------------------------------------------------------------
struct GainResidual {
    const double* a;
    const double* b;
    template <typename T>
    bool operator()(const T* g, T* r) const {
        for (int c = 0; c < 3; ++c) r[c] = T(b[c]) - g[0] * T(a[c]);
        return true;
    }
};

// ---- opacity: B_a = 1 - (1 - A_a)^k, B_rgb = A_rgb B_a / A_a ------------------------------------------
// (1 - (1 - alpha)^k) / alpha = -expm1(k log1p(-alpha)) / alpha, for 0 < alpha < 1.
template <typename T>
T opacity_ratio(double alpha, const T& k) {
    using std::expm1;
    return -expm1(k * std::log1p(-alpha)) / alpha;
}

bool depends_on_opacity_exponent(double alpha) { return alpha > 0.0 && alpha < 1.0; }

// Fitted on alpha alone: B_a - (1 - (1 - A_a)^k) = B_a - A_a ratio.
struct OpacityResidual {
    double a_alpha, b_alpha;
    template <typename T>
    bool operator()(const T* k, T* r) const {
        r[0] = T(b_alpha) - T(a_alpha) * opacity_ratio(a_alpha, k[0]);
        return true;
    }
};

// ---- shift: B(x, y) = A(x - sx, y - sy) -------------------------------------------------------------
using Grid = ceres::Grid2D<double, 4>;
using Interpolator = ceres::BiCubicInterpolator<Grid>;

struct ShiftResidual {
    const Interpolator* a;
    const double* b;
    double x, y;
    template <typename T>
    bool operator()(const T* s, T* r) const {
        T v[4];
        a->Evaluate(T(y) - s[1], T(x) - s[0], v);  // (row, column)
        for (int c = 0; c < 4; ++c) r[c] = T(b[c]) - v[c];
        return true;
    }
};

int shift_margin() { return int(std::ceil(kMaxShiftPixels)); }

}  // namespace

ModelFit fit_gain(const Image& a, const Image& b) {
    ModelFit fit;
    fit.model = "gain";
    const std::size_t n = pixel_count(a);
    double g = 1.0;
    ceres::Problem problem;
    for (std::size_t p = 0; p < n; p += fit_stride(n))
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<GainResidual, 3, 1>(
                                     new GainResidual{&a.pixels[p * 4], &b.pixels[p * 4]}),
                                 nullptr, &g);
    if (n > 0) solve(problem);
    double before = 0.0, after = 0.0;
    for (std::size_t i = 0; i < n * 4; ++i) {
        const double model = i % 4 == 3 ? a.pixels[i] : g * a.pixels[i];
        before += (b.pixels[i] - a.pixels[i]) * (b.pixels[i] - a.pixels[i]);
        after += (b.pixels[i] - model) * (b.pixels[i] - model);
    }
    const double values = std::max<double>(1.0, double(n * 4));
    fit.judged_on = "RGBA";
    fit.rgba_before = fit.residual_before = std::sqrt(before / values);
    fit.rgba_after = fit.residual_after = std::sqrt(after / values);
    fit.values = {g};
    fit.parameters = format("g = %.9g", g);
    fit.fitted = n > 0;
    return fit;
}

ModelFit fit_opacity_exponent(const Image& a, const Image& b) {
    ModelFit fit;
    fit.model = "opacity";
    const std::size_t n = pixel_count(a);
    std::vector<std::size_t> used;
    for (std::size_t p = 0; p < n; ++p)
        if (depends_on_opacity_exponent(a.pixels[p * 4 + 3])) used.push_back(p);
    double k = 1.0;
    if (!used.empty()) {
        ceres::Problem problem;
        for (std::size_t i = 0; i < used.size(); i += fit_stride(used.size()))
            problem.AddResidualBlock(new ceres::AutoDiffCostFunction<OpacityResidual, 1, 1>(new OpacityResidual{
                                         a.pixels[used[i] * 4 + 3], b.pixels[used[i] * 4 + 3]}),
                                     nullptr, &k);
        problem.SetParameterLowerBound(&k, 0, 1e-9);
        solve(problem);
    }
    double before = 0.0, after = 0.0, alpha_before = 0.0, alpha_after = 0.0;
    for (std::size_t p = 0; p < n; ++p) {
        const double alpha = a.pixels[p * 4 + 3];
        const double ratio = depends_on_opacity_exponent(alpha) ? opacity_ratio(alpha, k) : 1.0;
        for (std::size_t c = 0; c < 4; ++c) {
            const double av = a.pixels[p * 4 + c], bv = b.pixels[p * 4 + c];
            before += (bv - av) * (bv - av);
            after += (bv - av * ratio) * (bv - av * ratio);
            if (c == 3) {
                alpha_before += (bv - av) * (bv - av);
                alpha_after += (bv - av * ratio) * (bv - av * ratio);
            }
        }
    }
    const double values = std::max<double>(1.0, double(n * 4));
    fit.judged_on = "alpha";
    fit.rgba_before = std::sqrt(before / values);
    fit.rgba_after = std::sqrt(after / values);
    fit.residual_before = std::sqrt(alpha_before / std::max<double>(1.0, double(n)));
    fit.residual_after = std::sqrt(alpha_after / std::max<double>(1.0, double(n)));
    fit.values = {k};
    fit.parameters = format("k = %.9g", k);
    fit.fitted = !used.empty();
    if (!fit.fitted) fit.note = "A has no semi-transparent pixel (0 < alpha < 1)";
    return fit;
}

ModelFit fit_shift(const Image& a, const Image& b) {
    ModelFit fit;
    fit.model = "shift";
    const int m = shift_margin();
    const int w = a.width, h = a.height;
    if (w < 2 * m + 1 || h < 2 * m + 1) {
        fit.note = "image smaller than " + std::to_string(2 * m + 1) + " pixels";
        fit.values = {0.0, 0.0};
        return fit;
    }
    const Grid grid(a.pixels.data(), 0, h, 0, w);
    const Interpolator interp(grid);
    std::vector<std::size_t> used;
    for (int y = m; y < h - m; ++y)
        for (int x = m; x < w - m; ++x) used.push_back(std::size_t(y) * std::size_t(w) + std::size_t(x));
    double s[2] = {0.0, 0.0};
    ceres::Problem problem;
    for (std::size_t i = 0; i < used.size(); i += fit_stride(used.size())) {
        const std::size_t p = used[i];
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ShiftResidual, 4, 2>(new ShiftResidual{
                                     &interp, &b.pixels[p * 4], double(p % std::size_t(w)), double(p / std::size_t(w))}),
                                 nullptr, s);
    }
    for (int i = 0; i < 2; ++i) {
        problem.SetParameterLowerBound(s, i, -kMaxShiftPixels);
        problem.SetParameterUpperBound(s, i, kMaxShiftPixels);
    }
    solve(problem);
    double before = 0.0, after = 0.0;
    for (const std::size_t p : used) {
        const double x = double(p % std::size_t(w)), y = double(p / std::size_t(w));
        double v[4];
        interp.Evaluate(y - s[1], x - s[0], v);
        for (std::size_t c = 0; c < 4; ++c) {
            const double av = a.pixels[p * 4 + c], bv = b.pixels[p * 4 + c];
            before += (bv - av) * (bv - av);
            after += (bv - v[c]) * (bv - v[c]);
        }
    }
    const double values = double(used.size() * 4);
    fit.judged_on = "RGBA";
    fit.rgba_before = fit.residual_before = std::sqrt(before / values);
    fit.rgba_after = fit.residual_after = std::sqrt(after / values);
    fit.values = {s[0], s[1]};
    fit.parameters = format("sx = %.6g, sy = %.6g pixels", s[0], s[1]);
    fit.fitted = true;
    return fit;
}

ModelFit fit_convention(const ConventionVariant& v, const Image& a_in, const Image& b_in) {
    ModelFit fit;
    fit.model = v.model;
    fit.judged_on = "RGBA";
    fit.parameters = v.description;
    if (!v.applicable) {
        fit.note = v.note;
        return fit;
    }
    if (v.image.width != a_in.width || v.image.height != a_in.height || v.image.channel_count() != 4)
        throw Error("--fit: the re-rendered scene is not the images' size");
    // Left out: pixels with a non-finite value in A, B or the variant.
    double before = 0.0, after = 0.0, values = 0.0;
    const Image& a = a_in;
    const Image& b = b_in;
    const Image& variant = v.image;
    for (std::size_t p = 0; p < pixel_count(a); ++p) {
        bool finite = true;
        for (std::size_t c = 0; c < 4; ++c)
            finite = finite && std::isfinite(a.pixels[p * 4 + c]) && std::isfinite(b.pixels[p * 4 + c]) &&
                     std::isfinite(variant.pixels[p * 4 + c]);
        if (!finite) continue;
        for (std::size_t i = p * 4; i < p * 4 + 4; ++i) {
            before += (b.pixels[i] - a.pixels[i]) * (b.pixels[i] - a.pixels[i]);
            after += (variant.pixels[i] - a.pixels[i]) * (variant.pixels[i] - a.pixels[i]);
        }
        values += 4.0;
    }
    values = std::max(values, 1.0);
    fit.rgba_before = fit.residual_before = std::sqrt(before / values);
    fit.rgba_after = fit.residual_after = std::sqrt(after / values);
    fit.fitted = true;
    return fit;
}

DifferenceExplanation explain_difference(const Image& a_in, const Image& b_in,
                                         const std::vector<ConventionVariant>& conventions) {
    if (a_in.width != b_in.width || a_in.height != b_in.height || a_in.channel_count() != 4 || b_in.channel_count() != 4)
        throw Error("--fit: the images must have the same size and R, G, B, A");
    Image a, b;
    finite_copies(a_in, b_in, a, b);  // non-finite pixels never reach Ceres
    DifferenceExplanation e;
    e.fits = {fit_gain(a, b), fit_opacity_exponent(a, b), fit_shift(a, b)};
    for (const ConventionVariant& v : conventions) e.fits.push_back(fit_convention(v, a_in, b_in));
    if (e.fits[0].rgba_before == 0.0) {
        e.verdict = "likely cause: none needed, the images are identical";
        return e;
    }
    const ModelFit* best = nullptr;
    for (const ModelFit& f : e.fits)
        if (f.fitted && (!best || f.ratio() < best->ratio())) best = &f;
    if (!best || best->ratio() > kExplainedResidualRatio) {
        e.verdict = conventions.empty() ? "likely cause: none of gain, opacity exponent or shift explains the difference"
                                        : "likely cause: none of gain, opacity exponent, shift or the scene's conventions "
                                          "explains the difference";
        if (best)
            e.verdict += " (the best, " + best->model + ", leaves " + format("%.0f", 100.0 * best->ratio()) +
                         "% of the RMS difference in " + best->judged_on + ")";
        e.verdict += ": another cause (discretisation: step, sample placement, reconstruction, transfer-function "
                     "tables; or a bug)";
        return e;
    }
    const std::string kept = format("%.0f", 100.0 * best->ratio()) + "% of the RMS difference in " + best->judged_on + " left";
    if (best->model == "gain")
        e.verdict = "likely cause: a colour gain, B = " + format("%.6g", best->values[0]) +
                    " A (exposure, a colour or transfer-function scale, or sRGB against linear; " + kept + ")";
    else if (best->model == "opacity")
        e.verdict = "likely cause: opacity correction, B has " + format("%.6g", best->values[0]) +
                    " times A's optical depth (its step, opacity unit distance or density scale differs by that "
                    "factor, or it does not correct opacity for the step; " + kept + ")";
    else if (best->model != "shift")
        e.verdict = "likely cause: " + best->parameters + " (B re-rendered with it; " + kept + ")";
    else
        e.verdict = "likely cause: a sub-pixel shift of " + format("(%.3g, %.3g)", best->values[0], best->values[1]) +
                    " pixels (pixel centres at (x + 0.5, y + 0.5) or (x, y), or a different camera; " + kept + ")";
    return e;
}

// ---- error = c h^p ----------------------------------------------------------------------------------
namespace {

struct LogPowerResidual {
    double log_h, log_e;
    template <typename T>
    bool operator()(const T* log_c, const T* p, T* r) const {
        r[0] = T(log_e) - log_c[0] - p[0] * T(log_h);
        return true;
    }
};

}  // namespace

PowerLawFit fit_power_law(const std::vector<double>& h, const std::vector<double>& error) {
    PowerLawFit fit;
    std::vector<double> lh, le;
    for (std::size_t i = 0; i < std::min(h.size(), error.size()); ++i)
        if (h[i] > 0.0 && error[i] > 0.0 && std::isfinite(h[i]) && std::isfinite(error[i])) {
            lh.push_back(std::log(h[i]));
            le.push_back(std::log(error[i]));
        }
    fit.points = int(lh.size());
    if (lh.size() < 2) return fit;
    // Start: ordinary least squares through (log h, log e).
    const double n = double(lh.size());
    double mx = 0.0, my = 0.0;
    for (std::size_t i = 0; i < lh.size(); ++i) {
        mx += lh[i] / n;
        my += le[i] / n;
    }
    double sxx = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < lh.size(); ++i) {
        sxx += (lh[i] - mx) * (lh[i] - mx);
        sxy += (lh[i] - mx) * (le[i] - my);
    }
    if (sxx <= 0.0) return fit;  // every h equal
    double p = sxy / sxx, log_c = my - p * mx;
    ceres::Problem problem;
    for (std::size_t i = 0; i < lh.size(); ++i)
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LogPowerResidual, 1, 1, 1>(
                                     new LogPowerResidual{lh[i], le[i]}),
                                 new ceres::CauchyLoss(kPowerLawLossScale), &log_c, &p);
    solve(problem);
    fit.c = std::exp(log_c);
    fit.p = p;
    fit.ok = std::isfinite(fit.c) && std::isfinite(fit.p);
    return fit;
}

double step_for_error(const PowerLawFit& fit, double tolerance) {
    if (!fit.ok || fit.p == 0.0 || fit.c <= 0.0 || tolerance <= 0.0) return std::nan("");
    return std::pow(tolerance / fit.c, 1.0 / fit.p);
}

}  // namespace volref::compare
