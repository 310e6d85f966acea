// Procedural fields sampled at a grid's vertices (scene-format.md, volume.source.field).
#pragma once
#include <functional>
#include "core/grid/Volume.h"
#include "core/scene/Scene.h"

namespace volref {

// Builds the volume of `field` on the grid (field.dims, origin, spacing); type F64.
//   constant        f = value
//   linear          f = a x + b y + c z + d at the voxel's world position
//   radial          f = |p - center|
//   marschner-lobb  voxel i on an axis of n samples sits at u = -1 + 2 i / (n - 1) (0 when n = 1),
//                   whatever the origin and spacing; with r = sqrt(x^2 + y^2),
//                   f = (1 - sin(pi z / 2) + alpha (1 + cos(2 pi fm cos(pi r / 2)))) / (2 (1 + alpha))
//   gaussian        f = amplitude exp(-|p - center|^2 / (2 sigma^2))
//   cells           f = values[i + nx (j + ny k)]
Volume make_procedural_volume(const FieldSpec& field, const glm::dvec3& origin, const glm::dvec3& spacing);

// The same with the world position of sample (i, j, k) given by `position` (beam-space grids:
// ShellGrid::sample_position); origin and spacing are left at 0 and 1.
Volume make_procedural_volume(const FieldSpec& field,
                              const std::function<glm::dvec3(std::int64_t, std::int64_t, std::int64_t)>& position);

// The sub-box of make_procedural_volume(field, origin, spacing) with voxels lo .. lo + dims - 1 (each
// value computed from its global indices and position, so the same bits); its origin is voxel lo's
// position. volref-mpi's bricks (cli/mpi/).
Volume make_procedural_brick(const FieldSpec& field, const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims);

}  // namespace volref
