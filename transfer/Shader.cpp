#include "transfer/Shader.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace volref {

Shader::Shader(const ShadingSpec& spec, std::vector<LightSpec> lights, double zero_gradient_tolerance)
    : spec_(spec), lights_(std::move(lights)), tolerance_(zero_gradient_tolerance) {
    if (spec_.model == ShadingSpec::Model::Nodal) spec_.ks = 0.0;
}

LightTerms Shader::light_terms(const LightSpec& light, const glm::dvec3& m, const glm::dvec3& N,
                               const glm::dvec3& V, double depth) const {
    const glm::dvec3 L = light.type == LightSpec::Type::Headlight ? V : light.direction;
    auto clamp_dot = [&](double x) { return spec_.two_sided ? std::fabs(x) : std::max(x, 0.0); };
    LightTerms t;
    t.L = L;
    t.n_dot_l = clamp_dot(glm::dot(N, L));
    if (spec_.model == ShadingSpec::Model::Phong) {
        t.H = 2.0 * glm::dot(N, L) * N - L;  // R
        t.specular_dot = std::max(glm::dot(t.H, V), 0.0);
    } else {
        t.H = glm::normalize(L + V);
        t.specular_dot = clamp_dot(glm::dot(N, t.H));
    }
    t.depth_cue = 1.0 / (spec_.kc + spec_.kl * depth);
    const glm::dvec3 I = light.color;
    t.ambient = I * (spec_.ka * m);
    t.diffuse = I * (spec_.kd * m * t.n_dot_l * t.depth_cue);
    t.specular = spec_.ks == 0.0 ? glm::dvec3(0.0) : I * (spec_.ks * std::pow(t.specular_dot, spec_.n) * t.depth_cue);
    return t;
}

template <bool kTerms>
glm::dvec3 Shader::shade_impl(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth,
                              ShadeTerms* terms) const {
    const double g = glm::length(gradient);
    if constexpr (kTerms) {
        terms->gradient_magnitude = g;
        terms->zero_gradient = !(g > tolerance_);
        terms->normal = glm::dvec3(0.0);
        terms->lights.clear();
        terms->result = m;
    }
    if (!(g > tolerance_)) return m;
    const glm::dvec3 N = -gradient / g;
    glm::dvec3 c(0.0);
    for (const LightSpec& light : lights_) {
        const LightTerms t = light_terms(light, m, N, view, depth);
        c += t.ambient + t.diffuse + t.specular;
        if constexpr (kTerms) terms->lights.push_back(t);
    }
    if constexpr (kTerms) {
        terms->normal = N;
        terms->result = c;
    }
    return c;
}

glm::dvec3 Shader::shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth) const {
    return shade_impl<false>(m, gradient, view, depth, nullptr);
}

glm::dvec3 Shader::shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth,
                         ShadeTerms& terms) const {
    return shade_impl<true>(m, gradient, view, depth, &terms);
}

}  // namespace volref
