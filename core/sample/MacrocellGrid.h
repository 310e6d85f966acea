// MacrocellGrid: the min/max grid of empty-space skipping (conventions section 4, "Empty-space
// skipping"), for the composite projection.
//
// The cells of the volume (cell i = [i, i + 1] per axis, as VolumeSampler::locate picks it; one cell on
// an axis with n = 1) are grouped into macrocells of M^3 cells, M = conventions::kMacrocellSize (fewer at
// the high end of an axis whose cell count is not a multiple of M). A sample belongs to the macrocell of
// the cell that VolumeSampler::locate gives for it (computed by the same code, so a sample on a
// macrocell face belongs to exactly the macrocell whose voxels it reads), and reads only:
//   nearest, trilinear: the corners of its cell (nearest: voxel floor(u + 1/2), a corner of that cell);
//   tricubic:           the taps i-1 .. i+2 per axis (indices clamped), an apron of one voxel.
// Macrocell m covers cells [c0, c1) per axis (c0 = m M, c1 = min(c0 + M, cells)), so its voxels are
// [c0, c1] (nearest, trilinear) or [c0 - 1, c1 + 1] (tricubic), clamped to [0, n - 1]. It stores their
// [min, max] and an `empty` flag, true only when no sample in it can have opacity > 0:
//   post-classification: the classifier says no value in reconstruction_bounds(min, max) can;
//   pre-classification:  every voxel it reads has pre-classified opacity a_i = 0 (so the interpolated
//                        opacity is 0 exactly for every kernel): a_i = classify(v_i, 0) for classifiers
//                        that ignore the gradient, else "classify cannot give > 0 at v_i" (any |grad f|).
// A macrocell with a non-finite voxel is never empty.
// mip / minip use the same grid without the flags: value_bounds(m) bounds every value a sample in m
// can reconstruct, so a macrocell whose bound cannot beat a ray's extremum so far is passed over
// (SegmentWalk.h).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/Conventions.h"
#include "core/camera/Ray.h"
#include "core/sample/VolumeSampler.h"
#include "transfer/Classifier.h"

namespace volref {

class MacrocellGrid {
public:
    using Index = std::array<std::int64_t, 3>;
    enum class Classification { Post, Pre };

    // `sampler` places samples (continuous_index, locate) and names the interpolation; it must outlive
    // the grid. The classifier is only used while building.
    MacrocellGrid(const VolumeSampler& sampler, const Classifier& classifier, Classification classification);

    // Macrocells per axis: ceil(cells / M), cells = max(n - 1, 1).
    const Index& counts() const { return counts_; }
    // The same for a volume of `dims` voxels (the one formula, also before a grid is built).
    static Index counts_for(const std::int64_t dims[3]);
    // At most the bytes a grid over a volume of `dims` voxels takes (for --max-memory, before it is
    // built): per macrocell its range (16), empty flag and empty radius (1 + 1) and the construction's
    // transient distance field (8 + 1); with `octant_radii`, the composite packets' 8 signed radii (32,
    // the copy CompositeIntegrator holds).
    static std::size_t bytes_for(const std::int64_t dims[3], bool octant_radii);
    std::int64_t empty_count() const { return empty_count_; }
    // [min, max] of the voxels the samples in macrocell m read ([-inf, +inf] if one is not finite).
    std::array<double, 2> range(const Index& m) const { return ranges_[linear(m)]; }
    // Every value a sample in macrocell m can reconstruct lies in this interval (reconstruction_bounds of
    // range(m)); [-inf, +inf] when a voxel it reads is not finite.
    std::array<double, 2> value_bounds(const Index& m) const;
    // False for an index outside the grid.
    bool empty(const Index& m) const { return inside(m) && empty_[linear(m)] != 0; }
    // The voxels (first, last, inclusive, per axis) that the samples in macrocell m read.
    void voxel_box(const Index& m, Index& first, Index& last) const;

