// GradientField: grad f at a world point, in world units (value per world unit), for shading and
// gradient-based classification (conventions section 2). Built only when a scene needs gradients.
//
// On axis a with spacing h, domain [lo, hi] and x the point's coordinate:
//   central:  g_a = (f(b) - f(c)) / (b - c) with c = max(x - h, lo), b = min(x + h, hi): the central
//             difference (f(x + h) - f(x - h)) / 2h inside, one-sided at the domain boundary;
//   forward:  g_a = (f(x + h) - f(x)) / h where x + h <= hi, else the backward difference
//             (f(x) - f(c)) / (x - c) with c = max(x - h, lo);
//   analytic: the derivative of the tricubic reconstruction (tricubic kernels only);
// g_a = 0 on an axis with n = 1. f is the reconstructed field, so a linear field's gradient is
// exact everywhere, including at the boundary.
// With `cache`, the chosen scheme is evaluated once at every voxel (in parallel) and the gradient at
// x is the trilinear interpolation of those voxel gradients (what GPU renderers with a gradient
// texture do); it differs from the on-the-fly gradient by the interpolation error, O(h^2).
#pragma once
#include <memory>

#include <glm/vec3.hpp>

#include "core/sample/FieldSampler.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/Scene.h"

namespace volref {

class GradientField final : public GradientSource {
public:
    GradientField(const VolumeSampler& sampler, GradientSpec spec);
    ~GradientField();

    glm::dvec3 gradient(const glm::dvec3& world) const override;
    // The scheme after resolving Default (analytic for tricubic kernels, central otherwise).
    GradientSpec::Scheme scheme() const { return scheme_; }
    // With `cache`: component a (0, 1, 2) of the per-voxel gradients; null without a cache.
    const Volume* cached_component(int a) const;

private:
    glm::dvec3 on_the_fly(const glm::dvec3& world) const;
    const VolumeSampler& sampler_;
    GradientSpec::Scheme scheme_;
    glm::dvec3 lo_, hi_;
    struct Cache;
    std::unique_ptr<Cache> cache_;
};

}  // namespace volref
