#include "transfer/Shader.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/Lanes.h"

namespace volref {

#include "transfer/Shading-inl.h"

namespace {

ShadingConstants constants(const ShadingSpec& s) {
    ShadingConstants k;
    k.ka = s.ka;
    k.kd = s.kd;
    k.ks = s.ks;
    k.n = s.n;
    k.kc = s.kc;
    k.kl = s.kl;
    k.two_sided = s.two_sided;
    k.phong = s.model == ShadingSpec::Model::Phong;
    return k;
}

glm::dvec3 vec(const double v[3]) { return {v[0], v[1], v[2]}; }

LightTerms terms_of(const LightLanes<Scalar>& t) {
    LightTerms out;
    out.L = vec(t.Ld);
    out.H = vec(t.H);
    out.n_dot_l = t.n_dot_l;
    out.specular_dot = t.specular_dot;
    out.depth_cue = t.depth_cue;
    out.ambient = vec(t.ambient);
    out.diffuse = vec(t.diffuse);
    out.specular = vec(t.specular);
    return out;
}

}  // namespace

Shader::Shader(const ShadingSpec& spec, std::vector<LightSpec> lights, double zero_gradient_tolerance)
    : spec_(spec), lights_(std::move(lights)), tolerance_(zero_gradient_tolerance) {
    if (spec_.model == ShadingSpec::Model::Nodal) spec_.ks = 0.0;
}

// The lane templates of Shading-inl.h on one lane (the SIMD packets run the same ones).
LightTerms Shader::light_terms(const LightSpec& light, const glm::dvec3& m, const glm::dvec3& N,
                               const glm::dvec3& V, double depth) const {
    const glm::dvec3 L = light.type == LightSpec::Type::Headlight ? V : light.direction;
    const double n[3] = {N.x, N.y, N.z}, l[3] = {L.x, L.y, L.z}, v[3] = {V.x, V.y, V.z}, mm[3] = {m.r, m.g, m.b};
    const double I[3] = {light.color.r, light.color.g, light.color.b};
    LightLanes<Scalar> t;
    light_lanes<Scalar>(constants(spec_), n, l, v, depth, mm, I, t);
    return terms_of(t);
}

template <bool kTerms>
glm::dvec3 Shader::shade_impl(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth,
                              ShadeTerms* terms) const {
    double c[3] = {m.r, m.g, m.b}, N[3] = {0.0, 0.0, 0.0};
    const double g[3] = {gradient.x, gradient.y, gradient.z}, v[3] = {view.x, view.y, view.z};
    if constexpr (kTerms) terms->lights.clear();
    auto light_at = [&](int i, double* L, double* I) {
        const LightSpec& light = lights_[std::size_t(i)];
        const glm::dvec3 d = light.type == LightSpec::Type::Headlight ? view : light.direction;
        for (int a = 0; a < 3; ++a) {
            L[a] = d[a];
            I[a] = light.color[a];
        }
    };
    bool lit = false;
    const double length = shade_lanes<Scalar>(constants(spec_), tolerance_, int(lights_.size()), light_at, c, g, v, depth, N, lit,
                                              [&](int, const LightLanes<Scalar>& t) {
                                                  if constexpr (kTerms) terms->lights.push_back(terms_of(t));
                                              });
    if constexpr (kTerms) {
        terms->gradient_magnitude = length;
        terms->zero_gradient = !lit;
        terms->normal = lit ? vec(N) : glm::dvec3(0.0);
        terms->result = vec(c);
    }
    return vec(c);
}

glm::dvec3 Shader::shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth) const {
    return shade_impl<false>(m, gradient, view, depth, nullptr);
}

glm::dvec3 Shader::shade(const glm::dvec3& m, const glm::dvec3& gradient, const glm::dvec3& view, double depth,
                         ShadeTerms& terms) const {
    return shade_impl<true>(m, gradient, view, depth, &terms);
}

}  // namespace volref
