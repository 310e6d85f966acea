#include "python/SceneDict.h"

#include "core/integrate/profiles/Profile.h"

#include "core/explain/PixelTrace.h"

#include <glm/mat4x4.hpp>

namespace volref::python {

namespace {

using json = nlohmann::ordered_json;

json vec(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }
json vec(const glm::dvec4& v) { return json::array({v.x, v.y, v.z, v.w}); }
template <class T, std::size_t N> json vec(const std::array<T, N>& a) {
    json j = json::array();
    for (const T& x : a) j.push_back(x);
    return j;
}
template <std::size_t N> json rows(const std::vector<std::array<double, N>>& r) {
    json j = json::array();
    for (const auto& row : r) j.push_back(vec(row));
    return j;
}

const char* interpolation_name(Interpolation i) {
    switch (i) {
        case Interpolation::Nearest: return "nearest";
        case Interpolation::Trilinear: return "trilinear";
        case Interpolation::TricubicBSpline: return "tricubic-bspline";
        case Interpolation::TricubicCatmullRom: return "tricubic-catmull-rom";
    }
    return "trilinear";
}

json field_json(const FieldSpec& f) {
    using K = FieldSpec::Kind;
    json j;
    switch (f.kind) {
        case K::Constant: j["field"] = "constant"; break;
        case K::Linear: j["field"] = "linear"; break;
        case K::Radial: j["field"] = "radial"; break;
        case K::MarschnerLobb: j["field"] = "marschner-lobb"; break;
        case K::Gaussian: j["field"] = "gaussian"; break;
        case K::Cells: j["field"] = "cells"; break;
    }
    j["dims"] = vec(f.dims);
    switch (f.kind) {
        case K::Constant: j["value"] = f.value; break;
        case K::Linear: j["coefficients"] = vec(f.coefficients); break;
        case K::Radial: j["center"] = vec(f.center); break;
        case K::MarschnerLobb:
            j["fm"] = f.fm;
            j["alpha"] = f.alpha;
            break;
        case K::Gaussian:
            j["center"] = vec(f.center);
            j["sigma"] = f.sigma;
            j["amplitude"] = f.amplitude;
            break;
        case K::Cells: j["values"] = f.values; break;
    }
    return j;
}

json source_json(const VolumeSourceSpec& s) {
    if (s.field) return field_json(*s.field);
    json j;
    j["file"] = s.file ? s.file->string() : std::string();
    if (!s.format.empty()) j["format"] = s.format;
    return j;
}

json bounds_json(const BoundsSpec& b) {
    using T = BoundsSpec::Type;
    json j;
    switch (b.type) {
        case T::Box:
            j["type"] = "box";
            if (b.min) j["min"] = vec(*b.min);
            if (b.max) j["max"] = vec(*b.max);
            return j;
        case T::Mesh:
            j["type"] = "mesh";
            j["file"] = b.mesh.string();
            return j;
        case T::Cylindrical: {
            const CylindricalShell& c = b.cylinder;
            j["type"] = "cylindrical";
            j["center"] = vec(c.center);
            j["radius"] = {c.r0, c.r1};
            j["angle"] = {c.a0, c.a1};
            j["height"] = {c.h0, c.h1};
            break;
        }
        case T::Spherical: {
            const SphericalShell& s = b.sphere;
            static const char* const names[] = {"longitude", "latitude", "radius"};
            j["type"] = "spherical";
            j["center"] = vec(s.center);
            j["radius"] = {s.r0, s.r1};
            j["longitude"] = {s.lon0, s.lon1};
            j["latitude"] = {s.lat0, s.lat1};
            j["axes"] = {names[s.axes[0]], names[s.axes[1]], names[s.axes[2]]};
            break;
        }
    }
    if (b.tessellate > 0) j["tessellate"] = b.tessellate;
    return j;
}

json transfer_json(const TransferSpec& t) {
    json j;
    j["domain"] = t.domain == TransferSpec::Domain::Normalized ? "normalized" : "data";
    if (t.window) j["window"] = vec(*t.window);
    if (!t.color.empty()) j["color"] = rows(t.color);
    if (!t.opacity.empty()) j["opacity"] = rows(t.opacity);  // absent: the default ramp over the window
    j["opacity_unit_distance"] = t.opacity_unit_distance;
    if (!t.gradient_opacity.empty()) j["gradient_opacity"] = rows(t.gradient_opacity);
    return j;
}

json classification_json(const ClassificationSpec& c) {
    json j;
    if (c.type == ClassificationSpec::Type::Isovalue) {
        j["type"] = "isovalue";
        j["isovalues"] = json::array();
        for (const IsovalueContour& i : c.isovalues)
            j["isovalues"].push_back(
                {{"value", i.value}, {"opacity", i.opacity}, {"thickness", i.thickness}, {"color", vec(i.color)}});
    } else {
        j["type"] = "boundary";
        j["regions"] = json::array();
        for (const BoundaryRegion& r : c.regions)
            j["regions"].push_back({{"value", r.value}, {"opacity", r.opacity}, {"color", vec(r.color)}});
    }
    j["opacity_unit_distance"] = c.opacity_unit_distance;
    return j;
}

json shading_json(const ShadingSpec& s) {
    using M = ShadingSpec::Model;
    json j;
    j["model"] = s.model == M::Nodal ? "nodal" : s.model == M::Phong ? "phong" : "blinn-phong";
    j["ka"] = s.ka;
    j["kd"] = s.kd;
    if (s.model != M::Nodal) {
        j["ks"] = s.ks;
        j["n"] = s.n;
    }
    j["kc"] = s.kc;
    j["kl"] = s.kl;
    j["two_sided"] = s.two_sided;
    return j;
}

json gradient_json(const GradientSpec& g) {
    using S = GradientSpec::Scheme;
    json j = json::object();
    if (g.scheme == S::Central) j["scheme"] = "central";
    if (g.scheme == S::Forward) j["scheme"] = "forward";
    if (g.scheme == S::Analytic) j["scheme"] = "analytic";
    if (g.cache_auto)
        j["cache"] = "auto";
    else
        j["cache"] = g.cache;
    return j;
}

// Row-major, as the scene file writes a transform (m[col][row]).
json row_major(const glm::dmat4& m) {
    json j = json::array();
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) j.push_back(m[col][row]);
    return j;
}
// Column-major, as the camera's OpenGL matrices are written.
json column_major(const glm::dmat4& m) {
    json j = json::array();
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) j.push_back(m[col][row]);
    return j;
}

