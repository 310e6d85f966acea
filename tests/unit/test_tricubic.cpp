// Tricubic reconstruction against closed forms and hand-clamped tap sums (core/sample/Tricubic.h).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>

#include "core/grid/Volume.h"
#include "core/sample/Tricubic.h"

using namespace volref;

namespace {

constexpr CubicKernel kKernels[] = {CubicKernel::BSpline, CubicKernel::CatmullRom};

// A Volume with unit spacing whose voxel (i, j, k) holds f(i, j, k) (index units).
Volume make_volume(std::array<std::int64_t, 3> dims, const std::function<double(double, double, double)>& f) {
    Volume v;
    v.dims = dims;
    v.values.resize(std::size_t(dims[0] * dims[1] * dims[2]));
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j)
            for (std::int64_t i = 0; i < dims[0]; ++i) v.values[v.index(i, j, k)] = f(double(i), double(j), double(k));
    return v;
}

// Random continuous index with each component in [lo[a], hi[a]].
glm::dvec3 random_point(std::mt19937_64& rng, const glm::dvec3& lo, const glm::dvec3& hi) {
    std::uniform_real_distribution<double> d(0.0, 1.0);
    glm::dvec3 u;
    for (int a = 0; a < 3; ++a) u[a] = lo[a] + (hi[a] - lo[a]) * d(rng);
    return u;
}

// The interior of a volume: the points whose 4 taps per axis are all inside, u in [1, n - 2].
glm::dvec3 interior_lo() { return glm::dvec3(1.0); }
glm::dvec3 interior_hi(const Volume& v) {
    return glm::dvec3(double(v.dims[0] - 2), double(v.dims[1] - 2), double(v.dims[2] - 2));
}
glm::dvec3 domain_hi(const Volume& v) {
    return glm::dvec3(double(v.dims[0] - 1), double(v.dims[1] - 1), double(v.dims[2] - 1));
}

// The quadratic of the brief and its gradient (index units).
double quad(double x, double y, double z) {
    return 1.0 + 2.0 * x - y + 0.5 * z + x * x - 0.3 * x * y + 0.7 * z * z + 0.2 * y * z;
}
glm::dvec3 quad_gradient(const glm::dvec3& u) {
    return {2.0 + 2.0 * u.x - 0.3 * u.y, -1.0 - 0.3 * u.x + 0.2 * u.z, 0.5 + 1.4 * u.z + 0.2 * u.y};
}

// The hand calculation: sum over the 4 x 4 x 4 listed taps of wx wy wz f, given the tap index lists
// per axis (written out by the test, not computed by clamping).
double hand_sum(const Volume& v, const std::array<double, 4>& wx, const std::array<double, 4>& wy,
                const std::array<double, 4>& wz, const std::array<std::int64_t, 4>& ix,
                const std::array<std::int64_t, 4>& iy, const std::array<std::int64_t, 4>& iz) {
    double s = 0.0;
    for (int c = 0; c < 4; ++c)
        for (int b = 0; b < 4; ++b)
            for (int a = 0; a < 4; ++a) s += wx[a] * wy[b] * wz[c] * v.at(ix[a], iy[b], iz[c]);
    return s;
}

std::array<double, 4> weights(CubicKernel k, double t) {
    std::array<double, 4> w, dw;
    cubic_weights(k, t, w, dw);
    return w;
}
std::array<double, 4> dweights(CubicKernel k, double t) {
    std::array<double, 4> w, dw;
    cubic_weights(k, t, w, dw);
    return dw;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Weights

TEST(Tricubic, WeightsSumToOneAndDerivativesToZero) {
    for (CubicKernel k : kKernels) {
        for (int n = 0; n <= 1000; ++n) {
            const double t = n / 1000.0;
            std::array<double, 4> w, dw;
            cubic_weights(k, t, w, dw);
            EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0, 1e-15) << "t = " << t;
            EXPECT_NEAR(dw[0] + dw[1] + dw[2] + dw[3], 0.0, 1e-15) << "t = " << t;
        }
    }
}

TEST(Tricubic, DerivativeWeightsAreTheDerivatives) {
    const double h = 1e-6;
    for (CubicKernel k : kKernels) {
        for (int n = 1; n < 100; ++n) {
            const double t = n / 100.0;
            const auto wp = weights(k, t + h), wm = weights(k, t - h), dw = dweights(k, t);
            for (int m = 0; m < 4; ++m) EXPECT_NEAR((wp[m] - wm[m]) / (2.0 * h), dw[m], 1e-8) << "t = " << t;
        }
    }
}

