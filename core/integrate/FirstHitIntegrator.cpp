#include "core/integrate/FirstHitIntegrator.h"

#include <optional>

#include "core/Conventions.h"
#include "core/integrate/Segments.h"

namespace volref {

namespace {

int sign(double x) { return (x > 0.0) - (x < 0.0); }

}  // namespace

PixelValue FirstHitIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    const double iso = *ctx_.render.isovalue;
    auto g = [&](double t) { return ctx_.field(ray, t) - iso; };
    std::optional<double> hit;
    for (const Interval& iv : intervals) {
        const std::int64_t n = segment_count(iv, ctx_.step);
        double ta = iv.t0, ga = g(ta);
        if (ga == 0.0) {
            hit = ta;
            break;
        }
        for (std::int64_t k = 0; k < n && !hit; ++k) {
            const double tb = segment(iv, ctx_.step, k, n).t1, gb = g(tb);
            if (gb == 0.0) {
                hit = tb;
            } else if (sign(gb) != sign(ga)) {
                // Bisection on [ta, tb]; ga keeps the sign at ta.
                double lo = ta, hi = tb, glo = ga;
                const double tol = conventions::kFirstHitRelativeTolerance * iv.length();
                for (int it = 0; it < 200 && hi - lo > tol; ++it) {
                    const double m = 0.5 * (lo + hi), gm = g(m);
                    if (gm == 0.0) {
                        lo = hi = m;
                        break;
                    }
                    if (sign(gm) == sign(glo)) {
                        lo = m;
                        glo = gm;
                    } else {
                        hi = m;
                    }
                }
                hit = 0.5 * (lo + hi);
            }
            ta = tb;
            ga = gb;
        }
        if (hit) break;
    }
    PixelValue out;
    if (hit) {
        out.rgba = glm::dvec4(ctx_.pipeline.sample(ray, *hit, SamplePipeline::Use::Surface).color, 1.0);
        out.depth = *hit;
    }
    return out;
}

}  // namespace volref
