#include "transfer/PreIntegration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/common.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Conventions.h"
#include "core/Lanes.h"
#include "core/GaussKronrod.h"
#include "transfer/TransferFunction.h"

namespace volref {

#include "transfer/PreIntegration-inl.h"

namespace {

// f(x) = p + q x on the piece of a piecewise-linear function that holds x (PiecewiseLinear's rows:
// constant before the first and from the last row on; at a jump the later row).
template <std::size_t N>
void piece_at(const PiecewiseLinear<N>& f, double x, std::size_t c, double& p, double& q) {
    const auto& xs = f.xs();
    const auto& ys = f.ys();
    const auto it = std::upper_bound(xs.begin(), xs.end(), x);
    if (it == xs.begin() || it == xs.end()) {
        p = (it == xs.begin() ? ys.front() : ys.back())[c];
        q = 0.0;
        return;
    }
    const std::size_t k = std::size_t(it - xs.begin());
    q = (ys[k][c] - ys[k - 1][c]) / (xs[k] - xs[k - 1]);
    p = ys[k - 1][c] - q * xs[k - 1];
}

// F(a) = (1 - a) log(1 - a) + a: F'(a) = -log(1 - a).
double F(double a) { return (1.0 - a) * std::log1p(-a) + a; }

// integral over u in [u0, u1] of -log(1 - a(u)) for a(u) linear on it, a(u0) = a0, a(u1) = a1, both
// at most kPreIntegrationMaxOpacity.
double log_integral(double a0, double a1, double u0, double u1) {
    if (!(u1 > u0)) return 0.0;
    if (std::fabs(a1 - a0) < 1e-4) return -std::log1p(-0.5 * (a0 + a1)) * (u1 - u0);
    return (F(a1) - F(a0)) / ((a1 - a0) / (u1 - u0));
}

}  // namespace

SegmentIntegral segment_integral(const TransferFunction& tf, double x_f, double x_b, double d) {
    const double l = tf.unit_distance();
    const auto& of = tf.opacity_function();
    const auto& cf = tf.color_function();
    // The pieces: u = 0, every row x strictly between the ends, u = 1.
    std::vector<double> cuts{0.0, 1.0};
    const double lo = std::min(x_f, x_b), hi = std::max(x_f, x_b);
    for (const auto* xs : {&of.xs(), &cf.xs()})
        for (double x : *xs)
            if (x > lo && x < hi) cuts.push_back((x - x_f) / (x_b - x_f));
    // ... and where the opacity crosses the clamp, so that on every piece a is linear or the clamp.
    const auto& ox = of.xs();
    const auto& oy = of.ys();
    for (std::size_t k = 1; k < ox.size(); ++k) {
        const double y0 = oy[k - 1][0], y1 = oy[k][0];
        if ((y0 - kPreIntegrationMaxOpacity) * (y1 - kPreIntegrationMaxOpacity) < 0.0) {
            const double x = ox[k - 1] + (kPreIntegrationMaxOpacity - y0) / (y1 - y0) * (ox[k] - ox[k - 1]);
            if (x > lo && x < hi) cuts.push_back((x - x_f) / (x_b - x_f));
        }
    }
    std::sort(cuts.begin(), cuts.end());
    const gauss_kronrod::Tables& gk = gauss_kronrod::tables();
    SegmentIntegral out;
    double tau = 0.0;  // optical depth from u = 0 to the piece's start, over d (sigma_bar so far)
    for (std::size_t p = 0; p + 1 < cuts.size(); ++p) {
        const double u0 = cuts[p], u1 = cuts[p + 1];
        if (!(u1 > u0)) continue;
        const double um = 0.5 * (u0 + u1);
        auto x_at = [&](double u) { return x_f + (x_b - x_f) * u; };
        // a = ap + aq x and c = cp + cq x on this piece (the rows that hold its midpoint).
        double ap, aq, cp[3], cq[3];
        piece_at(of, x_at(um), 0, ap, aq);
        for (std::size_t c = 0; c < 3; ++c) piece_at(cf, x_at(um), c, cp[c], cq[c]);
        auto a_at = [&](double u) { return std::clamp(ap + aq * x_at(u), 0.0, kPreIntegrationMaxOpacity); };
        // On the piece a is linear, or constant at the clamp (the cuts above): the closed form holds.
        const double a0 = a_at(u0);
        auto depth = [&](double u) { return log_integral(a0, a_at(u), u0, u); };  // integral_{u0}^{u} sigma l
        // The colour integral, K15 against G7 on [ua, ub], halved until they agree to 1e-13, at most kAdaptiveMaxDepth times (sigma has a
        // logarithmic peak where a nears the clamp; elsewhere one rule is enough).
        auto rule = [&](double ua, double ub, glm::dvec3& k, glm::dvec3& g) {
            const double m = 0.5 * (ua + ub), hh = 0.5 * (ub - ua);
            k = g = glm::dvec3(0.0);
            for (int i = 0; i < gauss_kronrod::kNodes; ++i) {
                const double u = m + hh * gk.x[std::size_t(i)];
                const double sigma = -std::log1p(-a_at(u)) / l;
                const double T = std::exp(-d * (tau + depth(u) / l));
                const double x = x_at(u);
                const glm::dvec3 f = hh * d * sigma * T * glm::dvec3(cp[0] + cq[0] * x, cp[1] + cq[1] * x, cp[2] + cq[2] * x);
                k += gk.wk[std::size_t(i)] * f;
                if (i % 2 == 1) g += gk.wg[std::size_t(i / 2)] * f;
            }
        };
        struct Part {
            double a, b;
            int depth;
        };
        std::vector<Part> todo{{u0, u1, 0}};
        while (!todo.empty()) {
            const Part q = todo.back();
            todo.pop_back();
            glm::dvec3 k, g;
            rule(q.a, q.b, k, g);
            const glm::dvec3 e = glm::abs(k - g);
            if (std::max({e.x, e.y, e.z}) <= 1e-13 || q.depth >= conventions::kAdaptiveMaxDepth) {
                out.colour += k;
            } else {
                const double mid = 0.5 * (q.a + q.b);
                todo.push_back({q.a, mid, q.depth + 1});
                todo.push_back({mid, q.b, q.depth + 1});
            }
        }
        tau += depth(u1) / l;
    }
    out.sigma_bar = tau;
    out.alpha = -std::expm1(-d * tau);
    return out;
}

PreIntegrationTable build_preintegration_table(const TransferFunction& tf, double x_lo, double x_hi, double h, int n) {
    PreIntegrationTable t;
    t.n = n;
    t.x0 = x_lo;
    t.dx = x_hi > x_lo ? (x_hi - x_lo) / n : 1.0;
    t.h = h;
    const std::size_t m = std::size_t(n) + 1;
    t.entries.assign(m * m * 4, 0.0f);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            for (std::size_t j = 0; j < m; ++j) {
                const double xf = t.x0 + double(i) * t.dx, xb = t.x0 + double(j) * t.dx;
                const SegmentIntegral s = segment_integral(tf, xf, xb, h);
                float* e = &t.entries[(i * m + j) * 4];
                e[0] = float(s.sigma_bar);
                // c_bar = C / alpha; where nothing is absorbed (alpha = 0) the colour at the middle of the
                // ramp, so that a lookup between this entry and an opaque one blends colours, not black.
                const auto cm = tf.color_function()(0.5 * (xf + xb));
                for (int c = 0; c < 3; ++c)
                    e[1 + c] = s.alpha > 0.0 ? float(s.colour[std::size_t(c)] / s.alpha) : float(cm[std::size_t(c)]);
            }
    });
    return t;
}

void lookup_preintegration(const PreIntegrationTable& t, double x_f, double x_b, double out[4]) {
    using L = ScalarLanes<double>;
    const std::size_t m = std::size_t(t.n) + 1;
    double fi, fj, wi, wj;
    preintegration_axis<L>(x_f, t.x0, 1.0 / t.dx, double(t.n), fi, wi);
    preintegration_axis<L>(x_b, t.x0, 1.0 / t.dx, double(t.n), fj, wj);
    const std::size_t i = std::size_t(fi), j = std::size_t(fj);
    for (std::size_t c = 0; c < 4; ++c) {
        auto e = [&](std::size_t a, std::size_t b) { return double(t.entries[(a * m + b) * 4 + c]); };
        out[c] = preintegration_blend<L>(e(i, j), e(i, j + 1), e(i + 1, j), e(i + 1, j + 1), wi, wj);
    }
}

}  // namespace volref