json volume_json(const VolumeSpec& v) {
    json j;
    j["source"] = source_json(v.source);
    if (v.origin) j["origin"] = vec(*v.origin);
    if (v.spacing) j["spacing"] = vec(*v.spacing);
    j["interpolation"] = interpolation_name(v.interpolation);
    j["classify"] = v.classify == VolumeSpec::Classify::Pre ? "pre" : "post";
    j["bounds"] = bounds_json(v.bounds);
    if (v.classification)
        j["classification"] = classification_json(*v.classification);
    else
        j["transfer"] = transfer_json(v.transfer);
    if (v.shading) j["shading"] = shading_json(*v.shading);
    // A shell volume takes no gradient options (docs/scene-format.md): written only when they differ
    // from the defaults.
    const bool shell = v.bounds.type == BoundsSpec::Type::Cylindrical || v.bounds.type == BoundsSpec::Type::Spherical;
    const GradientSpec none{};
    if (!shell || v.gradient.scheme != none.scheme || v.gradient.cache || v.gradient.cache_auto)
        j["gradient"] = gradient_json(v.gradient);
    if (v.transform) j["transform"] = row_major(*v.transform);
    if (!v.clip_planes.empty()) {
        j["clip_planes"] = json::array();
        for (const ClipPlaneSpec& c : v.clip_planes)
            j["clip_planes"].push_back({{"point", vec(c.point)}, {"normal", vec(c.normal)}});
    }
    if (v.crop) j["crop"] = {{"planes", vec(v.crop->planes)}, {"regions", v.crop->regions}};
    return j;
}


const char* profile_name(ProfileId p) {
    switch (p) {
        case ProfileId::Reference: return "reference";
        case ProfileId::VtkGpu: return "vtk-gpu";
        case ProfileId::GlslBasic: return "glsl-basic";
        case ProfileId::Ospray: return "ospray";
        case ProfileId::CudaCurvilinear: return "cuda-curvilinear";
        case ProfileId::VtkCpu: return "vtk-cpu";
        case ProfileId::Fast: return "fast";
        case ProfileId::VtkJs: return "vtk-js";
    }
    return "reference";
}