    // The macrocell of a sample at world point x (the cell of VolumeSampler::locate divided by M);
    // {-1, -1, -1} if x is NaN.
    Index macrocell_at(const glm::dvec3& world) const {  // inline: once per run of every ray
        const glm::dvec3 u = sampler_.continuous_index(world);
        if (std::isnan(u.x) || std::isnan(u.y) || std::isnan(u.z)) return {-1, -1, -1};
        std::array<std::int64_t, 3> cell;
        glm::dvec3 frac;
        sampler_.locate(u, cell, frac);
        constexpr std::int64_t M = conventions::kMacrocellSize;
        return {cell[0] / M, cell[1] / M, cell[2] / M};
    }
    // The Chebyshev distance, in macrocells, from m to the nearest macrocell that is not empty: 0 when m
    // is not empty, r >= 1 when every macrocell within r - 1 of m (per axis) is empty; capped at
    // kMaxEmptyRadius (also when no macrocell is non-empty).
    std::int64_t empty_radius(const Index& m) const { return inside(m) ? empty_radius_[linear(m)] : 0; }
    static constexpr std::int64_t kMaxEmptyRadius = 255;
    // The distance ahead, per octant of ray directions, computed on each call (only the composite
    // packets read it, once): for octant o = (s0 < 0) + 2 (s1 < 0) + 4 (s2 < 0) (s: the direction's
    // sign per axis, + for 0), entry o * count + linear(m) is the largest r such that every macrocell
    // m + (i s0, j s1, k s2), 0 <= i, j, k < r, is as m is, empty or not (a cube with its corner at m,
    // ahead of a ray in that octant), capped at kMaxEmptyRadius; a cube may reach beyond the grid (as
    // empty_radius' box). By the recurrence r(m) = 1 + min over m's 7 neighbours ahead q = m + (a s0,
    // b s1, c s2) (a, b, c in {0, 1}, not all 0) of r(q) where q is as m is, else 0 (kMaxEmptyRadius
    // outside the grid). Signed, as the composite packets read it (VectorSkip): +r for an empty m (never
    // below empty_radius(m): a lane there may move to the cube's exit), -r for a non-empty one (r >= 1: a
    // lane there needs no check for empty space before that exit).
    std::vector<std::int32_t> octant_radii() const;
    // Where the ray leaves (enters) the box of macrocell m through a face with a neighbour behind it,
    // in the ray's t: +inf (-inf) when it crosses no such face. Rounded, so only an estimate: the
    // integrator checks it against macrocell_at. exit_distance with r > 1: where the ray leaves the box
    // of the macrocells within r - 1 of m (per axis), through a face with a macrocell behind it.
    double exit_distance(const Ray& ray, const Index& m, std::int64_t r = 1) const;
    double entry_distance(const Ray& ray, const Index& m) const;

    // An interval that holds every value the interpolation can reconstruct, rounding included, from
    // taps whose values lie in [lo, hi] (finite):
    //   nearest:            [lo, hi] (a voxel value, exactly);
    //   trilinear, B-spline: non-negative weights summing to 1: [lo, hi] widened by the rounding margin;
    //   Catmull-Rom:        the weights sum to 1 but w0, w3 <= 0, and sum |w| = 1 + t (1 - t) <= 5/4 per
    //                       axis, so |f - mid| <= (5/4)^3 r = 1.953125 r (mid, r: the centre and
    //                       half-width of [lo, hi]), widened by the rounding margin.
    // Rounding margin: 1e-12 max(|lo|, |hi|) + 1e-300 (0 when lo = hi = 0, which reconstructs to 0
    // exactly). The weights' rounding and the three 4-tap passes stay below 400 u = 4.4e-14 of the
    // taps' magnitude (times 1.95 for Catmull-Rom); 1e-300 covers subnormal taps.
    static std::array<double, 2> reconstruction_bounds(Interpolation interpolation, double lo, double hi);

private:
    bool inside(const Index& m) const {
        for (int a = 0; a < 3; ++a)
            if (m[a] < 0 || m[a] >= counts_[a]) return false;
        return true;
    }
    std::size_t linear(const Index& m) const {
        return std::size_t(m[0] + counts_[0] * (m[1] + counts_[1] * m[2]));
    }

    const VolumeSampler& sampler_;
    Index counts_{1, 1, 1};
    Index cells_{1, 1, 1};
    std::int64_t apron_ = 0;
    std::vector<std::array<double, 2>> ranges_;
    // Per macrocell, the Chebyshev distance to the nearest macrocell that is not empty.
    std::vector<std::uint8_t> chebyshev_radii() const;
    std::vector<unsigned char> empty_;
    std::vector<std::uint8_t> empty_radius_;  // empty_radius(m)
    std::int64_t empty_count_ = 0;
};

}  // namespace volref
