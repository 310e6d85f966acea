// The H100 texture unit's rule (core/integrate/profiles/TextureUnit.h, issue 27) against every fetch an
// NVIDIA H100 returned (tests/data/h100-fetches, recorded by dump_fetches.cu; README there): bit for bit.
// And the band (TextureUnit.h, "The family and its band") on each of those fetches and on random points
// against simulated units of the family; the L1 constant recomputed over every weight box.
#include <gtest/gtest.h>

#include <zlib.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <algorithm>
#include <random>
#include <type_traits>
#include <sstream>
#include <string>
#include <vector>

#include "core/integrate/profiles/TextureUnit.h"

using namespace volref::texture_unit;

namespace {

// The rows of a gzip'd CSV (two header lines: a comment and the column names), as doubles.
std::vector<std::vector<double>> read_csv_gz(const std::string& name) {
    const std::string path = std::string(VOLREF_SOURCE_DIR) + "/tests/data/h100-fetches/" + name;
    gzFile f = gzopen(path.c_str(), "rb");
    if (!f) {
        ADD_FAILURE() << "cannot open " << path;
        return {};
    }
    std::vector<std::vector<double>> rows;
    char line[512];
    int n = 0;
    while (gzgets(f, line, sizeof line)) {
        if (n++ < 2) continue;
        std::vector<double> row;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
        rows.push_back(row);
    }
    gzclose(f);
    return rows;
}

float f32(double x) { return static_cast<float>(x); }
double d32(double x) { return to_float32(x); }  // double(float(x)), safe from GCC 12's vectoriser (TextureUnit.h)

// A fetch of a 3D float texture (x fastest) at an unnormalised float point, by the rule.
template <class T>
float fetch3d(const std::vector<T>& tex, const std::array<std::int64_t, 3>& n, double x, double y, double z,
              bool unorm16, std::array<double, 8>* corners = nullptr, Fetch3d* where = nullptr) {
    const Fetch3d f = locate_3d({x, y, z}, n);
    std::array<float, 8> v{};
    std::array<std::uint16_t, 8> q{};
    for (int c = 0; c < 8; ++c) {
        const auto i = f.corner_index(c);
        const std::size_t idx = std::size_t(i[0] + n[0] * (i[1] + n[1] * i[2]));
        if constexpr (std::is_same_v<T, float>) v[std::size_t(c)] = tex[idx];
        else q[std::size_t(c)] = tex[idx];
        if (corners) (*corners)[std::size_t(c)] = unorm16 ? double(q[std::size_t(c)]) / 65535.0 : double(v[std::size_t(c)]);
    }
    if (where) *where = f;
    return unorm16 ? filter_unorm16(f.w.data(), q.data(), 8) : filter_float(f.w.data(), v.data(), 8, 2);
}

}  // namespace

// fetch1d_weight: texels {0, 1}, x = 0.5 + k / 65536: every one of the 65,537 fetches.
TEST(TextureUnit, OneDimensionalWeightsBitForBit) {
    const auto rows = read_csv_gz("fetch1d_weight.csv.gz");
    ASSERT_EQ(rows.size(), 65537u);
    int same = 0;
    const float tex[2] = {0.0f, 1.0f};
    for (const auto& r : rows) {
        const AxisRead a = axis_read(d32((r[0])), 2);
        const int w[2] = {kWeightOne - a.a, a.a};
        const float t[2] = {tex[a.i0], tex[a.i1]};
        same += filter_float(w, t, 2, 1) == f32(r[1]);
    }
    EXPECT_EQ(same, 65537);
    // by hand: x - 0.5 = 1/512 is a tie, rounded up to a = 1; 127/65536 gives a = 0
    EXPECT_EQ(axis_read(0.5 + 128.0 / 65536.0, 2).a, 1);
    EXPECT_EQ(axis_read(0.5 + 127.0 / 65536.0, 2).a, 0);
}

