// ShellSampler: the reconstructed field of a beam-space volume (data on a cylindrical or spherical
// shell grid, geometry/ShellCoordinates.h) at any world point (docs/shells.md).
//
// A world point is converted to shell coordinates and then to the continuous grid index u
// (ShellGrid::continuous_index); the field is reconstructed in index space, as VolumeSampler does on a
// Cartesian grid (conventions section 2), except that on a periodic axis (a full 360-degree angle or
// longitude) indices wrap modulo n instead of clamping:
//   nearest:   per axis i = floor(u + 0.5); clamped to [0, n - 1], or taken modulo n when periodic;
//   trilinear: per axis the cell i and fraction p: non-periodic i = min(floor(u), n - 2) (0 when n = 1)
//              with u clamped to [0, n - 1]; periodic i = floor(u) with u in [0, n), the other corner
//              (i + 1) mod n, so the cell [n - 1, n) interpolates between the last and the first sample.
//              Corners in Levoy's order, summed by volref::trilinear (Trilinear.h);
//   tricubic:  the same cells and fractions, B-spline or Catmull-Rom weights (cubic_weights), taps
//              i-1 .. i+2 clamped to [0, n - 1], or taken modulo n when periodic; the nested 1-D passes
//              of Tricubic.h (along axis 0 for each (j, k), then 1, then 2).
// An axis with n = 1 uses its single layer (fraction 0, cubic weights (0, 1, 0, 0)). NaN indices read
// as 0. The volume's origin and spacing are not used: the shell places the samples.
// On a non-periodic grid the values equal VolumeSampler's on the same index, bit for bit.
//
// Near the axis (r = 0) and the poles the radial and latitude axes clamp (no taps across the axis or
// over the pole), and the angle there is 0 (ShellCoordinates.h).
#pragma once
#include <array>
#include <cstdint>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"
#include "core/scene/Scene.h"
#include "core/scene/ShellSpec.h"
#include "geometry/ShellCoordinates.h"

namespace volref {

class ShellSampler {
public:
    // The volume's dims are the grid's (axes as ShellGrid says). gradient_step: the step h of
    // gradient(); 0 means ShellGrid::default_gradient_step(). Throws volref::Error on an invalid
    // shell, a volume whose value count does not match its dims, or a step that is not finite and >= 0.
    ShellSampler(const Volume& volume, const CylindricalShell& shell, Interpolation interpolation,
                 double gradient_step = 0.0);
    ShellSampler(const Volume& volume, const SphericalShell& shell, Interpolation interpolation,
                 double gradient_step = 0.0);

    double value(const glm::dvec3& world) const { return index_value(grid_.continuous_index(world)); }
    // The reconstruction at continuous grid index u.
    double index_value(const glm::dvec3& u) const;
    double nearest(const glm::dvec3& u) const;
    double trilinear(const glm::dvec3& u) const;
    double tricubic(const glm::dvec3& u) const;

    // grad f in world units, by differences of value() along the world axes with step h:
    // on axis a, with p+ = x + h e_a and p- = x - h e_a,
    //   both in the shell region: (f(p+) - f(p-)) / (p+_a - p-_a)  (central);
    //   only p+:                  (f(p+) - f(x)) / (p+_a - x_a)     (forward);
    //   only p-:                  (f(x) - f(p-)) / (x_a - p-_a)     (backward);
    //   neither:                  0.
    // "In the shell region" is ShellGrid::contains (no tolerance).
    glm::dvec3 gradient(const glm::dvec3& world) const;
    double gradient_step() const { return h_; }

    const ShellGrid& grid() const { return grid_; }
    const Volume& volume() const { return volume_; }
    Interpolation interpolation() const { return interpolation_; }

private:
    void check();
    const Volume& volume_;
    ShellGrid grid_;
    Interpolation interpolation_;
    double h_;
    std::array<bool, 3> periodic_;
};

}  // namespace volref
