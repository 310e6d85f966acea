#include "core/integrate/adaptive/AdaptiveIntegrator.h"

#include "core/integrate/march/SpanStates.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/Cancellation.h"
#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/integrate/adaptive/AdaptiveCellWalk.h"
#include "core/integrate/adaptive/AdaptiveComposite.h"
#include "core/integrate/adaptive/CellCubic.h"
#include "core/GaussKronrod.h"
#include "core/integrate/march/CompensatedSum.h"
#include "geometry/ShellCoordinates.h"
#include "core/integrate/march/Accumulators.h"
#include "transfer/OpacityCorrection.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/VolumeSampler.h"
#include "transfer/TransferFunction.h"

namespace volref {

namespace gk = gauss_kronrod;

using adaptive_detail::rounding_bound;

AdaptiveIntegrator::AdaptiveIntegrator(const IntegrationContext& ctx)
    : OneLoopIntegrator(ctx), kind_(accumulation(ctx.render.projection)), maximum_(takes_maximum(ctx.render.projection)),
      mean_(takes_mean(ctx.render.projection)) {
    const RenderSpec& r = ctx.render;
    // Resumable for the accumulations whose parts are independent (extremum, line integral): each
    // span's extremum (classified here) or sums, merged behind the state (march/SpanStates.h). Not the
    // composite, whose state (AdaptiveComposite) volref-mpi hands on itself.
    traits_.resumable = kind_ == Accumulation::Extremum || kind_ == Accumulation::LineIntegral;
    traits_.writes_error = true;
    if (r.early_termination)
        throw Error("render.integrator: \"adaptive\" integrates the whole ray; it cannot be combined with render.early_termination");
    cartesian_ = ctx.pipeline.view().cartesian;
    shell_grid_ = ctx.pipeline.view().shell_grid;
    if (cartesian_) {
        cut_cells_ = true;
        const Interpolation interp = cartesian_->interpolation();
        cut_offset_ = interp == Interpolation::Nearest ? 0.5 : 0.0;
        cubic_ = interp == Interpolation::Trilinear;
    }
    // Rows of a post-classified transfer function (nearest: the value is constant between cuts).
    const bool nearest = cartesian_ && cartesian_->interpolation() == Interpolation::Nearest;
    if (!ctx.pipeline.preclassified() && !nearest)
        if (const TransferFunction* tf = ctx.pipeline.view().transfer_function) {
            rows_ = tf;
            for (double x : tf->color_function().xs()) row_values_.push_back(x);
            for (double x : tf->opacity_function().xs()) row_values_.push_back(x);
            std::sort(row_values_.begin(), row_values_.end());
            row_values_.erase(std::unique(row_values_.begin(), row_values_.end()), row_values_.end());
        }
    // Composite: is every kink of the integrand at a cut? Only for trilinear reconstruction with a
    // transfer function (rows located as cubic roots) or pre-classification (trilinear opacity and
    // colour), unshaded, without gradient opacity. Otherwise the estimate carries kAdaptiveWeakSafety.
    const bool smooth_between_cuts = cubic_ && !ctx.pipeline.shaded() && !ctx.pipeline.classifier().needs_gradient() &&
                                     (rows_ || ctx.pipeline.preclassified());
    weak_ = !smooth_between_cuts;
    if (kind_ == Accumulation::Extremum &&
        !(cartesian_ && (cubic_ || cartesian_->interpolation() == Interpolation::Nearest)))
        throw Error("render.integrator: \"adaptive\" mip/minip needs a Cartesian grid with trilinear or nearest "
                    "interpolation (the extremum is found exactly there)");
}

double AdaptiveIntegrator::safety() const { return weak_ ? conventions::kAdaptiveWeakSafety : 1.0; }

// Every ray by its pieces; there is no traced loop.
PixelValue AdaptiveIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, NoRecording&) const {
    switch (kind_) {
        case Accumulation::Composite: return composite(ray, intervals);
        case Accumulation::LineIntegral: return line_integral(ray, intervals);
        case Accumulation::Extremum: return extremum(ray, intervals);
        case Accumulation::FirstHit: break;  // FirstHitIntegrator
    }
    throw Error("render.integrator: internal: the adaptive integrator has no first-hit path");
}

