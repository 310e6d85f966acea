// The texture unit's models (core/integrate/profiles/TextureUnit.h, issue 17 part 4) against what
// ../shared/gpu/README.md measured on an NVIDIA H100 (the formulas of its programs), and the error band
// against a direct simulation of every texture unit within the model.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <set>

#include "core/integrate/profiles/TextureUnit.h"

using namespace volref::texture_unit;

// weights.cu: texels {0, 1}, x = 0.5 + k / 65536, k = 0 .. 65536: the fetch is the weight
// floor((x - 0.5) 256 + 0.5) / 256; 257 distinct values; ties round up (k = 128: x - 0.5 = 1/512 -> 1/256).
TEST(TextureUnit, OneDimensionalWeightsAsMeasured) {
    const double t[2] = {0.0, 1.0};
    std::set<double> distinct;
    for (int k = 0; k <= 65536; ++k) {
        const double x = 0.5 + double(k) / 65536.0;
        const double y = fetch_1d(t, 2, x, Model::Hardware);
        EXPECT_EQ(y, std::floor((x - 0.5) * 256.0 + 0.5) / 256.0);
        EXPECT_LE(std::fabs(y - fetch_1d(t, 2, x, Model::Exact)), kWeightError);
        distinct.insert(y);
    }
    EXPECT_EQ(distinct.size(), 257u);
    EXPECT_EQ(fetch_1d(t, 2, 0.5 + 128.0 / 65536.0, Model::Hardware), 1.0 / 256.0);   // the tie rounds up
    EXPECT_EQ(fetch_1d(t, 2, 0.5 + 127.0 / 65536.0, Model::Hardware), 0.0);
}

// weights.cu's 9-entry normalised table with alternating 0/1 alpha: texel position 9 u - 0.5 clamped
// to [0, 8]; the largest difference from exact filtering is 1/512 = 1.953e-3 (measured: 1.96e-3).
TEST(TextureUnit, NineEntryTableAsMeasured) {
    const double t[9] = {0, 1, 0, 1, 0, 1, 0, 1, 0};
    double worst = 0.0;
    for (int k = 0; k <= 90000; ++k) {
        const double u = double(k) / 90000.0;
        worst = std::max(worst, std::fabs(fetch_1d_normalized(t, 9, u, Model::Hardware) -
                                          fetch_1d_normalized(t, 9, u, Model::Exact)));
    }
    EXPECT_LE(worst, 1.0 / 512.0);
    EXPECT_GT(worst, 1.0 / 512.0 - 1e-4);  // the u grid's texel step is 1e-4
    EXPECT_EQ(fetch_1d_normalized(t, 9, 0.0, Model::Hardware), 0.0);     // clamped to texel 0
    EXPECT_EQ(fetch_1d_normalized(t, 9, 1.5 / 9.0, Model::Hardware), 1.0);  // texel 1's centre
}

// weights3d_probe.cu's example: axis weights (0.132812, 0.679688, 0.792969) = (34, 174, 203) / 256,
// corner (1, 1, 1): the fetch was 18/256; the product 0.0715821 rounded to 1/256 is 18/256.
TEST(TextureUnit, ThreeDimensionalModelReproducesTheMeasuredExample) {
    const double fx = 34.0 / 256.0, fy = 174.0 / 256.0, fz = 203.0 / 256.0;
    const std::array<double, 8> w = corner_weights(fx, fy, fz, Model::Hardware);
    EXPECT_EQ(w[7], 18.0 / 256.0);
    EXPECT_NEAR(corner_weights(fx, fy, fz, Model::Exact)[7], 0.0715821, 1e-7);
    // The measured fetch is inside the band around exact filtering at the rounded fractions.
    std::array<double, 8> one_hot{};
    one_hot[7] = 1.0;
    EXPECT_LE(std::fabs(18.0 / 256.0 - fetch_3d(one_hot, fx, fy, fz, Model::Exact)),
              fetch_error_band_3d(one_hot, fx, fy, fz));
}

// The band holds for the model and for every texture unit within it: random corner values in [-1, 1]
// (and texfilter.cu's [0, 1]), random fractions; simulated units take each axis weight anywhere within
// 1/512 of exact and each corner weight anywhere within 1/512 of the product of those. The band is
// also not vacuous: it stays below 8 (4/512 + 3 (1/512)^2 ...) times max |v|, and the worst simulated
// case uses more than half of it somewhere.
TEST(TextureUnit, BandHoldsForEveryUnitWithinTheModel) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> unit(0.0, 1.0), sym(-1.0, 1.0);
    double largest_use = 0.0;
    for (int trial = 0; trial < 20000; ++trial) {
        std::array<double, 8> v{};
        for (double& x : v) x = trial % 2 ? unit(rng) : sym(rng);
        const double f[3] = {unit(rng), unit(rng), unit(rng)};
        const double exact = fetch_3d(v, f[0], f[1], f[2], Model::Exact);
        const double band = fetch_error_band_3d(v, f[0], f[1], f[2]);
        EXPECT_LE(std::fabs(fetch_3d(v, f[0], f[1], f[2], Model::Hardware) - exact), band);
        for (int unit_try = 0; unit_try < 4; ++unit_try) {
            double a[3];
            for (int k = 0; k < 3; ++k) a[k] = f[k] + kWeightError * (unit_try == 0 ? (k % 2 ? 1 : -1) : sym(rng));
            double fetch = 0.0;
            for (int c = 0; c < 8; ++c) {
                double p = 1.0;
                for (int k = 0; k < 3; ++k) p *= ((c >> k) & 1) ? a[k] : 1.0 - a[k];
                const double r = unit_try == 0 ? (v[std::size_t(c)] > 0 ? kWeightError : -kWeightError) : kWeightError * sym(rng);
                fetch += (p + r) * v[std::size_t(c)];
            }
            const double err = std::fabs(fetch - exact);
            EXPECT_LE(err, band);
            largest_use = std::max(largest_use, err / band);
        }
        double vmax = 0.0;
        for (double x : v) vmax = std::max(vmax, std::fabs(x));
        EXPECT_LE(band, 8.0 * (4.0 / 512.0 + 1e-4) * vmax);
    }
    EXPECT_GT(largest_use, 0.5);
}
