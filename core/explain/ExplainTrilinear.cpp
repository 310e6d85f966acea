// explain trilinear: Levoy's lecture form (4 lerps along x, 2 along y, 1 along z) beside the sum
// volref evaluates (Trilinear.h: eight weights times corners, term by term in corner order). Both
// are the same polynomial; they differ only by rounding, which is printed.
#include <cmath>
#include <string>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "core/explain/NumberFormat.h"
#include "core/sample/Trilinear.h"
#include "core/sample/VolumeSampler.h"

namespace volref::explain {

namespace {

constexpr const char* kCorner[8] = {"(0,0,0)", "(1,0,0)", "(1,1,0)", "(0,1,0)",
                                    "(0,0,1)", "(1,0,1)", "(1,1,1)", "(0,1,1)"};

// The lecture's linear interpolation between a (at 0) and b (at 1).
double lerp(double a, double b, double t) { return (1.0 - t) * a + t * b; }

void add_steps(Explanation& e, const std::array<double, 8>& f, const glm::dvec3& pqr) {
    const double p = pqr.x, q = pqr.y, r = pqr.z;
    Section& in = e.section("corners (Levoy's order) and local coordinates");
    for (int n = 0; n < 8; ++n) add(in, "f" + std::to_string(n + 1), f[std::size_t(n)], std::string("corner ") + kCorner[n]);
    add(in, "p", p, "along x");
    add(in, "q", q, "along y");
    add(in, "r", r, "along z");

    Section& x = e.section("x-lerps (Levoy's lecture)");
    const double f12 = lerp(f[0], f[1], p), f43 = lerp(f[3], f[2], p), f56 = lerp(f[4], f[5], p),
                 f87 = lerp(f[7], f[6], p);
    add(x, "f12", f12, "(1-p) f1 + p f2   (y=0, z=0)");
    add(x, "f43", f43, "(1-p) f4 + p f3   (y=1, z=0)");
    add(x, "f56", f56, "(1-p) f5 + p f6   (y=0, z=1)");
    add(x, "f87", f87, "(1-p) f8 + p f7   (y=1, z=1)");
    Section& y = e.section("y-lerps");
    const double f1243 = lerp(f12, f43, q), f5687 = lerp(f56, f87, q);
    add(y, "f1243", f1243, "(1-q) f12 + q f43   (z=0)");
    add(y, "f5687", f5687, "(1-q) f56 + q f87   (z=1)");
    Section& z = e.section("z-lerp");
    const double nested = lerp(f1243, f5687, r);
    add(z, "f", nested, "(1-r) f1243 + r f5687");

    Section& sum = e.section("volref's sum (core/sample/Trilinear.h), term by term");
    const std::array<double, 8> w = trilinear_weights(p, q, r);
    static constexpr const char* kWeight[8] = {"(1-p)(1-q)(1-r)", "p(1-q)(1-r)", "p q (1-r)", "(1-p) q (1-r)",
                                               "(1-p)(1-q) r",    "p(1-q) r",    "p q r",     "(1-p) q r"};
    for (int n = 0; n < 8; ++n) add(sum, "w" + std::to_string(n + 1), w[std::size_t(n)], kWeight[n]);
    for (int n = 0; n < 8; ++n)
        add(sum, "f" + std::to_string(n + 1) + " w" + std::to_string(n + 1), f[std::size_t(n)] * w[std::size_t(n)]);

    Section& res = e.section("result");
    const double value = volref::trilinear(f, p, q, r);
    add(res, "f", value, "volref::trilinear: sum of the eight terms in order");
    add(res, "lerps - f", nested - value, "the lecture's nested form minus volref's (rounding only)");
}

}  // namespace

Explanation trilinear(const std::array<double, 8>& corners, const glm::dvec3& pqr) {
    for (int a = 0; a < 3; ++a)
        if (!(pqr[a] >= 0.0 && pqr[a] <= 1.0))
            throw Error("--point: each of p, q, r must be in [0, 1], got " + number(pqr[a]));
    Explanation e;
    e.topic = "trilinear";
    add_steps(e, corners, pqr);
    return e;
}

Explanation trilinear_at(const VolumeSampler& sampler, const glm::dvec3& world) {
    Explanation e;
    e.topic = "trilinear";
    const Volume& v = sampler.volume();
    Section& g = e.section("grid");
    add(g, "x", {world.x, world.y, world.z}, "the world point");
    add(g, "origin", {v.origin.x, v.origin.y, v.origin.z});
    add(g, "spacing", {v.spacing.x, v.spacing.y, v.spacing.z});
    add(g, "dims", {double(v.dims[0]), double(v.dims[1]), double(v.dims[2])});
    const glm::dvec3 u = sampler.continuous_index(world);
    add(g, "u", {u.x, u.y, u.z}, "(x - origin) / spacing, clamped to [0, n - 1]");
    std::array<std::int64_t, 3> cell;
    glm::dvec3 frac;
    sampler.locate(u, cell, frac);
    add(g, "cell", {double(cell[0]), double(cell[1]), double(cell[2])}, "min(floor(u), n - 2) (0 when n = 1)");
    add(g, "(p, q, r)", {frac.x, frac.y, frac.z}, "u - cell");
    add_steps(e, sampler.corners(cell), frac);
    if (sampler.interpolation() == Interpolation::Trilinear)
        add(e.sections.back(), "VolumeSampler::value", sampler.value(world), "the renderer's sample at x");
    else
        e.sections.back().notes.push_back("(the volume's interpolation is not trilinear: the renderer reconstructs differently)");
    return e;
}

}  // namespace volref::explain