// The part of `iv` whose pieces a span can own: [t0 - m, t1 + m] of the span with m two of the ray's
// longest pieces (a piece lies between two consecutive grid planes of every axis the ray crosses, so it
// is at most min_a spacing_a / |d_a| long). Cutting that part gives the whole interval's cuts inside it
// (each plane's t is computed on its own: grid_cuts), and its end pieces, cut short, lie outside the
// span (their midpoints before t0 or after t1), so the pieces the span owns are the whole interval's.
// The whole interval for the whole span, beam space, or a ray that crosses no plane.
Interval AdaptiveIntegrator::span_part(const Ray& ray, const Interval& iv, const RaySpan& span) const {
    if (span.whole() || !cut_cells_) return iv;
    const Volume& v = cartesian_->volume();
    double longest = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
        if (v.dims[a] >= 2 && ray.direction[a] != 0.0) longest = std::min(longest, v.spacing[a] / std::fabs(ray.direction[a]));
    if (!std::isfinite(longest)) return iv;
    Interval part = iv;
    part.t0 = std::max(iv.t0, span.t0 - 2.0 * longest);
    part.t1 = std::min(iv.t1, span.t1 + 2.0 * longest);
    return part;
}

void AdaptiveIntegrator::cuts(const Ray& ray, const Interval& iv, std::vector<double>& out, const RaySpan& span) const {
    const Interval part = span_part(ray, iv, span);
    if (!(part.t0 < part.t1) && !span.whole()) return out.clear();
    cuts(ray, part, out);
}

void AdaptiveIntegrator::cuts(const Ray& ray, const Interval& iv, std::vector<double>& out) const {
    out.clear();
    if (!cut_cells_) {  // beam space: the fixed integrator's segment ends
        const std::int64_t n = segment_count(iv, ctx_.step);
        check_memory(std::size_t(n + 1) * sizeof(double), "render.step: the adaptive integrator's cuts of one interval");
        out.push_back(iv.t0);
        for (std::int64_t k = 0; k < n; ++k) out.push_back(segment(iv, ctx_.step, k, n).t1);
        if (shell_grid_) sampled_shell_cuts(ray, out);
    } else {
        grid_cuts(ray, iv.t0, iv.t1, cartesian_->volume(), cut_offset_, out);
    }
    if (!rows_ || row_values_.empty()) return;
    if (!cubic_) return sampled_row_cuts(ray, out);
    // Rows: the roots of s(f(t)) = x_k inside each cell, s the transfer function's coordinate.
    std::vector<double> all;
    all.reserve(out.size() * 2);
    for (std::size_t p = 0; p + 1 < out.size(); ++p) {
        const double ta = out[p], tb = out[p + 1], L = tb - ta;
        all.push_back(ta);
        Cubic s = cell_cubic(*cartesian_, ray, ta, tb);
        if (rows_->normalized()) {
            const double w = rows_->inverse_window_width();
            s = s.affine(w, -rows_->window()[0] * w);
        }
        double ex[2];
        const int ne = cubic_extrema(s, L, ex);
        double pts[4] = {0.0, 0.0, 0.0, 0.0};
        int np = 0;
        pts[np++] = 0.0;
        for (int k = 0; k < ne; ++k) pts[np++] = ex[k];
        pts[np++] = L;
        const std::size_t first = all.size();
        for (int m = 0; m + 1 < np; ++m) {  // s is monotone on [pts[m], pts[m + 1]]
            const double xa = pts[m], xb = pts[m + 1];
            const double va = s(xa), vb = s(xb);
            const double lo = std::min(va, vb), hi = std::max(va, vb);
            for (auto it = std::upper_bound(row_values_.begin(), row_values_.end(), lo);
                 it != row_values_.end() && *it < hi; ++it) {
                const double x = *it;
                const double root = bisect_to_rounding([&](double y) { return s(y) - x; }, xa, xb, va < x ? -1 : 1);
                const double t = ta + root;
                if (t > ta && t < tb) all.push_back(t);
            }
        }
        std::sort(all.begin() + std::ptrdiff_t(first), all.end());
    }
    all.push_back(out.back());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    out.swap(all);
}

