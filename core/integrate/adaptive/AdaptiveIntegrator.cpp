#include "core/integrate/adaptive/AdaptiveIntegrator.h"

#include <algorithm>
#include <cmath>

#include "core/Cancellation.h"
#include "core/Conventions.h"
#include "core/Error.h"
#include "core/integrate/adaptive/AdaptiveCellWalk.h"
#include "core/integrate/adaptive/CellCubic.h"
#include "core/integrate/adaptive/AdaptiveQuadrature.h"
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

namespace {

double max_abs(const glm::dvec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }
double max_abs(const glm::dvec4& v) { return std::max(max_abs(glm::dvec3(v)), std::fabs(v.w)); }

double rounding_bound(const glm::dvec4& rgba) {
    return conventions::kRoundingErrorRelative * (1.0 + max_abs(rgba));
}

}  // namespace

AdaptiveIntegrator::AdaptiveIntegrator(const IntegrationContext& ctx) : Integrator(ctx) {
    const RenderSpec& r = ctx.render;
    if (r.early_termination)
        throw Error("render.integrator: \"adaptive\" integrates the whole ray; it cannot be combined with render.early_termination");
    cartesian_ = ctx.pipeline.cartesian_sampler();
    shell_grid_ = ctx.pipeline.stages().shell_grid;
    if (cartesian_) {
        cut_cells_ = true;
        const Interpolation interp = cartesian_->interpolation();
        cut_offset_ = interp == Interpolation::Nearest ? 0.5 : 0.0;
        cubic_ = interp == Interpolation::Trilinear;
    }
    // Rows of a post-classified transfer function (nearest: the value is constant between cuts).
    const bool nearest = cartesian_ && cartesian_->interpolation() == Interpolation::Nearest;
    if (!ctx.pipeline.preclassified() && !nearest)
        if (const TransferFunction* tf = ctx.pipeline.stages().transfer_function) {
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
    if ((r.projection == Projection::Mip || r.projection == Projection::Minip) &&
        !(cartesian_ && (cubic_ || cartesian_->interpolation() == Interpolation::Nearest)))
        throw Error("render.integrator: \"adaptive\" mip/minip needs a Cartesian grid with trilinear or nearest "
                    "interpolation (the extremum is found exactly there)");
}

PixelValue AdaptiveIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    switch (ctx_.render.projection) {
        case Projection::Composite: return composite(ray, intervals);
        case Projection::Average:
        case Projection::Xray: return line_integral(ray, intervals);
        case Projection::Mip:
        case Projection::Minip: return extremum(ray, intervals);
        case Projection::FirstHit: break;  // FirstHitIntegrator
    }
    throw Error("render.integrator: internal: the adaptive integrator has no first-hit path");
}

