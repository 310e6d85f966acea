// Gradients against closed forms (conventions section 2, GradientField.h).
#include <gtest/gtest.h>

#include <random>

#include "core/grid/ProceduralField.h"
#include "core/render/Renderer.h"
#include "core/sample/GradientField.h"
#include "transfer/TransferFunction.h"

using namespace volref;

namespace {
Volume make(FieldSpec f, glm::dvec3 origin, glm::dvec3 spacing) { return make_procedural_volume(f, origin, spacing); }

FieldSpec linear(std::array<double, 4> c, std::array<std::int64_t, 3> dims) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Linear;
    f.coefficients = c;
    f.dims = dims;
    return f;
}
}  // namespace

// On a linear field every scheme is exact everywhere: interior, faces, edges and corners.
TEST(Gradient, ExactOnLinearFieldsEverywhere) {
    const glm::dvec3 origin(-1.0, 0.5, 2.0), spacing(0.5, 0.25, 0.75);
    const Volume v = make(linear({0.7, -1.3, 2.1, 0.25}, {6, 9, 5}), origin, spacing);
    const VolumeSampler s(v, Interpolation::Trilinear);
    const glm::dvec3 lo = v.domain_min(), hi = v.domain_max();
    std::vector<glm::dvec3> points{lo, hi, {lo.x, hi.y, lo.z}, {hi.x, lo.y, hi.z}, 0.5 * (lo + hi)};
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int n = 0; n < 200; ++n) points.push_back(lo + glm::dvec3(u(rng), u(rng), u(rng)) * (hi - lo));
    for (auto scheme : {GradientSpec::Scheme::Central, GradientSpec::Scheme::Forward})
        for (bool cache : {false, true}) {
            const GradientField g(s, {scheme, cache});
            for (const glm::dvec3& p : points) {
                const glm::dvec3 grad = g.gradient(p);
                EXPECT_NEAR(grad.x, 0.7, 1e-12);
                EXPECT_NEAR(grad.y, -1.3, 1e-12);
                EXPECT_NEAR(grad.z, 2.1, 1e-12);
            }
        }
}

// At a voxel of f = x^2 (spacing h): the central difference is exact for quadratics,
// (f(x+h) - f(x-h)) / 2h = 2x; the forward difference is (f(x+h) - f(x)) / h = 2x + h; at the
// upper boundary the backward difference is 2x - h; at the lower boundary central becomes forward.
TEST(Gradient, CentralAndForwardOnAQuadratic) {
    FieldSpec cells;
    cells.kind = FieldSpec::Kind::Cells;
    cells.dims = {6, 1, 1};
    const double h = 0.5;
    for (int i = 0; i < 6; ++i) cells.values.push_back((i * h) * (i * h));
    const Volume v = make_procedural_volume(cells, glm::dvec3(0.0), glm::dvec3(h, 1.0, 1.0));
    const VolumeSampler s(v, Interpolation::Trilinear);
    const GradientField central(s, {GradientSpec::Scheme::Central, false});
    const GradientField forward(s, {GradientSpec::Scheme::Forward, false});
    for (int i = 1; i < 5; ++i) {
        const glm::dvec3 p(i * h, 0, 0);
        EXPECT_NEAR(central.gradient(p).x, 2 * i * h, 1e-13) << i;
        EXPECT_NEAR(forward.gradient(p).x, 2 * i * h + h, 1e-13) << i;
        EXPECT_EQ(central.gradient(p).y, 0.0);  // a flat axis
    }
    EXPECT_NEAR(central.gradient({0, 0, 0}).x, h, 1e-13);              // forward at the low end: (h^2 - 0) / h
    EXPECT_NEAR(forward.gradient({5 * h, 0, 0}).x, 2 * 5 * h - h, 1e-13);  // backward at the top
    EXPECT_NEAR(central.gradient({5 * h, 0, 0}).x, 2 * 5 * h - h, 1e-13);
}

// The analytic tricubic gradient (Catmull-Rom reproduces quadratics) in world units.
TEST(Gradient, AnalyticTricubicInWorldUnits) {
    FieldSpec cells;
    cells.kind = FieldSpec::Kind::Cells;
    cells.dims = {8, 1, 1};
    const double h = 0.25;
    for (int i = 0; i < 8; ++i) cells.values.push_back(3.0 * (i * h) * (i * h));
    const Volume v = make_procedural_volume(cells, glm::dvec3(0.0), glm::dvec3(h, 1.0, 1.0));
    const VolumeSampler s(v, Interpolation::TricubicCatmullRom);
    const GradientField g(s, {GradientSpec::Scheme::Default, false});
    EXPECT_EQ(g.scheme(), GradientSpec::Scheme::Analytic);
    for (double x : {0.3, 0.8, 1.1, 1.2}) EXPECT_NEAR(g.gradient({x, 0, 0}).x, 6.0 * x, 1e-12) << x;
}

// "cache": "auto": e = pixels (diagonal / step) (visible fraction) / voxels against the break-even 2.
TEST(Gradient, AutoCacheRule) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Linear;
    g.coefficients = {1, 0, 0, 0};
    g.dims = {11, 11, 11};  // values 0..10 along x; diagonal 10 sqrt(3)
    const Volume v = make_procedural_volume(g, glm::dvec3(0.0), glm::dvec3(1.0));
    TransferSpec tf;
    tf.opacity = {{0, 0}, {5, 0}, {5, 1}};  // visible where x >= 5: 6 of 11 columns
    const TransferFunction t(tf, v);
    GradientSpec spec;
    spec.cache_auto = true;
    ImageSpec image;
    // 4 x 4 pixels, step 1: e = 16 * 17.32 * (6/11) / 1331 = 0.114 -> no cache.
    image.width = image.height = 4;
    EXPECT_FALSE(resolve_gradient_cache(spec, v, t, image, 1.0).cache);
    // 64 x 64 pixels: e = 4096 * 17.32 * 0.545 / 1331 = 29 -> cache.
    image.width = image.height = 64;
    const GradientSpec r = resolve_gradient_cache(spec, v, t, image, 1.0);
    EXPECT_TRUE(r.cache);
    EXPECT_FALSE(r.cache_auto);
    // Not asked: never cached.
    EXPECT_FALSE(resolve_gradient_cache(GradientSpec{}, v, t, image, 1.0).cache);
}
