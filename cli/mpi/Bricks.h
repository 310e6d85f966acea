// volref-mpi's bricks (docs/architecture.md, "volref-mpi"; docs/conventions.md §14): the volume's
// cells split into N boxes by a k-d tree (each split on the box's longest axis, in cells, at the
// point that balances the cell counts of the two halves in proportion to their ranks), the voxels a
// brick's rank holds (its cells' corners plus a ghost layer), and which brick owns a point.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene/Scene.h"

namespace volref::mpi {

struct Brick {
    // The cells [lo, hi) on each axis (voxel indices; a cell a spans voxels a and a + 1). An axis of
    // one voxel has the one "cell" [0, 0).
    std::array<std::int64_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
    // The voxels this rank holds: [vlo, vhi] (inclusive), the cells' corners widened by the ghost
    // layer and clamped to the volume.
    std::array<std::int64_t, 3> vlo{0, 0, 0}, vhi{0, 0, 0};
    std::array<std::int64_t, 3> voxel_dims() const {
        return {vhi[0] - vlo[0] + 1, vhi[1] - vlo[1] + 1, vhi[2] - vlo[2] + 1};
    }
};

// `count` >= 1 bricks of a grid of `dims` voxels, each with `ghost` voxels of ghost layer. Throws
// volref::Error when the grid has fewer cells than bricks.
std::vector<Brick> split_bricks(const std::array<std::int64_t, 3>& dims, int count, int ghost);

// The ghost layer a volume's reconstruction needs (conventions §14): 1 voxel for nearest and
// trilinear (a midpoint owned by the brick may round to the neighbouring cell), +1 for tricubic taps
// (i - 1 .. i + 2), +1 when gradients are taken by differences (x +- h reads one voxel further).
int ghost_voxels(const VolumeSpec& vs, const RenderSpec& render);

// Whether the point with continuous grid index u (u_a = (x_a - origin_a) / spacing_a of the whole
// volume) belongs to `b`: lo_a <= u_a < hi_a on every axis, open-ended at the volume's faces, so
// every point belongs to exactly one brick of a k-d split (the same test on every rank).
bool owns(const Brick& b, const std::array<std::int64_t, 3>& dims, const glm::dvec3& u);

}  // namespace volref::mpi
