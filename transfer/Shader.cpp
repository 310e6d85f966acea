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
    t.n_dot_l = clamp_dot(glm::dot(N, L));
    if (spec_.model == ShadingSpec::Model::Phong) {
        const glm::dvec3 R = 2.0 * glm::dot(N, L) * N - L;
        t.specular_dot = std::max(glm::dot(R, V), 0.0);
    } else {
        t.specular_dot = clamp_dot(glm::dot(N, glm::normalize(L + V)));
    }
    t.depth_cue = 1.0 / (spec_.kc + spec_.kl * depth);
    const glm::dvec3 I = light.color;
    t.ambient = I * (spec_.ka * m);
    t.diffuse = I * (spec_.kd * m * t.n_dot_l * t.depth_cue);
    t.specular = spec_.ks == 0.0 ? glm::dvec3(0.0) : I * (spec_.ks * std::pow(t.specular_dot, spec_.n) * t.depth_cue);
    return t;
}

glm::dvec3 Shader::shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth) const {
    const double g = glm::length(gradient);
    if (!(g > tolerance_)) return m;
    const glm::dvec3 N = -gradient / g;
    glm::dvec3 c(0.0);
    for (const LightSpec& light : lights_) {
        const LightTerms t = light_terms(light, m, N, view, depth);
        c += t.ambient + t.diffuse + t.specular;
    }
    return c;
}

}  // namespace volref
