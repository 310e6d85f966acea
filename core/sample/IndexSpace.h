// Reconstruction in index space, one axis at a time (conventions section 2): the taps and weights
// every sampler uses once it has a point's continuous index u. VolumeSampler (Cartesian) maps a world
// point to u = (x - origin) / spacing; ShellSampler (beam space) maps it through the shell's
// coordinates (ShellGrid::continuous_index). After that map both are this one sampler: the same
// rules, the same fetches (Volume::index) and the same sums (Trilinear.h, Tricubic.h). The one
// difference is an axis' boundary rule: every Cartesian axis, and a shell's radius, height and
// latitude, clamp; a shell's full-circle angle or longitude is periodic (indices wrap modulo n).
//
//   clamped axis:  u clamped to [0, n - 1] (NaN reads as 0); the cell i = min(floor(u), n - 2) with
//                  fraction u - i; taps i - 1 .. i + 2 clamped to [0, n - 1]; nearest floor(u + 0.5)
//                  clamped to [0, n - 1];
//   periodic axis: u reduced into [0, n) (NaN and infinities read as 0); the cell i = floor(u) with
//                  fraction u - i, its other corner (i + 1) mod n (the cell [n - 1, n) interpolates
//                  between the last sample and the first); taps (i - 1 + m) mod n; nearest
//                  floor(u + 0.5) mod n;
//   n = 1:         the single layer: cell 0, fraction 0, cubic weights (0, 1, 0, 0), derivative 0.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "core/grid/Volume.h"
#include "core/sample/Tricubic.h"

namespace volref {

// u reduced into [0, n) (NaN and infinities read as 0).
inline double wrap_index(double u, std::int64_t n) {
    if (!std::isfinite(u)) return 0.0;
    const double dn = double(n);
    double w = std::fmod(u, dn);
    if (w < 0.0) w += dn;
    if (w >= dn) w = 0.0;
    return w + 0.0;
}

// u clamped to [0, n - 1] (NaN reads as 0).
inline double clamp_index(double u, std::int64_t n) {
    const double hi = double(n - 1);
    if (!(u > 0.0)) return 0.0;
    return u > hi ? hi : u;
}

// One axis of a trilinear lookup: the two corner indices and the fraction.
struct LinearAxis {
    std::int64_t i0 = 0, i1 = 0;
    double p = 0.0;
};

inline LinearAxis linear_axis(double u, std::int64_t n, bool periodic) {
    LinearAxis a;
    if (n <= 1) return a;
    if (periodic) {
        u = wrap_index(u, n);
        a.i0 = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 1);
        a.i1 = a.i0 + 1 == n ? 0 : a.i0 + 1;
        a.p = u - double(a.i0);
        return a;
    }
    u = clamp_index(u, n);
    a.i0 = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 2);
    a.i1 = a.i0 + 1;
    a.p = u - double(a.i0);
    return a;
}

// The voxel nearest u on one axis (round half up).
inline std::int64_t nearest_axis(double u, std::int64_t n, bool periodic) {
    if (periodic) {
        const std::int64_t i = std::int64_t(std::floor(wrap_index(u, n) + 0.5));
        return i >= n ? i - n : i;
    }
    return std::min<std::int64_t>(std::int64_t(std::floor(clamp_index(u, n) + 0.5)), n - 1);
}

// One axis of a tricubic lookup: the 4 weights, their derivatives d/du and the tap indices.
inline CubicAxis cubic_axis(CubicKernel k, double u, std::int64_t n, bool periodic) {
    CubicAxis a;
    if (n <= 1) return a;  // the single layer, exactly: (0, 1, 0, 0) sums to 1 without rounding
    if (periodic) {
        u = wrap_index(u, n);
        const std::int64_t i = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 1);
        cubic_weights(k, u - double(i), a.w, a.dw);
        for (int m = 0; m < 4; ++m) {
            std::int64_t t = (i - 1 + m) % n;
            if (t < 0) t += n;
            a.idx[std::size_t(m)] = t;
        }
        return a;
    }
    u = clamp_index(u, n);
    const std::int64_t i = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 2);
    cubic_weights(k, u - double(i), a.w, a.dw);
    for (int m = 0; m < 4; ++m) a.idx[std::size_t(m)] = std::clamp<std::int64_t>(i - 1 + m, 0, n - 1);
    return a;
}

// The corner values f1..f8 (Levoy's order) of the cell with corners i0/i1, j0/j1, k0/k1: one switch on
// the storage type per cell, then eight typed loads (exact conversions to double).
inline std::array<double, 8> cell_corners(const Volume& v, const LinearAxis& x, const LinearAxis& y, const LinearAxis& z) {
    const std::size_t n[8] = {v.index(x.i0, y.i0, z.i0), v.index(x.i1, y.i0, z.i0), v.index(x.i1, y.i1, z.i0),
                              v.index(x.i0, y.i1, z.i0), v.index(x.i0, y.i0, z.i1), v.index(x.i1, y.i0, z.i1),
                              v.index(x.i1, y.i1, z.i1), v.index(x.i0, y.i1, z.i1)};
    return v.values.visit([&](const auto* p) -> std::array<double, 8> {
        return {double(p[n[0]]), double(p[n[1]]), double(p[n[2]]), double(p[n[3]]),
                double(p[n[4]]), double(p[n[5]]), double(p[n[6]]), double(p[n[7]])};
    });
}

}  // namespace volref
