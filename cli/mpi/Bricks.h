// volref-mpi's bricks (docs/architecture.md, "volref-mpi"; docs/conventions.md §14): space split into
// N boxes by a k-d tree over the cells of the first volume's grid (extended to cover every volume:
// Lattice; each split on the box's longest axis, in cells, at the point that balances the cell counts
// of the two halves in proportion to their ranks), the voxels of each volume a brick's rank holds
// (the cells meeting its box plus a ghost layer), and which brick owns a point.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/integrate/march/RaySpan.h"
#include "core/scene/Scene.h"
#include "geometry/VolumeTransform.h"

namespace volref::mpi {

struct Brick {
    // The cells [lo, hi) on each axis (indices of the first volume's lattice; a cell a spans its
    // planes a and a + 1). An axis of one voxel has the one "cell" [0, 0).
    std::array<std::int64_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
    bool operator==(const Brick&) const = default;
};

// The cells [lo, hi) of the lattice of the first volume's grid, extended beyond that
// volume to cover every volume's domain (Lattice, from union_lattice), split by the same k-d rule;
// voxels_for gives each volume's voxels. Throws volref::Error
// when the lattice has fewer cells than bricks.
struct Lattice {
    std::array<std::int64_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
};
// Work measured over the lattice in bins (WorkBins: each axis' cells in `bins` equal runs of `width`
// cells, the last shorter). With it each cut balances the work of the two halves (in proportion to
// their ranks) instead of their cell counts: the box's work per cell along the axis (each bin's work
// spread evenly over its cells, the bins the box covers only in part counted by the fraction it
// covers), the cut at the first cell where the work before it reaches first / count of the box's
// work. No work in the box: the cell rule.
struct WorkBins {
    std::array<std::int64_t, 3> bins{1, 1, 1}, width{1, 1, 1};
    std::vector<double> work;  // bins[0] bins[1] bins[2] values, x fastest
    // `bins_per_axis` bins on each axis of `cells` (fewer where an axis has fewer cells).
    WorkBins(const Lattice& cells, std::int64_t bins_per_axis);
    WorkBins() = default;
    // The bin of a continuous lattice index (clamped to the lattice).
    std::size_t bin_of(const Lattice& cells, const glm::dvec3& u) const;
};
std::vector<Brick> split_lattice(const Lattice& cells, int count, const WorkBins* work = nullptr);

// The work of a SIMD packet (Balance.h's packet count; conventions §14): the fixed-step integrators step
// kWorkPacketLanes neighbouring rays together, and a step's time goes with the voxels its lanes wait for, so
// step j of a packet costs kWorkStepCost + (the distinct cache lines of kWorkLineBytes that the lanes with a
// j-th sample start their cells on), in units of one line. kWorkStepCost = 16 was measured (docs/
// performance.md, "volref-mpi on the resumable march"). The cost is shared equally among those
// lanes' bins in units of 1 / 840 (840 = lcm(1, ..., 8)), so every value added is an integer and the
// ranks' sums are exact in any order.
inline constexpr int kWorkPacketLanes = 8;
inline constexpr double kWorkStepCost = 16.0;
inline constexpr std::int64_t kWorkLineBytes = 64;
struct LaneSample {
    std::size_t bin;     // WorkBins::bin_of the sample's position
    std::int64_t line;   // the cache line its cell's first voxel lies on: (i + n_x (j + n_y k)) bytes / kWorkLineBytes
};
// Adds the packet of `lanes[0 .. count)` (count <= kWorkPacketLanes; each lane's samples in order) to `work`.
void add_packet_work(const std::vector<LaneSample>* lanes, int count, std::vector<double>& work);

// A grid: `dims` voxels at origin + i * spacing in its own space, placed in the world by `to_world`
// (null: its space is world space).
struct GridBox {
    std::array<std::int64_t, 3> dims{1, 1, 1};
    glm::dvec3 origin{0.0}, spacing{1.0};
    const VolumeTransform* to_world = nullptr;
};
// The lattice of grids[0] (cells between its voxel planes, extended) covering every grid's domain:
// grids[0] itself exactly ([0, dims - 1)), the others' 8 corners mapped through world space into
// grids[0]'s index space u = (x_local0 - origin_0) / spacing_0, floor and ceil.
Lattice union_lattice(const std::vector<GridBox>& grids);
// The voxels [vlo, vhi] (inclusive) of `grid` that the rank of brick `b` (cells of `lattice` in
// `first`'s index space) needs: the grid's cells meeting the brick's box (its 8 corners mapped into
// the grid's index space, floor and ceil), plus `ghost` voxels, clamped to the grid; on the lattice's
// outer faces (which own every point beyond them) up to the grid's face.
// When the brick does not meet the grid, a range of 1 or 2 voxels at the nearest face (never sampled).
void voxels_for(const Brick& b, const Lattice& lattice, const GridBox& first, const GridBox& grid, int ghost,
                std::array<std::int64_t, 3>& vlo, std::array<std::int64_t, 3>& vhi);

// The ghost layer a volume's reconstruction needs (conventions §14): 1 voxel for nearest and
// trilinear (a midpoint owned by the brick may round to the neighbouring cell), +1 for tricubic taps
// (i - 1 .. i + 2), +1 when gradients are taken by differences (x +- h reads one voxel further); with
// a gradient cache at least 1 + the scheme's reach (1 for differences, 2 for the analytic tricubic).
int ghost_voxels(const VolumeSpec& vs, const RenderSpec& render);

// Whether the point with continuous grid index u (u_a = (x_a - origin_a) / spacing_a of the whole
// volume, or of the first volume's lattice) belongs to `b`: lo_a <= u_a < hi_a on every axis,
// open-ended at the lattice's outer faces ([0, dims - 1] for one volume), so every point belongs to
// exactly one brick of a k-d split (the same test on every rank).
bool owns(const Brick& b, const Lattice& lattice, const glm::dvec3& u);

// The span of `ray` (in `first`'s space) that `b` owns: exactly the doubles t with
// owns(b, lattice, (ray.at(t) - first.origin) / first.spacing) (march/RaySpan.h's [t0, t1), t1 the double
// after the last owned t; empty: [+inf, +inf)). Each axis' index is monotone in t, so each of the
// brick's faces bounds the owned t on one side; each bound is found by bisection over the doubles.
RaySpan owned_span(const Brick& b, const Lattice& lattice, const GridBox& first, const Ray& ray);

}  // namespace volref::mpi
