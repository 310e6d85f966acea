// explain shade: one sample's shading (conventions section 8), every term from Shader itself
// (Shader::shade with ShadeTerms, Shader::light_terms).
#include <cmath>
#include <string>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include <glm/geometric.hpp>

#include "transfer/Shader.h"
#include "core/scene/SceneNames.h"

namespace volref::explain {

namespace {
std::vector<double> v3(const glm::dvec3& c) { return {c.x, c.y, c.z}; }
const char* model_name(ShadingSpec::Model m) { return scene_names::name_of(scene_names::kShadingModels, m); }
}  // namespace

Explanation shade(const ShadeInput& in) {
    const ShadingSpec& k = in.spec;
    for (double c : {in.gradient.x, in.gradient.y, in.gradient.z})
        if (!std::isfinite(c)) throw Error("--gradient: must be finite");
    if (!(std::fabs(glm::dot(in.view, in.view) - 1.0) < 1e-12)) throw Error("--view: must be a unit vector");
    if (!(k.kc + k.kl * in.depth > 0.0)) throw Error("--kc: kc + kl d must be > 0");
    const Shader shader(in.spec, in.lights, 0.0);
    Explanation e;
    e.topic = "shade";
    Section& s = e.section("inputs");
    add(s, "grad f", v3(in.gradient));
    add(s, "V", v3(in.view), "unit vector towards the eye");
    add(s, "m", v3(in.material), "material (classified) colour");
    add(s, "d", in.depth, "distance from the eye (depth cue)");
    s.notes.push_back(std::string("model ") + model_name(k.model) + (k.two_sided ? ", two-sided" : ""));
    add(s, "ka", k.ka);
    add(s, "kd", k.kd);
    add(s, "ks", shader.spec().ks, k.model == ShadingSpec::Model::Nodal ? "0 for nodal" : "");
    add(s, "n", k.n);
    add(s, "kc", k.kc);
    add(s, "kl", k.kl);

    ShadeTerms terms;
    const glm::dvec3 c = shader.shade(in.material, in.gradient, in.view, in.depth, terms);
    Section& n = e.section("normal");
    add(n, "|grad f|", terms.gradient_magnitude);
    if (terms.zero_gradient) {
        n.notes.push_back("|grad f| = 0: the sample is unshaded, c = m");
    } else {
        add(n, "N", v3(terms.normal), "-grad f / |grad f|");
        for (std::size_t l = 0; l < terms.lights.size(); ++l) {
            const LightTerms& t = terms.lights[l];
            const LightSpec& ls = in.lights[l];
            Section& L = e.section("light " + std::to_string(l + 1) +
                                   (ls.type == LightSpec::Type::Headlight ? " (headlight)" : " (directional)"));
            add(L, "I", v3(ls.color), "light colour");
            add(L, "L", v3(t.L), ls.type == LightSpec::Type::Headlight ? "= V" : "towards the light");
            const bool phong = k.model == ShadingSpec::Model::Phong;
            add(L, phong ? "R" : "H", v3(t.H), phong ? "2 (N.L) N - L" : "normalize(L + V)");
            add(L, "N.L", t.n_dot_l, k.two_sided ? "|N.L|" : "max(N.L, 0)");
            add(L, phong ? "R.V" : "N.H", t.specular_dot, phong ? "max(R.V, 0)" : (k.two_sided ? "|N.H|" : "max(N.H, 0)"));
            add(L, "cue", t.depth_cue, "1 / (kc + kl d)");
            add(L, "ambient", v3(t.ambient), "I ka m");
            add(L, "diffuse", v3(t.diffuse), "I kd m (N.L) cue");
            add(L, "specular", v3(t.specular), phong ? "I ks (R.V)^n cue" : "I ks (N.H)^n cue");
        }
    }
    Section& r = e.section("result (Shader::shade)");
    add(r, "c", v3(c), "sum over lights of ambient + diffuse + specular (not clamped)");
    return e;
}

}  // namespace volref::explain