// fetch1d_table9: the 9-entry float4 table, normalised coordinates: 20,001 points x 4 channels.
TEST(TextureUnit, NineEntryNormalizedTableBitForBit) {
    const auto rows = read_csv_gz("fetch1d_table9.csv.gz");
    ASSERT_EQ(rows.size(), 20001u);
    float tab[9][4];
    for (int j = 0; j < 9; ++j) {
        tab[j][0] = float(j), tab[j][1] = float(j) / 8.f, tab[j][2] = 1.f - float(j) / 8.f, tab[j][3] = float(j % 2);
    }
    int same = 0, same_uncut = 0;
    for (const auto& r : rows) {
        const double u = d32((r[0]));
        const AxisRead a = axis_read(unnormalized(u, 9), 9);
        const AxisRead b = axis_read(d32((f32(u) * 9.0f)), 9);  // u * 9 in float32, no cut
        const int w[2] = {kWeightOne - a.a, a.a}, wb[2] = {kWeightOne - b.a, b.a};
        bool ok = true, ok_b = true;
        for (int c = 0; c < 4; ++c) {
            const float t[2] = {tab[a.i0][c], tab[a.i1][c]}, tb[2] = {tab[b.i0][c], tab[b.i1][c]};
            ok = ok && filter_float(w, t, 2, 1) == f32(r[std::size_t(1 + c)]);
            ok_b = ok_b && filter_float(wb, tb, 2, 1) == f32(r[std::size_t(1 + c)]);
        }
        same += ok;
        same_uncut += ok_b;
    }
    EXPECT_EQ(same, 20001);
    EXPECT_LT(same_uncut, 20001);  // the 20-bit cut is needed: without it some points are 1/256 off
}

// fetch3d_corner_weights (float32 and unorm16): one-hot corners, every corner of 20,000 points.
TEST(TextureUnit, CornerWeightsBitForBit) {
    for (const bool unorm16 : {false, true}) {
        const auto rows = read_csv_gz(unorm16 ? "fetch3d_corner_weights_unorm16.csv.gz" : "fetch3d_corner_weights.csv.gz");
        ASSERT_EQ(rows.size(), 20000u);
        int same = 0;
        for (const auto& r : rows) {
            bool ok = true;
            for (int c = 0; c < 8; ++c) {
                std::vector<float> vf(8, 0.0f);
                std::vector<std::uint16_t> vq(8, 0);
                vf[std::size_t(c)] = 1.0f;
                vq[std::size_t(c)] = 65535;
                const double x = d32((r[0])), y = d32((r[1])), z = d32((r[2]));
                const float got = unorm16 ? fetch3d(vq, {2, 2, 2}, x, y, z, true) : fetch3d(vf, {2, 2, 2}, x, y, z, false);
                ok = ok && got == f32(r[std::size_t(3 + c)]);
            }
            same += ok;
        }
        EXPECT_EQ(same, 20000) << (unorm16 ? "unorm16" : "float32");
    }
    // the README's example: axis weights (34, 174, 203) / 256; corner (1, 1, 1) gets 18 / 256
    const std::array<int, 8> w = corner_weights(34, 174, 203);
    EXPECT_EQ(w[7], 18);
    int total = 0;
    for (int x : w) total += x;
    EXPECT_EQ(total, 256);
    // by hand: Z1 = 203, Z0 = 53; X1(k=1) = rnd(34 * 203 = 6902) = (6902 + 128) >> 8 = 27,
    // w(1,1,1) = rnd(174 * 27 = 4698) = 18, w(1,0,1) = 27 - 18 = 9; X0(k=1) = 203 - 27 = 176,
    // w(0,0,1) = rnd(82 * 176 = 14432) = 56, w(0,1,1) = 176 - 56 = 120
    EXPECT_EQ(w[5], 9);
    EXPECT_EQ(w[4], 56);
    EXPECT_EQ(w[6], 120);
}