json render_json(const RenderSpec& r) {
    json j;
    j["projection"] = explain::projection_name(r.projection);  // the name trace and explain print
    j["order"] = r.order == CompositeOrder::BackToFront ? "back-to-front" : "front-to-back";
    j["step"] = r.step;
    j["step_units"] = r.step_units == StepUnits::World ? "world" : "voxel";
    if (r.isovalue) j["isovalue"] = *r.isovalue;
    if (r.early_termination) j["early_termination"] = *r.early_termination;
    j["gain"] = r.gain;
    j["integrator"] = r.integrator == IntegrationMethod::Adaptive ? "adaptive" : "fixed";
    j["tolerance"] = r.tolerance;
    j["profile"] = profile_name(r.profile);
    const ProfileRules& rules = r.profile_rules;
    if (!rules.empty()) {  // issue 29: every rule of the resolved profile (texture_unit and arithmetic where the scene set them)
        j["profile"] = profile_rules_json(resolve_profile(r));
        if (rules.texture_unit) j["profile"]["texture_unit"] = *rules.texture_unit == ProfileOptions::TextureUnit::H100 ? "h100" : "exact";
        if (rules.arithmetic) j["profile"]["arithmetic"] = *rules.arithmetic == ProfileRules::Arithmetic::Float32 ? "float32" : "double";
    }
    if (r.profile == ProfileId::CudaCurvilinear)
        j["profile_options"] = {{"density", r.profile_options.density},
                                {"transfer_scale", r.profile_options.transfer_scale},
                                {"iso_threshold", r.profile_options.iso_threshold},
                                {"brightness", r.profile_options.brightness}};
    if (r.profile == ProfileId::GlslBasic) j["profile_options"] = {{"intensity", r.profile_options.intensity}};
    if (r.profile == ProfileId::CudaCurvilinear || r.profile == ProfileId::GlslBasic || r.profile == ProfileId::VtkGpu) {
        // issue 17: listed when not the defaults
        if (r.profile_options.texture_unit == ProfileOptions::TextureUnit::H100 && !rules.texture_unit)
            j["profile_options"]["texture_unit"] = "h100";
        if (r.profile_options.texture_band) j["profile_options"]["texture_band"] = true;
        if (r.profile_options.data_unorm16) j["profile_options"]["texture_format"] = "unorm16";
    }
    if (r.profile == ProfileId::CudaCurvilinear && r.profile_options.kernel == ProfileOptions::Kernel::Double && !rules.arithmetic)
        j["profile_options"]["kernel"] = "double";  // issue 28
    if (r.profile == ProfileId::CudaCurvilinear && r.profile_options.tricubic) j["profile_options"]["tricubic"] = true;
    if (r.profile == ProfileId::VtkJs)  // issue 22
        j["profile_options"] = {{"jitter", r.profile_options.jitter}, {"fixed_normal", r.profile_options.fixed_normal},
                                {"flip_normal", r.profile_options.flip_normal},
                                {"ray_box", r.profile_options.ray_box_domain ? "domain" : "texel"},
                                {"mip_correction", r.profile_options.mip_correction},
                                {"subpixel_bits", r.profile_options.subpixel_bits}};
    return j;
}

}  // namespace

json scene_to_json(const Scene& scene) {
    json j;
    if (scene.volumes.size() == 1) {
        j["volume"] = volume_json(scene.volumes.front());
    } else {
        j["volumes"] = json::array();
        for (const VolumeSpec& v : scene.volumes) j["volumes"].push_back(volume_json(v));
    }
    j["lights"] = json::array();
    for (const LightSpec& l : scene.lights) {
        if (l.type == LightSpec::Type::Headlight)
            j["lights"].push_back({{"type", "headlight"}, {"color", vec(l.color)}});
        else
            j["lights"].push_back({{"type", "directional"}, {"direction", vec(l.direction)}, {"color", vec(l.color)}});
    }
    const CameraSpec& c = scene.camera;
    switch (c.type) {
        case CameraSpec::Type::Default: break;  // placed from the volumes' bounds (Camera.h)
        case CameraSpec::Type::Perspective:
            j["camera"] = {{"type", "perspective"}, {"eye", vec(c.eye)}, {"target", vec(c.target)}, {"up", vec(c.up)},
                           {"fov_y", c.fov_y}};
            break;
        case CameraSpec::Type::Orthographic:
            j["camera"] = {{"type", "orthographic"}, {"eye", vec(c.eye)}, {"target", vec(c.target)}, {"up", vec(c.up)},
                           {"height", c.height}};
            break;
        case CameraSpec::Type::Matrices:
            j["camera"] = {{"type", "matrices"}, {"view", column_major(c.view)}, {"projection", column_major(c.projection)}};
            break;
    }
    j["image"] = {{"width", scene.image.width}, {"height", scene.image.height}, {"background", vec(scene.image.background)}};
    j["render"] = render_json(scene.render);
    return j;
}

}  // namespace volref::python
