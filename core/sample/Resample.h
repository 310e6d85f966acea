// Resampling between Cartesian volumes and beam-space volumes on cylindrical or spherical shells
// (docs/shells.md): every output sample is the source field, reconstructed with the given
// interpolation, at that sample's world position.
//   to a shell:     sample (i, j, k) sits at ShellGrid::sample_position(i, j, k); the source is a
//                   Cartesian volume read by VolumeSampler. A sample outside the source's domain
//                   (by more than 1e-9 of a spacing on some axis: rounding of the shell's sin/cos at a
//                   domain face is not "outside") gets `fill`.
//   to Cartesian:   voxel (i, j, k) sits at origin + (i, j, k) spacing; the source is a beam-space
//                   volume read by ShellSampler. A voxel outside the shell region (ShellGrid::contains
//                   with tolerance 1e-9 of each axis' range) gets `fill`.
// A beam-space result has origin (0, 0, 0) and spacing (1, 1, 1) (its grid indices: the shell, not
// the origin and spacing, places its samples); every result has type F64. Samples are computed in
// parallel; each depends only on its own position, so the result does not depend on the thread count.
#pragma once
#include <array>
#include <cstdint>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"
#include "core/scene/Scene.h"
#include "core/scene/ShellSpec.h"

namespace volref {

// The tolerances above.
inline constexpr double kResampleDomainTolerance = 1e-9;  // in spacings (Cartesian source)
inline constexpr double kResampleShellTolerance = 1e-9;   // in axis ranges (beam-space source)

// `dims` are the beam-space grid's, in its grid-axis order (cylinder (radius, angle, height); sphere
// per SphericalShell::axes). Throw volref::Error on an invalid shell or dims.
Volume resample_to_cylindrical(const Volume& cartesian, Interpolation interpolation, const CylindricalShell& shell,
                               const std::array<std::int64_t, 3>& dims, double fill = 0.0);
Volume resample_to_spherical(const Volume& cartesian, Interpolation interpolation, const SphericalShell& shell,
                             const std::array<std::int64_t, 3>& dims, double fill = 0.0);

// `beam`'s dims are its grid's. Throw volref::Error on an invalid shell, dims, origin or spacing
// (finite, spacing > 0).
Volume resample_to_cartesian(const Volume& beam, const CylindricalShell& shell, Interpolation interpolation,
                             const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& dims, double fill = 0.0);
Volume resample_to_cartesian(const Volume& beam, const SphericalShell& shell, Interpolation interpolation,
                             const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& dims, double fill = 0.0);

}  // namespace volref