// fetch3d_random_volume: 50,000 points over [-1, n + 1] (clamping included), float32 and unorm16;
// and the band holds on every one of them.
TEST(TextureUnit, RandomVolumeBitForBitAndWithinTheBand) {
    const auto vals = read_csv_gz("fetch3d_random_volume_values.csv.gz");
    const auto rows = read_csv_gz("fetch3d_random_volume.csv.gz");
    ASSERT_EQ(vals.size(), 1920u);
    ASSERT_EQ(rows.size(), 50000u);
    std::vector<float> vf;
    std::vector<std::uint16_t> vq;
    for (const auto& v : vals) {
        vf.push_back(f32(v[0]));
        vq.push_back(static_cast<std::uint16_t>(std::lround(v[1])));
    }
    const std::array<std::int64_t, 3> n{16, 12, 10};
    int same[2] = {0, 0};
    double worst[2] = {0.0, 0.0}, largest_error[2] = {0.0, 0.0};
    for (const auto& r : rows) {
        const double x = d32((r[0])), y = d32((r[1])), z = d32((r[2]));
        for (int u = 0; u < 2; ++u) {
            std::array<double, 8> k;
            Fetch3d f;
            const float got = u ? fetch3d(vq, n, x, y, z, true, &k, &f) : fetch3d(vf, n, x, y, z, false, &k, &f);
            const float gpu = f32(r[std::size_t(3 + u)]);
            same[u] += got == gpu;
            // the band around exact trilinear at the same (float) point: delta 0
            const std::array<double, 8> e = exact_weights(f.axis);
            double exact = 0.0, lo = k[0], hi = k[0], amax = 0.0;
            for (int c = 0; c < 8; ++c) {
                exact += e[std::size_t(c)] * k[std::size_t(c)];
                lo = std::min(lo, k[std::size_t(c)]);
                hi = std::max(hi, k[std::size_t(c)]);
                amax = std::max(amax, std::fabs(k[std::size_t(c)]));
            }
            const double band = weight_factor(0.0) * (hi - lo) + (u ? kUnorm16Rounding : kFloatRounding * amax);
            const double err = std::fabs(double(gpu) - exact);
            EXPECT_LE(err, band);
            worst[u] = std::max(worst[u], err / band);
            largest_error[u] = std::max(largest_error[u], err);
        }
    }
    EXPECT_EQ(same[0], 50000);
    EXPECT_EQ(same[1], 50000);
    // the README: exact trilinear is off by at most 6.3e-3 / 5.9e-3; the band is not vacuous
    EXPECT_NEAR(largest_error[0], 6.3e-3, 0.1e-3);
    EXPECT_NEAR(largest_error[1], 5.9e-3, 0.1e-3);
    EXPECT_GT(worst[0], 0.3);
    EXPECT_GT(worst[1], 0.3);
}