TEST(Tricubic, WeightsAtTheCellEnds) {
    const auto b0 = weights(CubicKernel::BSpline, 0.0);
    EXPECT_DOUBLE_EQ(b0[0], 1.0 / 6.0);
    EXPECT_DOUBLE_EQ(b0[1], 4.0 / 6.0);
    EXPECT_DOUBLE_EQ(b0[2], 1.0 / 6.0);
    EXPECT_EQ(b0[3], 0.0);
    const auto b1 = weights(CubicKernel::BSpline, 1.0);
    EXPECT_EQ(b1[0], 0.0);
    EXPECT_DOUBLE_EQ(b1[1], 1.0 / 6.0);
    EXPECT_DOUBLE_EQ(b1[2], 4.0 / 6.0);
    EXPECT_DOUBLE_EQ(b1[3], 1.0 / 6.0);
    // Catmull-Rom interpolates: exactly (0, 1, 0, 0) at t = 0 and (0, 0, 1, 0) at t = 1.
    EXPECT_EQ(weights(CubicKernel::CatmullRom, 0.0), (std::array<double, 4>{0.0, 1.0, 0.0, 0.0}));
    EXPECT_EQ(weights(CubicKernel::CatmullRom, 1.0), (std::array<double, 4>{0.0, 0.0, 1.0, 0.0}));
    // Both have slope (f[i+1] - f[i-1]) / 2 at t = 0.
    for (CubicKernel k : kKernels)
        EXPECT_EQ(dweights(k, 0.0), (std::array<double, 4>{-0.5, 0.0, 0.5, 0.0}));
    // The cubic B-spline at the centre of a cell: (1, 23, 23, 1) / 48.
    const auto bh = weights(CubicKernel::BSpline, 0.5);
    EXPECT_DOUBLE_EQ(bh[0], 1.0 / 48.0);
    EXPECT_DOUBLE_EQ(bh[1], 23.0 / 48.0);
    EXPECT_DOUBLE_EQ(bh[2], 23.0 / 48.0);
    EXPECT_DOUBLE_EQ(bh[3], 1.0 / 48.0);
    // Catmull-Rom at the centre: (-1, 9, 9, -1) / 16.
    const auto ch = weights(CubicKernel::CatmullRom, 0.5);
    EXPECT_DOUBLE_EQ(ch[0], -1.0 / 16.0);
    EXPECT_DOUBLE_EQ(ch[1], 9.0 / 16.0);
    EXPECT_DOUBLE_EQ(ch[2], 9.0 / 16.0);
    EXPECT_DOUBLE_EQ(ch[3], -1.0 / 16.0);
}

// ---------------------------------------------------------------------------------------------------
// Polynomial reproduction

TEST(Tricubic, CatmullRomReproducesQuadraticsInTheInterior) {
    const Volume v = make_volume({8, 7, 9}, quad);
    std::mt19937_64 rng(3);
    for (int n = 0; n < 500; ++n) {
        const glm::dvec3 u = random_point(rng, interior_lo(), interior_hi(v));
        const double f = quad(u.x, u.y, u.z);
        EXPECT_NEAR(tricubic(v, CubicKernel::CatmullRom, u), f, 1e-12) << u.x << " " << u.y << " " << u.z;
        const glm::dvec3 g = tricubic_index_gradient(v, CubicKernel::CatmullRom, u);
        const glm::dvec3 e = quad_gradient(u);
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(g[a], e[a], 1e-12) << "axis " << a;
    }
    // The interior's corners and cell boundaries too.
    for (double x : {1.0, 3.0, 6.0})
        for (double y : {1.0, 2.5, 5.0})
            for (double z : {1.0, 4.0, 7.0}) {
                const glm::dvec3 u(x, y, z);
                EXPECT_NEAR(tricubic(v, CubicKernel::CatmullRom, u), quad(x, y, z), 1e-12);
                const glm::dvec3 g = tricubic_index_gradient(v, CubicKernel::CatmullRom, u);
                for (int a = 0; a < 3; ++a) EXPECT_NEAR(g[a], quad_gradient(u)[a], 1e-12);
            }
}

