// VolumeSampler: the reconstructed field f(x) of a Volume at any world point (conventions section 2).
//
// A world point x maps to the continuous index u = (x - origin) / spacing, clamped to [0, n - 1] on
// each axis (points outside the domain take the value on its boundary; the integrators only ask
// inside it). Then
//   nearest:   the voxel floor(u + 0.5) (round half up), clamped to [0, n - 1];
//   trilinear: the cell i = min(floor(u), n - 2) (0 when n = 1) with fraction p = u - i, evaluated by
//              trilinear() in Levoy's corner order; an axis with n = 1 uses the same voxel twice;
//   tricubic:  the same cell and fraction, the B-spline or Catmull-Rom tensor-product cubic over the
//              4 x 4 x 4 taps i-1 .. i+2 with indices clamped to [0, n - 1] (Tricubic.h).
#pragma once
#include <array>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"
#include "core/scene/Scene.h"

namespace volref {

class VolumeSampler {
public:
    VolumeSampler(const Volume& volume, Interpolation interpolation);

    double value(const glm::dvec3& world) const {
        switch (interpolation_) {
            case Interpolation::Nearest: return nearest(world);
            case Interpolation::Trilinear: return trilinear(world);
            default: return tricubic(world);
        }
    }
    double nearest(const glm::dvec3& world) const;
    double trilinear(const glm::dvec3& world) const;
    double tricubic(const glm::dvec3& world) const;
    // The analytic gradient of the tricubic reconstruction, in world units (tricubic kernels only).
    glm::dvec3 tricubic_gradient(const glm::dvec3& world) const;
    Interpolation interpolation() const { return interpolation_; }
    bool is_tricubic() const {
        return interpolation_ == Interpolation::TricubicBSpline || interpolation_ == Interpolation::TricubicCatmullRom;
    }

    // The continuous index u of a world point, clamped to the domain.
    glm::dvec3 continuous_index(const glm::dvec3& world) const;
    // The cell containing u (lower corner) and the fractional position in it, per axis.
    void locate(const glm::dvec3& u, std::array<std::int64_t, 3>& cell, glm::dvec3& frac) const;
    // The corner values f1..f8 of a cell, in Levoy's order.
    std::array<double, 8> corners(const std::array<std::int64_t, 3>& cell) const;

    const Volume& volume() const { return volume_; }

private:
    const Volume& volume_;
    Interpolation interpolation_;
    glm::dvec3 inv_spacing_;
    glm::dvec3 max_index_;
};

}  // namespace volref