void AdaptiveIntegrator::cuts(const Ray& ray, const Interval& iv, std::vector<double>& out) const {
    out.clear();
    if (!cut_cells_) {  // beam space: the fixed integrator's segment ends
        const std::int64_t n = segment_count(iv, ctx_.step);
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

namespace {

struct LeafRecord {
    glm::dvec3 contribution;  // T(a) E
    double e_emission;        // T(a) e_E
    double e_tau;
};

struct CompositeState {
    const SamplePipeline* pipeline;
    const Ray* ray;
    double l;          // opacity_unit_distance
    double tolerance;  // render.tolerance
    double safety;     // 1, or kAdaptiveWeakSafety where kinks inside pieces are not located
    double total;      // length of all intervals
    // The pieces composite front to back with compensated colour sums (march/Accumulators.h).
    FrontToBack<Scalar, TransmittanceRule::OpticalDepthSum, true> acc;
    double colour_bound = 1.0;  // K: the largest colour seen (at least 1), for the tau part of the budget
    std::vector<LeafRecord> leaves;
    long rules_left = conventions::kAdaptiveMaxRulesPerRay;  // work bound of the ray
    double unresolved_T = 0.0;  // the transmittance in front of the first piece accepted unresolved
    // False once the ray has spent its rules or a cancel was requested: open pieces are then accepted
    // with their estimates (conventions.h, kAdaptiveMaxRulesPerRay).
    bool may_refine() const { return rules_left > 0 && !cancel_requested(); }

    // sigma and colour at t; transparent where the value (or the shaded colour) is not finite.
    void sample(double t, double& sigma, glm::dvec3& c) const {
        const PipelineSample p = pipeline->sample(*ray, t, SamplePipeline::Use::Composite);
        const double a = std::min(p.opacity, conventions::kAdaptiveMaxOpacity);
        if (!(a > 0.0) || !std::isfinite(p.value) || !std::isfinite(p.color.x + p.color.y + p.color.z)) {
            sigma = 0.0;
            c = glm::dvec3(0.0);
            return;
        }
        sigma = extinction(a, l);
        c = p.color;
    }

    // One G7/K15 evaluation of [a, b]: the emission E (relative to T(a)) and Delta tau by both rules.
    struct Rule {
        glm::dvec3 ek{0.0}, eg{0.0};
        double tk = 0.0, tg = 0.0;
        double em_error() const { return max_abs(ek - eg); }
        double tau_error() const { return std::fabs(tk - tg); }
    };
    Rule evaluate(double a, double b) {
        --rules_left;
        const gk::Tables& g = gk::tables();
        const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
        double sigma[gk::kNodes];
        glm::dvec3 c[gk::kNodes];
        for (int i = 0; i < gk::kNodes; ++i) {
            sample(mid + half * g.x[std::size_t(i)], sigma[i], c[i]);
            colour_bound = std::max(colour_bound, max_abs(c[i]));
        }
        Rule r;
        for (int i = 0; i < gk::kNodes; ++i) {
            r.tk += g.wk[std::size_t(i)] * sigma[i];
            if (sigma[i] == 0.0) continue;
            double tau_i = 0.0;
            for (int j = 0; j < gk::kNodes; ++j) tau_i += g.sk[std::size_t(i)][std::size_t(j)] * sigma[j];
            r.ek += (g.wk[std::size_t(i)] * sigma[i] * std::exp(-half * tau_i)) * c[i];
        }
        for (int q = 0; q < gk::kGaussNodes; ++q) {
            const int i = 2 * q + 1;
            r.tg += g.wg[std::size_t(q)] * sigma[i];
            if (sigma[i] == 0.0) continue;
            double tau_q = 0.0;
            for (int j = 0; j < gk::kGaussNodes; ++j) tau_q += g.sg[std::size_t(q)][std::size_t(j)] * sigma[2 * j + 1];
            r.eg += (g.wg[std::size_t(q)] * sigma[i] * std::exp(-half * tau_q)) * c[i];
        }
        r.tk *= half;
        r.tg *= half;
        r.ek *= half;
        r.eg *= half;
        return r;
    }

    // [a, b] with its rule P already evaluated: its halves L and R are evaluated; the pair is accepted
    // when the estimate  e = |P - (L + R)| + |K15 - G7|_L + |K15 - G7|_R  (emission with R behind L:
    // E = E_L + exp(-Delta tau_L) E_R; and optical depth) fits the budget; otherwise each half goes on.
    // Comparing a rule with its halves catches what both rules of one evaluation miss together (a
    // narrow feature between nodes, an unlocated kink).
    void process(double a, double b, int depth, const Rule& P) {
        const double m = 0.5 * (a + b);
        const double T = acc.transmittance();
        if (!(m > a && m < b) || depth >= conventions::kAdaptiveMaxDepth) {
            commit(T, P.ek, P.tk, 0.0, safety * P.em_error(), safety * P.tau_error());
            return;
        }
        const Rule L = evaluate(a, m), R = evaluate(m, b);
        const glm::dvec3 E = L.ek + std::exp(-L.tk) * R.ek;
        const double e_e = safety * (max_abs(P.ek - E) + L.em_error() + R.em_error());
        const double e_t = safety * (std::fabs(P.tk - (L.tk + R.tk)) + L.tau_error() + R.tau_error());
        const double estimate = T * (e_e + colour_bound * e_t);
        const double budget = tolerance * (b - a) / total;
        const double roundoff = conventions::kAdaptiveRoundoffRelative * T * (max_abs(E) + colour_bound * (L.tk + R.tk));
        if (estimate <= budget || estimate <= roundoff) {
            commit(T, E, L.tk, R.tk, e_e, e_t);
            return;
        }
        if (!may_refine()) {  // unresolved: everything from here on is uncertain (see composite())
            unresolved_T = std::max(unresolved_T, T);
            commit(T, E, L.tk, R.tk, e_e, e_t);
            return;
        }
        process(a, m, depth + 1, L);
        process(m, b, depth + 1, R);
    }
    void commit(double T, const glm::dvec3& E, double dtau0, double dtau1, double e_e, double e_t) {
        const glm::dvec3 contribution = T * E;
        const double e[3] = {E.r, E.g, E.b};
        acc.add_emission(e, dtau0, dtau1);
        leaves.push_back({contribution, T * e_e, e_t});
    }
    void integrate(double a, double b) { process(a, b, 0, evaluate(a, b)); }
};

}  // namespace

PixelValue AdaptiveIntegrator::composite(const Ray& ray, const std::vector<Interval>& intervals) const {
    PixelValue out;
    CompositeState st{&ctx_.pipeline, &ray, ctx_.pipeline.classifier().unit_distance(), ctx_.render.tolerance,
                      weak_ ? conventions::kAdaptiveWeakSafety : 1.0, 0.0, {}, 1.0, {}};
    for (const Interval& iv : intervals) st.total += iv.length();
    if (!(st.total > 0.0)) return out;
    bool opaque = false;
    glm::dvec3 opaque_colour(0.0);
    std::vector<double> cut;
    for (const Interval& iv : intervals) {
        cuts(ray, iv, cut);
        for (std::size_t p = 0; p + 1 < cut.size() && !opaque; ++p) {
            const double a = cut[p], b = cut[p + 1];
            if (!(b > a)) continue;
            // Empty-space skipping: a piece lies in one cell (nearest: reads one voxel, a corner of the
            // cell of its midpoint); in an empty macrocell every sample of it has opacity 0.
            if (ctx_.macrocells && cut_cells_ && ctx_.macrocells->empty(ctx_.macrocells->macrocell_at(ray.at(0.5 * (a + b)))))
                continue;
            const PipelineSample pm = ctx_.pipeline.sample(ray, 0.5 * (a + b), SamplePipeline::Use::Composite);
            if (pm.opacity >= 1.0 && std::isfinite(pm.value)) {  // opaque piece: the ray ends at a
                const PipelineSample ps = ctx_.pipeline.sample(ray, a + conventions::kAdaptiveOpaqueColourOffset * (b - a),
                                                               SamplePipeline::Use::Composite);
                opaque_colour = st.acc.transmittance() * ps.color;
                const double c[3] = {ps.color.r, ps.color.g, ps.color.b};
                st.acc.add_opaque(c);
                opaque = true;
                break;
            }
            st.integrate(a, b);
        }
        if (opaque) break;
    }
    const double T_end = opaque ? 0.0 : st.acc.transmittance();
    out.rgba = glm::dvec4(st.acc.color(0), st.acc.color(1), st.acc.color(2), st.acc.alpha());
    // Posterior error: leaf i's tau error scales everything emitted behind it.
    glm::dvec3 behind = opaque_colour;
    double colour_err = 0.0, tau_err = 0.0;
    for (auto it = st.leaves.rbegin(); it != st.leaves.rend(); ++it) {
        colour_err += it->e_emission + it->e_tau * max_abs(behind);
        tau_err += it->e_tau;
        behind += it->contribution;
    }
    // A piece accepted unresolved (the ray's rules spent) may be wrong by anything it and the pieces
    // behind it contribute: at most T K in each channel (T in front of it, K >= 1 the largest colour).
    out.error = std::max(colour_err, T_end * tau_err) + rounding_bound(out.rgba) + st.unresolved_T * st.colour_bound;
    return out;
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
    PixelValue out;
    if (intervals.empty()) return out;
    CompensatedSum length;
    for (const Interval& iv : intervals) length.add(iv.length());
    const double L = length.value();
    const bool mean = ctx_.render.projection == Projection::Average;
    const double tol = ctx_.render.tolerance;
    // Pixel = I / L (average) or gain I (xray); its tolerance spread over the length.
    const double per_length = mean ? tol : (L > 0.0 ? tol / (ctx_.render.gain * L) : 0.0);
    LineState st{&ctx_.pipeline, &ray, per_length, cubic_ ? 1.0 : conventions::kAdaptiveWeakSafety, {}, 0.0};
    std::vector<double> cut;
    for (const Interval& iv : intervals) {
        cuts(ray, iv, cut);
        for (std::size_t p = 0; p + 1 < cut.size(); ++p)
            if (cut[p + 1] > cut[p]) st.integrate(cut[p], cut[p + 1]);
    }
    const double g = mean ? (L > 0.0 ? st.integral.value() / L : 0.0) : ctx_.render.gain * st.integral.value();
    out.rgba = glm::dvec4(g, g, g, 1.0);
    out.error = (mean ? (L > 0.0 ? st.error / L : 0.0) : ctx_.render.gain * st.error) + rounding_bound(out.rgba);
    return out;
}

// ---------------------------------------------------------------------------------------------
// mip / minip
// ---------------------------------------------------------------------------------------------

PixelValue AdaptiveIntegrator::extremum(const Ray& ray, const std::vector<Interval>& intervals) const {
    const bool maximum = ctx_.render.projection == Projection::Mip;
    // The extremum over the candidates (march/Accumulators.h; non-finite values are ignored).
    Extremum<Scalar> acc(maximum);
    auto consider = [&](double t) { acc.add(true, ctx_.field(ray, t), t); };
    // A piece's end, read in the piece's own cell (piece_end, CellCubic.h).
    auto consider_end = [&](double t, double toward) {
        const auto [at, v] = piece_end([&](double u) { return ctx_.field(ray, u); }, t, toward);
        acc.add(true, v, at);
    };
    const Volume& v = cartesian_->volume();
    std::vector<double> cut;
    for (const Interval& iv : intervals) {
        grid_cuts(ray, iv.t0, iv.t1, v, cut_offset_, cut);
        for (std::size_t p = 0; p + 1 < cut.size(); ++p) {
            const double ta = cut[p], tb = cut[p + 1];
            if (!cubic_) {  // nearest: constant on the piece
                consider(0.5 * (ta + tb));
                continue;
            }
            consider_end(ta, tb);
            consider_end(tb, ta);
            double ex[2];
            const int ne = cubic_extrema(cell_cubic(*cartesian_, ray, ta, tb), tb - ta, ex);
            for (int k = 0; k < ne; ++k) consider(ta + ex[k]);
        }
    }
    PixelValue out;
    if (acc.any()) {
        const PipelineSample p = ctx_.pipeline.sample(ray, acc.where(), SamplePipeline::Use::Unshaded);
        out.rgba = glm::dvec4(p.opacity * p.color, p.opacity);
    }
    out.error = rounding_bound(out.rgba);
    return out;
}

}  // namespace volref