void AdaptiveIntegrator::sampled_shell_cuts(const Ray& ray, std::vector<double>& out) const {
    // The beam-space cell (per axis: floor of the continuous index, clamped to [0, n - 2] on
    // non-periodic axes, modulo n on periodic ones) at kAdaptiveRowSamples + 1 points of each piece;
    // where it differs between neighbours, the sub-interval is halved until no double lies between its
    // ends, and that end is a cut (every boundary between two samples whose cells differ is found; a
    // ray entering and leaving a cell between two samples is left to the quadrature).
    const ShellGrid& g = *shell_grid_;
    auto cell = [&](double t) {
        const glm::dvec3 u = g.continuous_index(ray.at(t));
        std::array<std::int64_t, 3> c{};
        for (int a = 0; a < 3; ++a) {
            const std::int64_t n = g.dims()[std::size_t(a)];
            if (n < 2 || !std::isfinite(u[a])) continue;
            const std::int64_t f = std::int64_t(std::floor(u[a]));
            c[std::size_t(a)] = g.axis(a).periodic ? ((f % n) + n) % n : std::clamp<std::int64_t>(f, 0, n - 2);
        }
        return c;
    };
    std::vector<double> all;
    all.reserve(out.size() * 2);
    auto find = [&](auto&& self, double xa, const std::array<std::int64_t, 3>& ca, double xb,
                    const std::array<std::int64_t, 3>& cb, int depth) -> void {
        if (ca == cb) return;
        const double m = 0.5 * (xa + xb);
        if (!(m > xa && m < xb) || depth > 2200) {
            all.push_back(xb);
            return;
        }
        const std::array<std::int64_t, 3> cm = cell(m);
        self(self, xa, ca, m, cm, depth + 1);
        self(self, m, cm, xb, cb, depth + 1);
    };
    const int n = conventions::kAdaptiveRowSamples;
    for (std::size_t p = 0; p + 1 < out.size(); ++p) {
        const double ta = out[p], tb = out[p + 1];
        all.push_back(ta);
        const std::size_t first = all.size();
        double xa = ta;
        std::array<std::int64_t, 3> ca = cell(ta);
        for (int k = 1; k <= n; ++k) {
            const double xb = k == n ? tb : ta + (tb - ta) * double(k) / double(n);
            const std::array<std::int64_t, 3> cb = cell(xb);
            find(find, xa, ca, xb, cb, 0);
            xa = xb;
            ca = cb;
        }
        std::sort(all.begin() + std::ptrdiff_t(first), all.end());
        while (all.size() > first && !(all.back() < tb)) all.pop_back();
    }
    all.push_back(out.back());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    out.swap(all);
}