TEST(Tricubic, CatmullRomInterpolatesEveryVoxelExactly) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> d(-10.0, 10.0);
    Volume v = make_volume({5, 4, 6}, [&](double, double, double) { return d(rng); });
    for (std::int64_t k = 0; k < 6; ++k)
        for (std::int64_t j = 0; j < 4; ++j)
            for (std::int64_t i = 0; i < 5; ++i)
                EXPECT_EQ(tricubic(v, CubicKernel::CatmullRom, glm::dvec3(double(i), double(j), double(k))),
                          v.at(i, j, k))
                    << i << " " << j << " " << k;
}

TEST(Tricubic, BSplineReproducesLinearFunctionsInTheInterior) {
    const auto lin = [](double x, double y, double z) { return 3.0 + 0.5 * x - 2.0 * y + 1.25 * z; };
    const Volume v = make_volume({7, 8, 6}, lin);
    std::mt19937_64 rng(7);
    for (int n = 0; n < 500; ++n) {
        const glm::dvec3 u = random_point(rng, interior_lo(), interior_hi(v));
        EXPECT_NEAR(tricubic(v, CubicKernel::BSpline, u), lin(u.x, u.y, u.z), 1e-12);
        const glm::dvec3 g = tricubic_index_gradient(v, CubicKernel::BSpline, u);
        EXPECT_NEAR(g.x, 0.5, 1e-12);
        EXPECT_NEAR(g.y, -2.0, 1e-12);
        EXPECT_NEAR(g.z, 1.25, 1e-12);
    }
    // Catmull-Rom reproduces them as well.
    for (int n = 0; n < 100; ++n) {
        const glm::dvec3 u = random_point(rng, interior_lo(), interior_hi(v));
        EXPECT_NEAR(tricubic(v, CubicKernel::CatmullRom, u), lin(u.x, u.y, u.z), 1e-12);
    }
}