// kL1Max is the largest L1 distance of the rule's weights from exact ones: L1 is convex in the
// fractions over each box where the integer weights are constant, so its maximum lies at a vertex
// (fractions (a +- 1/2) / 256 cut to [0, 1]); every box of the 257^3 is visited (every 4th z box under
// the sanitizers, where the full sweep takes a minute).
TEST(TextureUnit, L1MaxIsTheRulesLargest) {
#if defined(__SANITIZE_ADDRESS__)
    const int z_stride = 4;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
    const int z_stride = 4;
#else
    const int z_stride = 1;
#endif
#else
    const int z_stride = 1;
#endif
    double F[257][2];  // the fractions of a box's two faces along one axis
    for (int a = 0; a <= 256; ++a)
        for (int s = 0; s < 2; ++s) F[a][s] = std::clamp((double(a) + (s ? 0.5 : -0.5)) / 256.0, 0.0, 1.0);
    double largest = 0.0;
    int largest_at[3] = {0, 0, 0};
    for (int az = 0; az <= 256; az += (az == 0 ? 1 : z_stride))
        for (int ay = 0; ay <= 256; ++ay)
            for (int ax = 0; ax <= 256; ++ax) {
                const std::array<int, 8> w = corner_weights(ax, ay, az);
                for (int v = 0; v < 8; ++v) {
                    const double fx = F[ax][v & 1], fy = F[ay][(v >> 1) & 1], fz = F[az][v >> 2];
                    const double xy[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
                    double l1 = 0.0;
                    for (int c = 0; c < 8; ++c)
                        l1 += std::fabs(double(w[std::size_t(c)]) * (1.0 / 256.0) - xy[c & 3] * (c >> 2 ? fz : 1 - fz));
                    if (l1 > largest) largest = l1, largest_at[0] = ax, largest_at[1] = ay, largest_at[2] = az;
                }
            }
    EXPECT_LE(largest, kL1Max);
    if (z_stride == 1) {
        EXPECT_GT(largest, kL1Max - 1e-12) << largest_at[0] << ", " << largest_at[1] << ", " << largest_at[2];
    }
    std::printf("largest L1 %.17g at a = (%d, %d, %d), 256 L1 = %.6g\n", largest, largest_at[0], largest_at[1], largest_at[2], 256 * largest);
}

// The band holds for simulated units of the family at random points with a random position move
// within delta, random values (signed, mixed magnitudes), and is attained up to a fraction.
TEST(TextureUnit, BandHoldsForUnitsOfTheFamily) {
    std::mt19937_64 rng(27);
    std::uniform_real_distribution<double> uni(0.0, 1.0), sym(-1.0, 1.0);
    double use = 0.0;
    for (int trial = 0; trial < 20000; ++trial) {
        // a 3x3x3 texture so that the moved position may cross into the next cell
        std::vector<double> tex(27);
        const double scale = std::pow(10.0, 4.0 * sym(rng));
        for (double& t : tex) t = trial % 2 ? uni(rng) : scale * sym(rng);
        const std::array<std::int64_t, 3> n{3, 3, 3};
        std::array<double, 3> p, pm;
        const double delta = (trial % 3) * 1e-3;
        for (int a = 0; a < 3; ++a) {
            p[std::size_t(a)] = 0.5 + 2.0 * uni(rng);
            pm[std::size_t(a)] = p[std::size_t(a)] + delta * sym(rng);
        }
        auto corners = [&](const Fetch3d& f) {
            std::array<double, 8> k;
            for (int c = 0; c < 8; ++c) {
                const auto i = f.corner_index(c);
                k[std::size_t(c)] = tex[std::size_t(i[0] + 3 * (i[1] + 3 * i[2]))];
            }
            return k;
        };
        const Fetch3d fe = locate_3d(p, n), fu = locate_3d(pm, n);
        const std::array<double, 8> ke = corners(fe), ku = corners(fu), e = exact_weights(fe.axis);
        double exact = 0.0, lo = ke[0], hi = ke[0], amax = 0.0;
        for (int c = 0; c < 8; ++c) {
            exact += e[std::size_t(c)] * ke[std::size_t(c)];
            for (double v : {ke[std::size_t(c)], ku[std::size_t(c)]}) {
                lo = std::min(lo, v), hi = std::max(hi, v), amax = std::max(amax, std::fabs(v));
            }
        }
        const double band = weight_factor(3.0 * delta) * (hi - lo) + kFloatRounding * amax;
        // the h100 rule itself at the moved point, float32 texels
        std::array<float, 8> t;
        for (int c = 0; c < 8; ++c) t[std::size_t(c)] = float(ku[std::size_t(c)]);
        EXPECT_LE(std::fabs(double(filter_float(fu.w.data(), t.data(), 8, 2)) - exact), band);
        // units of the family
        Admissible r(std::uint64_t(trial), p[0], p[1], p[2]);
        for (int k = 0; k < 4; ++k) {
            const std::array<double, 8> w = admissible_weights(exact_weights(fu.axis), r);
            double s = 0.0;
            for (int c = 0; c < 8; ++c) s += w[std::size_t(c)] * ku[std::size_t(c)];
            const double err = std::fabs(s - exact);
            EXPECT_LE(err, band);
            use = std::max(use, err / band);
        }
    }
    EXPECT_GT(use, 0.5);
}