void AdaptiveIntegrator::sampled_row_cuts(const Ray& ray, std::vector<double>& out) const {
    // Not a cubic (tricubic: degree 9 per cell; beam space): the coordinate s(t) at
    // kAdaptiveRowSamples + 1 equally spaced points of each piece; a row value strictly between two
    // consecutive samples' s (or equal to the later one) is a crossing, bisected on the sampler to
    // rounding. Crossings that come and go between two samples are left to the quadrature.
    const int n = conventions::kAdaptiveRowSamples;
    auto s = [&](double t) { return rows_->coordinate(ctx_.field(ray, t)); };
    std::vector<double> all;
    all.reserve(out.size() * 2);
    for (std::size_t p = 0; p + 1 < out.size(); ++p) {
        const double ta = out[p], tb = out[p + 1];
        all.push_back(ta);
        double xa = ta, va = s(ta);
        for (int k = 1; k <= n; ++k) {
            const double xb = k == n ? tb : ta + (tb - ta) * double(k) / double(n), vb = s(xb);
            if (std::isfinite(va) && std::isfinite(vb) && va != vb) {
                const double lo = std::min(va, vb), hi = std::max(va, vb);
                const std::size_t first = all.size();
                for (auto it = std::upper_bound(row_values_.begin(), row_values_.end(), lo);
                     it != row_values_.end() && *it < hi; ++it) {
                    const double x = *it;
                    const double t = bisect_to_rounding([&](double y) { return s(y) - x; }, xa, xb, va < x ? -1 : 1);
                    if (t > ta && t < tb) all.push_back(t);
                }
                std::sort(all.begin() + std::ptrdiff_t(first), all.end());
            }
            xa = xb;
            va = vb;
        }
    }
    all.push_back(out.back());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    out.swap(all);
}

// ---------------------------------------------------------------------------------------------
// Composite
// ---------------------------------------------------------------------------------------------

bool AdaptiveIntegrator::opaque_piece(const Ray& ray, double a, double b) const {
    // A cut found to rounding beside another (a cell face and a row's root that coincide in exact
    // arithmetic) leaves a piece a few doubles long: it has no length, so it is never opaque.
    double t = a;
    for (int k = 0; k < conventions::kAdaptiveOpaqueMinDoubles; ++k)
        if (!((t = std::nextafter(t, b)) < b)) return false;
    // Opacity 1 at a, the midpoint and b (just inside the ends): on a piece the transfer function is
    // linear in s between two consecutive rows, so opacity 1 at two different s of it is opacity 1 on
    // all of it; opacity 1 at one point only (a tent's peak touched or crossed) is integrable.
    const double d = conventions::kAdaptiveOpaqueColourOffset * (b - a);
    for (double x : {0.5 * (a + b), a + d, b - d}) {
        const PipelineSample p = ctx_.pipeline.sample(ray, x, SamplePipeline::Use::Composite);
        if (!(p.opacity >= 1.0 && std::isfinite(p.value))) return false;
    }
    return true;
}

double AdaptiveIntegrator::opaque_from(const Ray& ray, double a, double b) const {
    if (opaque_piece(ray, a, b)) return a;
    if (!weak_) return std::numeric_limits<double>::infinity();  // rows are cuts: opaque pieces are whole
    // Kinks of the classification are not cuts here (Levoy's classification, gradient opacity, a
    // shaded or tricubic pipeline), so the opacity may reach 1 inside the piece and stay there (a
    // clamped boundary opacity). sigma is clamped (kAdaptiveMaxOpacity), which would spread the
    // opaque surface's colour over 1/36.7 of a unit length; instead, the first of kAdaptiveRowSamples
    // samples with opacity 1 is bisected back to the last sample below 1 to rounding (a double t_s),
    // and where the opacity is also 1 just behind it (t_s + kAdaptiveOpaqueColourOffset (b - a):
    // positive length, not a peak touching 1), the ray ends at t_s.
    auto saturated = [&](double t) {
        const PipelineSample p = ctx_.pipeline.sample(ray, t, SamplePipeline::Use::Composite);
        return p.opacity >= 1.0 && std::isfinite(p.value);
    };
    const int n = conventions::kAdaptiveRowSamples;
    const double d = conventions::kAdaptiveOpaqueColourOffset * (b - a);
    double prev = a;
    for (int k = 1; k <= n; ++k) {
        const double t = k == n ? b - d : a + (b - a) * double(k) / double(n);
        if (!saturated(t)) {
            prev = t;
            continue;
        }
        double lo = prev, hi = t;
        for (;;) {
            const double m = 0.5 * (lo + hi);
            if (!(m > lo && m < hi)) break;
            (saturated(m) ? hi : lo) = m;
        }
        if (hi + d < b && saturated(hi + d)) return hi;
        prev = t;
    }
    return std::numeric_limits<double>::infinity();
}

