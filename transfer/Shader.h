// Shader: gradient shading of a sample's colour (conventions section 8).
//
// N = -grad f / |grad f| (normals point from dense to thin). V = the unit vector towards the eye
// (-ray direction), d = the sample's distance from the eye (its ray parameter t). For each light of
// colour I and unit direction L towards it (a headlight has L = V; a directional light its fixed
// direction), with H = normalize(L + V) and R = 2 (N.L) N - L:
//   blinn-phong: c_l = I (ka m + (kd m max(N.L, 0) + ks max(N.H, 0)^n) / (kc + kl d))
//   phong:       the same with max(R.V, 0) in place of max(N.H, 0)
//   nodal:       Levoy's lecture model, ks = 0: c_l = I (ka m + kd m max(N.L, 0) / (kc + kl d))
// Two-sided lighting uses |N.L| and |N.H| (R does not depend on the sign of N). Several lights add:
// c_out = sum_l c_l (so each light brings its own ambient term; with no lights c_out = 0).
// Where |grad f| <= the zero-gradient tolerance the sample is unshaded: c_out = m exactly.
// Colours are not clamped (a reference keeps the exact sum; mirror profiles clamp).
#pragma once
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene/Scene.h"

namespace volref {

// Every term of one light's contribution, for `explain` and tests.
struct LightTerms {
    glm::dvec3 L{0.0};           // unit vector towards the light (V for a headlight)
    glm::dvec3 H{0.0};           // blinn-phong: normalize(L + V); phong: R = 2 (N.L) N - L
    double n_dot_l = 0.0;        // after max(., 0) or |.|
    double specular_dot = 0.0;   // N.H (blinn-phong) or R.V (phong), after max(., 0) or |.|
    double depth_cue = 1.0;      // 1 / (kc + kl d)
    glm::dvec3 ambient{0.0}, diffuse{0.0}, specular{0.0};  // I ka m, I kd m (N.L) cue, I ks dot^n cue
};

// Every term of one shaded sample: |grad f|, N, each light's terms, the result.
struct ShadeTerms {
    double gradient_magnitude = 0.0;
    bool zero_gradient = false;  // |grad f| <= the tolerance: unshaded, c = m
    glm::dvec3 normal{0.0};      // N = -grad f / |grad f| (0 when zero_gradient)
    std::vector<LightTerms> lights;
    glm::dvec3 result{0.0};      // what shade() returns
};

class Shader {
public:
    Shader(const ShadingSpec& spec, std::vector<LightSpec> lights, double zero_gradient_tolerance);

    // m: material colour; gradient: grad f in world units; view: unit vector towards the eye;
    // depth: distance from the eye.
    glm::dvec3 shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth) const;
    // The same computation (the same instructions), also filling `terms`.
    glm::dvec3 shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth,
                     ShadeTerms& terms) const;
    // One light's terms for a unit normal N.
    LightTerms light_terms(const LightSpec& light, const glm::dvec3& m, const glm::dvec3& N, const glm::dvec3& view,
                           double depth) const;
    double zero_gradient_tolerance() const { return tolerance_; }
    // The coefficients (ks = 0 for nodal) and the lights (read by the SIMD path, PacketComposite.h).
    const ShadingSpec& spec() const { return spec_; }
    const std::vector<LightSpec>& lights() const { return lights_; }

private:
    template <bool kTerms>
    glm::dvec3 shade_impl(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth,
                          ShadeTerms* terms) const;
    ShadingSpec spec_;
    std::vector<LightSpec> lights_;
    double tolerance_;
};

}  // namespace volref