// The B-spline blurs: for f = x^2, sum_k w_k(t) (i - 1 + k)^2 = (i + t)^2 + 1/3 = u^2 + 1/3 (the
// kernel's variance), so it does not reproduce quadratics. (With x = i + t: the weights' mean is
// sum_k w_k (k - 1) = t and their second moment sum_k w_k (k - 1)^2 = t^2 + 1/3.)
TEST(Tricubic, BSplineBlursAQuadraticByOneThird) {
    // The 1-D closed form straight from the weights, for several cells.
    for (int i = 1; i <= 5; ++i)
        for (int n = 0; n <= 100; ++n) {
            const double t = n / 100.0, u = i + t;
            const auto w = weights(CubicKernel::BSpline, t);
            double s = 0.0;
            for (int m = 0; m < 4; ++m) s += w[m] * double(i - 1 + m) * double(i - 1 + m);
            EXPECT_NEAR(s, u * u + 1.0 / 3.0, 1e-12) << "u = " << u;
        }
    // Through the volume along x (the other axes constant in the field).
    const Volume v = make_volume({9, 5, 4}, [](double x, double, double) { return x * x; });
    std::mt19937_64 rng(11);
    for (int n = 0; n < 300; ++n) {
        const glm::dvec3 u = random_point(rng, interior_lo(), interior_hi(v));
        EXPECT_NEAR(tricubic(v, CubicKernel::BSpline, u), u.x * u.x + 1.0 / 3.0, 1e-12);
        EXPECT_GT(std::abs(tricubic(v, CubicKernel::BSpline, u) - u.x * u.x), 0.33);  // not reproduced
        // The blur is a constant, so the derivative is still exact.
        const glm::dvec3 g = tricubic_index_gradient(v, CubicKernel::BSpline, u);
        EXPECT_NEAR(g.x, 2.0 * u.x, 1e-12);
        EXPECT_NEAR(g.y, 0.0, 1e-12);
        EXPECT_NEAR(g.z, 0.0, 1e-12);
    }
    // In 3-D: |u|^2 gives |u|^2 + 1; and the brief's quadratic gains (1 + 0.7) / 3 (cross terms
    // are products of linear factors, reproduced exactly).
    const Volume r2 = make_volume({6, 7, 8}, [](double x, double y, double z) { return x * x + y * y + z * z; });
    const Volume q = make_volume({8, 7, 9}, quad);
    for (int n = 0; n < 300; ++n) {
        const glm::dvec3 u = random_point(rng, interior_lo(), interior_hi(r2));
        EXPECT_NEAR(tricubic(r2, CubicKernel::BSpline, u), u.x * u.x + u.y * u.y + u.z * u.z + 1.0, 1e-12);
        const glm::dvec3 p = random_point(rng, interior_lo(), interior_hi(q));
        EXPECT_NEAR(tricubic(q, CubicKernel::BSpline, p), quad(p.x, p.y, p.z) + 1.7 / 3.0, 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------------
// Gradient

// A smooth non-polynomial field; the analytic gradient against a central difference of tricubic()
// over the whole domain (the reconstruction is C1 everywhere, borders included, since clamped taps
// are the convolution with the edge-replicated sequence).
TEST(Tricubic, GradientMatchesCentralDifferences) {
    const Volume v = make_volume({9, 8, 10}, [](double x, double y, double z) {
        return std::sin(0.7 * x) * std::cos(0.4 * y) + 0.3 * std::exp(0.15 * z) + 0.05 * x * y * z;
    });
    const double h = 1e-6;
    std::mt19937_64 rng(13);
    for (CubicKernel k : kKernels) {
        for (int n = 0; n < 400; ++n) {
            const glm::dvec3 u = random_point(rng, glm::dvec3(2.0 * h), domain_hi(v) - 2.0 * h);
            const glm::dvec3 g = tricubic_index_gradient(v, k, u);
            for (int a = 0; a < 3; ++a) {
                glm::dvec3 up = u, um = u;
                up[a] += h;
                um[a] -= h;
                const double fd = (tricubic(v, k, up) - tricubic(v, k, um)) / (2.0 * h);
                EXPECT_NEAR(g[a], fd, 1e-6 * std::max(1.0, std::abs(fd)))
                    << "kernel " << int(k) << " axis " << a << " at " << u.x << " " << u.y << " " << u.z;
            }
        }
    }
}

TEST(Tricubic, ValueAndGradientAgreeBitForBitWithTheSeparateCalls) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> d(-5.0, 5.0);
    Volume v = make_volume({6, 5, 7}, [&](double, double, double) { return d(rng); });
    for (CubicKernel k : kKernels)
        for (int n = 0; n < 200; ++n) {
            const glm::dvec3 u = random_point(rng, glm::dvec3(-0.5), domain_hi(v) + 0.5);
            glm::dvec3 g;
            const double f = tricubic_value_and_index_gradient(v, k, u, g);
            EXPECT_EQ(f, tricubic(v, k, u));
            const glm::dvec3 g2 = tricubic_index_gradient(v, k, u);
            EXPECT_EQ(g.x, g2.x);
            EXPECT_EQ(g.y, g2.y);
            EXPECT_EQ(g.z, g2.z);
        }
}

// ---------------------------------------------------------------------------------------------------
// Borders

// Along x on a 1-D row: at the low border (cell [0, 1]) the taps are f[0], f[0], f[1], f[2]; at the
// high border (cell [n-2, n-1]) they are f[n-3], f[n-2], f[n-1], f[n-1].
TEST(Tricubic, BorderTapsClampOnARow) {
    const double f[6] = {2.0, -1.0, 4.5, 3.0, 0.25, 7.0};
    Volume v = make_volume({6, 1, 1}, [&](double x, double, double) { return f[int(x)]; });
    for (CubicKernel k : kKernels) {
        for (double u : {0.0, 0.2, 0.5, 0.9, 0.999999}) {
            const auto w = weights(k, u), dw = dweights(k, u);
            const double e = w[0] * f[0] + w[1] * f[0] + w[2] * f[1] + w[3] * f[2];
            const double de = dw[0] * f[0] + dw[1] * f[0] + dw[2] * f[1] + dw[3] * f[2];
            EXPECT_NEAR(tricubic(v, k, {u, 0.0, 0.0}), e, 1e-13) << "u = " << u;
            EXPECT_NEAR(tricubic_index_gradient(v, k, {u, 0.0, 0.0}).x, de, 1e-13) << "u = " << u;
        }
        for (double u : {4.0, 4.3, 4.5, 4.8, 5.0}) {  // n - 2 = 4, n - 1 = 5
            const double t = u - 4.0;
            const auto w = weights(k, t), dw = dweights(k, t);
            const double e = w[0] * f[3] + w[1] * f[4] + w[2] * f[5] + w[3] * f[5];
            const double de = dw[0] * f[3] + dw[1] * f[4] + dw[2] * f[5] + dw[3] * f[5];
            EXPECT_NEAR(tricubic(v, k, {u, 0.0, 0.0}), e, 1e-13) << "u = " << u;
            EXPECT_NEAR(tricubic_index_gradient(v, k, {u, 0.0, 0.0}).x, de, 1e-13) << "u = " << u;
        }
        // Outside the domain the point is clamped first.
        EXPECT_EQ(tricubic(v, k, {-3.0, 0.0, 0.0}), tricubic(v, k, {0.0, 0.0, 0.0}));
        EXPECT_EQ(tricubic(v, k, {9.0, 0.0, 0.0}), tricubic(v, k, {5.0, 0.0, 0.0}));
        EXPECT_EQ(tricubic(v, k, {2.5, -1.0, 4.0}), tricubic(v, k, {2.5, 0.0, 0.0}));
    }
    // B-spline at u = 0 by hand: (1/6 + 4/6) f0 + 1/6 f1 = (5 * 2 - 1) / 6 = 1.5; slope (f1 - f0) / 2.
    EXPECT_NEAR(tricubic(v, CubicKernel::BSpline, {0.0, 0.0, 0.0}), 1.5, 1e-15);
    EXPECT_NEAR(tricubic_index_gradient(v, CubicKernel::BSpline, {0.0, 0.0, 0.0}).x, -1.5, 1e-15);
    // At u = n - 1 (cell [4, 5], t = 1): 0 f3 + 1/6 f4 + 4/6 f5 + 1/6 f5 = (0.25 + 5 * 7) / 6; slope (f5 - f4) / 2.
    EXPECT_NEAR(tricubic(v, CubicKernel::BSpline, {5.0, 0.0, 0.0}), 35.25 / 6.0, 1e-14);
    EXPECT_NEAR(tricubic_index_gradient(v, CubicKernel::BSpline, {5.0, 0.0, 0.0}).x, 3.375, 1e-14);
}

// In 3-D near the (0, 0, 0) corner and the opposite corner of a 5 x 6 x 5 volume, against the
// 64-term sum over hand-written tap lists.
TEST(Tricubic, BorderTapsClampIn3D) {
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> d(-3.0, 3.0);
    Volume v = make_volume({5, 6, 5}, [&](double, double, double) { return d(rng); });
    for (CubicKernel k : kKernels) {
        {   // Low corner: every axis in its cell [0, 1], taps 0, 0, 1, 2.
            const glm::dvec3 u(0.25, 0.5, 0.75);
            const std::array<std::int64_t, 4> taps{0, 0, 1, 2};
            const double e = hand_sum(v, weights(k, 0.25), weights(k, 0.5), weights(k, 0.75), taps, taps, taps);
            EXPECT_NEAR(tricubic(v, k, u), e, 1e-12);
            const glm::dvec3 g = tricubic_index_gradient(v, k, u);
            EXPECT_NEAR(g.x, hand_sum(v, dweights(k, 0.25), weights(k, 0.5), weights(k, 0.75), taps, taps, taps), 1e-12);
            EXPECT_NEAR(g.y, hand_sum(v, weights(k, 0.25), dweights(k, 0.5), weights(k, 0.75), taps, taps, taps), 1e-12);
            EXPECT_NEAR(g.z, hand_sum(v, weights(k, 0.25), weights(k, 0.5), dweights(k, 0.75), taps, taps, taps), 1e-12);
        }
        {   // High corner: x in [3, 4] (taps 2, 3, 4, 4), y in [4, 5] (taps 3, 4, 5, 5), z at 4 (cell [3, 4], t = 1).
            const glm::dvec3 u(3.6, 4.1, 4.0);
            const std::array<std::int64_t, 4> tx{2, 3, 4, 4}, ty{3, 4, 5, 5}, tz{2, 3, 4, 4};
            const double px = 0.6, py = u.y - 4.0, pz = 1.0;
            EXPECT_NEAR(tricubic(v, k, u), hand_sum(v, weights(k, px), weights(k, py), weights(k, pz), tx, ty, tz), 1e-12);
            const glm::dvec3 g = tricubic_index_gradient(v, k, u);
            EXPECT_NEAR(g.x, hand_sum(v, dweights(k, px), weights(k, py), weights(k, pz), tx, ty, tz), 1e-12);
            EXPECT_NEAR(g.y, hand_sum(v, weights(k, px), dweights(k, py), weights(k, pz), tx, ty, tz), 1e-12);
            EXPECT_NEAR(g.z, hand_sum(v, weights(k, px), weights(k, py), dweights(k, pz), tx, ty, tz), 1e-12);
        }
        {   // Mixed: x in the interior (cell [2, 3], taps 1..4), y low border, z high border.
            const glm::dvec3 u(2.3, 0.9, 3.2);
            const std::array<std::int64_t, 4> tx{1, 2, 3, 4}, ty{0, 0, 1, 2}, tz{2, 3, 4, 4};
            const double px = u.x - 2.0, py = 0.9, pz = u.z - 3.0;
            EXPECT_NEAR(tricubic(v, k, u), hand_sum(v, weights(k, px), weights(k, py), weights(k, pz), tx, ty, tz), 1e-12);
        }
    }
}

// An axis with n = 1 uses its single layer: the value is the 2-D bicubic of that layer whatever u
// on that axis, and that gradient component is exactly 0.
TEST(Tricubic, SingleLayerAxis) {
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> d(-3.0, 3.0);
    Volume v = make_volume({5, 1, 4}, [&](double, double, double) { return d(rng); });
    const std::array<double, 4> one{0.0, 1.0, 0.0, 0.0};
    const std::array<std::int64_t, 4> ty{0, 0, 0, 0};
    for (CubicKernel k : kKernels)
        for (double y : {0.0, 0.4, -2.0, 3.0}) {
            const glm::dvec3 u(1.7, y, 2.2);  // x: cell [1, 2], taps 0..3; z: cell [2, 3], taps 1, 2, 3, 3
            const std::array<std::int64_t, 4> tx{0, 1, 2, 3}, tz{1, 2, 3, 3};
            const double px = u.x - 1.0, pz = u.z - 2.0;
            const double e = hand_sum(v, weights(k, px), one, weights(k, pz), tx, ty, tz);
            EXPECT_NEAR(tricubic(v, k, u), e, 1e-13);
            glm::dvec3 g;
            EXPECT_NEAR(tricubic_value_and_index_gradient(v, k, u, g), e, 1e-13);
            EXPECT_EQ(g.y, 0.0);
            EXPECT_NEAR(g.x, hand_sum(v, dweights(k, px), one, weights(k, pz), tx, ty, tz), 1e-13);
            EXPECT_NEAR(g.z, hand_sum(v, weights(k, px), one, dweights(k, pz), tx, ty, tz), 1e-13);
        }
    // A single voxel: its value exactly and a zero gradient.
    Volume one_voxel = make_volume({1, 1, 1}, [](double, double, double) { return 0.1; });
    for (CubicKernel k : kKernels)
        for (const glm::dvec3& u : {glm::dvec3(0.0), glm::dvec3(0.3, -1.0, 5.0)}) {
            glm::dvec3 g;
            EXPECT_EQ(tricubic_value_and_index_gradient(one_voxel, k, u, g), 0.1);
            EXPECT_EQ(g.x, 0.0);
            EXPECT_EQ(g.y, 0.0);
            EXPECT_EQ(g.z, 0.0);
        }
    // A line along z: only the z gradient is non-zero.
    Volume line = make_volume({1, 1, 5}, [](double, double, double z) { return 2.0 * z - 1.0; });
    for (CubicKernel k : kKernels) {
        glm::dvec3 g;
        const double f = tricubic_value_and_index_gradient(line, k, {0.0, 0.0, 2.5}, g);
        EXPECT_NEAR(f, 4.0, 1e-13);  // linear in the interior: both kernels reproduce it
        EXPECT_EQ(g.x, 0.0);
        EXPECT_EQ(g.y, 0.0);
        EXPECT_NEAR(g.z, 2.0, 1e-13);
    }
}

// A 2 x 2 x 2 volume: one cell whose taps on every axis are 0, 0, 1, 1, so per axis the weights
// collapse to (w0 + w1, w2 + w3).
TEST(Tricubic, TwoByTwoByTwo) {
    Volume v = make_volume({2, 2, 2}, [](double x, double y, double z) { return 1.0 + x + 2.0 * y * z - 3.0 * x * y * z; });
    const std::array<std::int64_t, 4> taps{0, 0, 1, 1};
    for (CubicKernel k : kKernels) {
        for (const glm::dvec3& u : {glm::dvec3(0.0), glm::dvec3(0.3, 0.6, 0.9), glm::dvec3(1.0), glm::dvec3(0.5, 1.0, 0.0)}) {
            const double e = hand_sum(v, weights(k, u.x), weights(k, u.y), weights(k, u.z), taps, taps, taps);
            glm::dvec3 g;
            EXPECT_NEAR(tricubic_value_and_index_gradient(v, k, u, g), e, 1e-13);
            EXPECT_NEAR(g.x, hand_sum(v, dweights(k, u.x), weights(k, u.y), weights(k, u.z), taps, taps, taps), 1e-13);
            EXPECT_NEAR(g.y, hand_sum(v, weights(k, u.x), dweights(k, u.y), weights(k, u.z), taps, taps, taps), 1e-13);
            EXPECT_NEAR(g.z, hand_sum(v, weights(k, u.x), weights(k, u.y), dweights(k, u.z), taps, taps, taps), 1e-13);
        }
    }
    // The collapsed 1-D weights on the x edge (Catmull-Rom, which is (0, 1, 0, 0) at y = z = 0):
    // (w0 + w1) f(0, 0, 0) + (w2 + w3) f(1, 0, 0).
    const auto w = weights(CubicKernel::CatmullRom, 0.3);
    EXPECT_NEAR(tricubic(v, CubicKernel::CatmullRom, {0.3, 0.0, 0.0}), (w[0] + w[1]) * 1.0 + (w[2] + w[3]) * 2.0, 1e-14);
    // The B-spline at a corner also mixes in the neighbours: per axis (5/6, 1/6) on the layers 0, 1.
    const double a = 5.0 / 6.0, b = 1.0 / 6.0;
    double e = 0.0;
    for (int c = 0; c < 8; ++c) {
        const int i = c & 1, j = (c >> 1) & 1, kk = c >> 2;
        e += (i ? b : a) * (j ? b : a) * (kk ? b : a) * v.at(i, j, kk);
    }
    EXPECT_NEAR(tricubic(v, CubicKernel::BSpline, glm::dvec3(0.0)), e, 1e-14);
    // Catmull-Rom interpolates the 8 corners; the B-spline does not (it smooths between them).
    for (int c = 0; c < 8; ++c) {
        const int i = c & 1, j = (c >> 1) & 1, kk = c >> 2;
        EXPECT_EQ(tricubic(v, CubicKernel::CatmullRom, glm::dvec3(i, j, kk)), v.at(i, j, kk));
    }
    EXPECT_NE(tricubic(v, CubicKernel::BSpline, glm::dvec3(0.0)), v.at(0, 0, 0));
}

// ---------------------------------------------------------------------------------------------------
// Constant field

TEST(Tricubic, ConstantFieldGivesTheConstantAndZeroGradient) {
    const double c = 2.75;
    for (const std::array<std::int64_t, 3>& dims :
         {std::array<std::int64_t, 3>{4, 5, 3}, std::array<std::int64_t, 3>{2, 2, 2},
          std::array<std::int64_t, 3>{7, 1, 3}}) {
        Volume v = make_volume(dims, [&](double, double, double) { return c; });
        std::mt19937_64 rng(29);
        for (CubicKernel k : kKernels) {
            auto check = [&](const glm::dvec3& u) {
                glm::dvec3 g;
                EXPECT_NEAR(tricubic_value_and_index_gradient(v, k, u, g), c, 4e-15);
                EXPECT_NEAR(tricubic(v, k, u), c, 4e-15);
                for (int a = 0; a < 3; ++a) EXPECT_NEAR(g[a], 0.0, 4e-15);
            };
            for (int n = 0; n < 200; ++n) check(random_point(rng, glm::dvec3(-1.0), domain_hi(v) + 1.0));
            // Corners and faces exactly.
            const glm::dvec3 hi = domain_hi(v);
            for (double x : {0.0, 0.5 * hi.x, hi.x})
                for (double y : {0.0, 0.5 * hi.y, hi.y})
                    for (double z : {0.0, 0.5 * hi.z, hi.z}) check({x, y, z});
        }
    }
}