bool AdaptiveIntegrator::empty_piece(const Ray& ray, double a, double b) const {
    // A piece lies in one cell (nearest: reads one voxel, a corner of the cell of its midpoint); in an
    // empty macrocell every sample of it has opacity 0.
    return ctx_.macrocells && cut_cells_ && ctx_.macrocells->empty(ctx_.macrocells->macrocell_at(ray.at(0.5 * (a + b))));
}

void AdaptiveIntegrator::medium(const Ray& ray, double t, double& sigma, glm::dvec3& c) const {
    const PipelineSample p = ctx_.pipeline.sample(ray, t, SamplePipeline::Use::Composite);
    const double a = std::min(p.opacity, conventions::kAdaptiveMaxOpacity);
    if (!(a > 0.0) || !std::isfinite(p.value) || !std::isfinite(p.color.x + p.color.y + p.color.z)) {
        sigma = 0.0;
        c = glm::dvec3(0.0);
        return;
    }
    sigma = extinction(a, ctx_.pipeline.classifier().unit_distance());
    c = p.color;
}

glm::dvec3 AdaptiveIntegrator::opaque_colour(const Ray& ray, double a, double b) const {
    return ctx_.pipeline.sample(ray, a + conventions::kAdaptiveOpaqueColourOffset * (b - a), SamplePipeline::Use::Composite).color;
}

PixelValue AdaptiveIntegrator::composite(const Ray& ray, const std::vector<Interval>& intervals) const {
    double total = 0.0;
    for (const Interval& iv : intervals) total += iv.length();
    if (!(total > 0.0)) return PixelValue{};
    const OneVolume one{this, &ray};
    Composite st(one, ctx_.render.tolerance, safety(), total);
    std::vector<double> cut;
    for (const Interval& iv : intervals) {
        cuts(ray, iv, cut);
        for (std::size_t p = 0; p + 1 < cut.size() && !st.is_opaque(); ++p) composite_piece(ray, cut[p], cut[p + 1], st);
        if (st.is_opaque()) break;
    }
    return st.result();
}

void AdaptiveIntegrator::composite_piece(const Ray& ray, double a, double b, Composite& st) const {
    if (!(b > a) || empty_piece(ray, a, b)) return;
    const double ts = opaque_from(ray, a, b);
    if (ts < b) {  // the ray ends at ts
        if (ts > a) st.integrate(a, ts);
        st.opaque(opaque_colour(ray, ts, b));
    } else {
        st.integrate(a, b);
    }
}

// ---------------------------------------------------------------------------------------------
// average / xray
// ---------------------------------------------------------------------------------------------

namespace {

struct LineState {
    const SamplePipeline* pipeline;
    const Ray* ray;
    double budget_per_length;  // accepted error of the integral per unit length
    double safety;             // as CompositeState::safety
    CompensatedSum integral;
    double error = 0.0;
    long rules_left = conventions::kAdaptiveMaxRulesPerRay;  // as CompositeState's
    bool may_refine() const { return rules_left > 0 && !cancel_requested(); }

