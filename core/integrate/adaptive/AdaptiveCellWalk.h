// AdaptiveCellWalk: where a ray crosses the planes of a Cartesian grid (a 3-D DDA, all at once).
//
// Along x(t) = o + t d the continuous index on axis a is u_a(t) = (o_a + t d_a - origin_a) / s_a, affine
// in t. The ray crosses the plane u_a = w at t = (origin_a + w s_a - o_a) / d_a. With offset 0 the
// planes are the cell faces (w integer): between consecutive crossings the ray stays in one cell, where
// the trilinear field is a cubic in t (CellCubic.h) and the tricubic one a polynomial. With offset 1/2
// they are the faces of the nearest-neighbour regions (w = i + 1/2), where the nearest field is constant.
// An axis with one voxel, or along which the ray does not move (d_a = 0), has no crossing. A ray along a
// face or an edge (u_a an exact integer for all t) therefore gets no crossing on that axis: the sampler
// puts every point of it in the same cell (the higher one, by floor), where the field is that cubic.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/camera/Ray.h"
#include "core/grid/Volume.h"
#include "core/integrate/adaptive/CellCubic.h"
#include "core/sample/VolumeSampler.h"

namespace volref {

// cuts = t0, the crossings strictly inside (t0, t1) in increasing order (without repeats: a ray
// through an edge or a corner crosses two or three planes at one t), t1. Consecutive entries bound
// the pieces.
inline void grid_cuts(const Ray& ray, double t0, double t1, const Volume& v, double offset, std::vector<double>& cuts) {
    cuts.clear();
    cuts.push_back(t0);
    for (int a = 0; a < 3; ++a) {
        const double d = ray.direction[a];
        if (v.dims[a] < 2 || d == 0.0) continue;
        const double s = v.spacing[a], o = v.origin[a], e = ray.origin[a];
        const double u0 = (e + t0 * d - o) / s, u1 = (e + t1 * d - o) / s;
        const double lo = std::min(u0, u1) - offset, hi = std::max(u0, u1) - offset;
        if (!(std::isfinite(lo) && std::isfinite(hi))) continue;
        for (double k = std::floor(lo) + 1.0; k < hi; k += 1.0) {
            const double t = (o + (k + offset) * s - e) / d;
            if (t > t0 && t < t1) cuts.push_back(t);
        }
    }
    std::sort(cuts.begin() + 1, cuts.end());
    cuts.push_back(t1);
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
}

// The trilinear field along the piece [ta, tb] (inside one cell: the one VolumeSampler::locate gives
// its midpoint) as a cubic in x = t - ta: fractions (p0, q0, r0) = u(ta) - cell, slopes direction /
// spacing (0 on an axis with one voxel, where the sampler's fraction is 0).
inline Cubic cell_cubic(const VolumeSampler& sampler, const Ray& ray, double ta, double tb) {
    const Volume& v = sampler.volume();
    std::array<std::int64_t, 3> cell;
    glm::dvec3 frac;
    sampler.locate(sampler.continuous_index(ray.at(0.5 * (ta + tb))), cell, frac);
    glm::dvec3 f0(0.0), df(0.0);
    for (int a = 0; a < 3; ++a) {
        if (v.dims[a] == 1) continue;
        f0[a] = (ray.origin[a] + ta * ray.direction[a] - v.origin[a]) / v.spacing[a] - double(cell[std::size_t(a)]);
        df[a] = ray.direction[a] / v.spacing[a];
    }
    return trilinear_cubic(sampler.corners(cell), f0, df);
}

}  // namespace volref