    double s(double t) const {
        const double v = pipeline->value(*ray, t);
        if (!std::isfinite(v)) return 0.0;
        const double x = pipeline->classifier().coordinate(v);
        return std::isfinite(x) ? x : 0.0;
    }
    struct Rule {
        double k = 0.0, g = 0.0;
    };
    Rule evaluate(double a, double b) {
        --rules_left;
        const gk::Tables& t = gk::tables();
        const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
        Rule r;
        for (int i = 0; i < gk::kNodes; ++i) {
            const double f = s(mid + half * t.x[std::size_t(i)]);
            r.k += t.wk[std::size_t(i)] * f;
            if (i % 2 == 1) r.g += t.wg[std::size_t(i / 2)] * f;
        }
        r.k *= half;
        r.g *= half;
        return r;
    }
    // As CompositeState::process: a rule against its halves.
    void process(double a, double b, int depth, const Rule& P) {
        const double m = 0.5 * (a + b);
        if (!(m > a && m < b) || depth >= conventions::kAdaptiveMaxDepth) {
            integral.add(P.k);
            error += safety * std::fabs(P.k - P.g);
            return;
        }
        const Rule L = evaluate(a, m), R = evaluate(m, b);
        const double sum = L.k + R.k;
        const double e = safety * (std::fabs(P.k - sum) + std::fabs(L.k - L.g) + std::fabs(R.k - R.g));
        if (e <= budget_per_length * (b - a) || e <= conventions::kAdaptiveRoundoffRelative * std::fabs(sum) ||
            !may_refine()) {
            integral.add(L.k);
            integral.add(R.k);
            error += e;
            return;
        }
        process(a, m, depth + 1, L);
        process(m, b, depth + 1, R);
    }
    void integrate(double a, double b) { process(a, b, 0, evaluate(a, b)); }
};

}  // namespace

PixelValue AdaptiveIntegrator::line_integral(const Ray& ray, const std::vector<Interval>& intervals) const {
    LineSums st;
    line_over(ray, intervals, RaySpan{}, st);
    return line_pixel(intervals, st.integral, st.error);
}

// The one loop of average and x-ray: the pieces whose midpoints `span` owns added to `st`.
void AdaptiveIntegrator::line_over(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                   LineSums& st) const {
    if (intervals.empty()) return;
    const double per_length = line_budget(line_length(intervals));
    std::vector<double> cut;
    for (const Interval& iv : intervals) {
        cuts(ray, iv, cut, span);
        for (std::size_t p = 0; p + 1 < cut.size(); ++p)
            if (span.owns(0.5 * (cut[p] + cut[p + 1]))) line_piece(ray, cut[p], cut[p + 1], per_length, st);
    }
}

PixelValue AdaptiveIntegrator::line_pixel(const std::vector<Interval>& intervals, const CompensatedSum& integral,
                                          double error) const {
    PixelValue out;
    if (intervals.empty()) return out;
    const double L = line_length(intervals);
    const bool mean = mean_;
    const double g = mean ? (L > 0.0 ? integral.value() / L : 0.0) : ctx_.render.gain * integral.value();
    out.rgba = glm::dvec4(g, g, g, 1.0);
    out.error = (mean ? (L > 0.0 ? error / L : 0.0) : ctx_.render.gain * error) + rounding_bound(out.rgba);
    return out;
}

double AdaptiveIntegrator::line_length(const std::vector<Interval>& intervals) {
    CompensatedSum length;
    for (const Interval& iv : intervals) length.add(iv.length());
    return length.value();
}

double AdaptiveIntegrator::line_budget(double length) const {
    // Pixel = I / L (average) or gain I (xray); its tolerance spread over the length.
    const double tol = ctx_.render.tolerance;
    if (mean_) return tol;
    return length > 0.0 ? tol / (ctx_.render.gain * length) : 0.0;
}

void AdaptiveIntegrator::line_piece(const Ray& ray, double a, double b, double per_length, LineSums& sums) const {
    if (!(b > a)) return;
    LineState st{&ctx_.pipeline, &ray, per_length, cubic_ ? 1.0 : conventions::kAdaptiveWeakSafety, sums.integral,
                 sums.error, sums.rules_left};
    st.integrate(a, b);
    sums.integral = st.integral;
    sums.error = st.error;
    sums.rules_left = st.rules_left;
}

// ---------------------------------------------------------------------------------------------
// mip / minip
// ---------------------------------------------------------------------------------------------

PixelValue AdaptiveIntegrator::extremum(const Ray& ray, const std::vector<Interval>& intervals) const {
    Extremum<Scalar> acc(maximum_);
    extremum_over(ray, intervals, RaySpan{}, acc);
    PixelValue out;
    if (acc.any()) out.rgba = extremum_rgba(ray, acc.where());
    out.error = rounding_bound(out.rgba);
    return out;
}

// The one loop of mip and minip: the extremum over the candidates of the pieces whose midpoints
// `span` owns (march/Accumulators.h; non-finite values are ignored).
void AdaptiveIntegrator::extremum_over(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                       Extremum<Scalar>& acc) const {
    std::vector<double> cut;
    for (const Interval& iv : intervals) {
        const Interval part = span_part(ray, iv, span);
        if (!(part.t0 < part.t1) && !span.whole()) continue;
        extremum_cuts(ray, part, cut);
        for (std::size_t p = 0; p + 1 < cut.size(); ++p)
            if (span.owns(0.5 * (cut[p] + cut[p + 1]))) extremum_piece(ray, cut[p], cut[p + 1], acc);
    }
}

glm::dvec4 AdaptiveIntegrator::extremum_rgba(const Ray& ray, double t) const {
    const PipelineSample p = ctx_.pipeline.sample(ray, t, SamplePipeline::Use::Unshaded);
    return glm::dvec4(p.opacity * p.color, p.opacity);
}

void AdaptiveIntegrator::integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                             RayState& state) const {
    RayState part;
    switch (kind_) {
        case Accumulation::Extremum: {
            Extremum<Scalar> acc(maximum_);
            extremum_over(ray, intervals, span, acc);
            if (!acc.any()) return;
            extremum_state::save(acc.value(), acc.where(), extremum_rgba(ray, acc.where()), part);
            break;
        }
        case Accumulation::LineIntegral: {
            LineSums st;
            line_over(ray, intervals, span, st);
            line_state::save(st.integral, CompensatedSum(), st.error, part);
            break;
        }
        case Accumulation::Composite:
        case Accumulation::FirstHit: not_resumable();
    }
    merge_spans(state, part);
}

void AdaptiveIntegrator::merge_spans(RayState& front, const RayState& back) const {
    if (kind_ == Accumulation::Extremum)
        extremum_state::merge(front, back, maximum_);
    else
        line_state::merge(front, back);
}

PixelValue AdaptiveIntegrator::finish(const Ray&, const std::vector<Interval>& intervals, const RayState& state) const {
    if (kind_ == Accumulation::Extremum) {
        PixelValue out;
        if (extremum_state::seen(state)) out.rgba = extremum_state::rgba(state);
        out.error = rounding_bound(out.rgba);
        return out;
    }
    return line_pixel(intervals, line_state::integral(state), state.v[4]);
}

void AdaptiveIntegrator::extremum_cuts(const Ray& ray, const Interval& iv, std::vector<double>& out) const {
    grid_cuts(ray, iv.t0, iv.t1, cartesian_->volume(), cut_offset_, out);
}

void AdaptiveIntegrator::extremum_piece(const Ray& ray, double ta, double tb, Extremum<Scalar>& acc) const {
    auto consider = [&](double t) { acc.add(true, ctx_.field(ray, t), t); };
    if (!cubic_) {  // nearest: constant on the piece
        consider(0.5 * (ta + tb));
        return;
    }
    // A piece's end, read in the piece's own cell (piece_end, CellCubic.h).
    auto consider_end = [&](double t, double toward) {
        const auto [at, v] = piece_end([&](double u) { return ctx_.field(ray, u); }, t, toward);
        acc.add(true, v, at);
    };
    consider_end(ta, tb);
    consider_end(tb, ta);
    double ex[2];
    const int ne = cubic_extrema(cell_cubic(*cartesian_, ray, ta, tb), tb - ta, ex);
    for (int k = 0; k < ne; ++k) consider(ta + ex[k]);
}

}  // namespace volref
