#include "core/scene/SceneWriter.h"

#include "core/scene/ProfileRuleTable.h"
#include "core/scene/SceneNames.h"

namespace volref {

namespace {

using json = nlohmann::ordered_json;
using scene_names::name_of;
namespace names = scene_names;

json vec(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }
json vec(const glm::dvec4& v) { return json::array({v.x, v.y, v.z, v.w}); }
template <class T, std::size_t N>
json vec(const std::array<T, N>& a) {
    json j = json::array();
    for (const T& x : a) j.push_back(x);
    return j;
}
template <std::size_t N>
json rows(const std::vector<std::array<double, N>>& r) {
    json j = json::array();
    for (const auto& row : r) j.push_back(vec(row));
    return j;
}

// Each field writes only its own parameters, as read_field reads them.
json field_json(const FieldSpec& f) {
    using K = FieldSpec::Kind;
    json j;
    j["field"] = name_of(names::kFields, f.kind);
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
    j["type"] = name_of(names::kBounds, b.type);
    switch (b.type) {
        case T::Box:
            if (b.min) j["min"] = vec(*b.min);
            if (b.max) j["max"] = vec(*b.max);
            return j;
        case T::Mesh: j["file"] = b.mesh.string(); return j;
        case T::Tetrahedra:
            j["file"] = b.mesh.string();
            j["overlap"] = name_of(names::kOverlaps, b.overlap);
            return j;
        case T::Cylindrical: {
            const CylindricalShell& c = b.cylinder;
            j["center"] = vec(c.center);
            j["radius"] = {c.r0, c.r1};
            j["angle"] = {c.a0, c.a1};
            j["height"] = {c.h0, c.h1};
            break;
        }
        case T::Spherical: {
            const SphericalShell& s = b.sphere;
            j["center"] = vec(s.center);
            j["radius"] = {s.r0, s.r1};
            j["longitude"] = {s.lon0, s.lon1};
            j["latitude"] = {s.lat0, s.lat1};
            j["axes"] = json::array();
            for (int a : s.axes) j["axes"].push_back(name_of(names::kSphericalAxes, a));
            break;
        }
    }
    if (b.tessellate > 0) j["tessellate"] = b.tessellate;
    return j;
}

json transfer_json(const TransferSpec& t) {
    json j;
    j["domain"] = name_of(names::kTransferDomains, t.domain);
    if (t.window) j["window"] = vec(*t.window);
    if (!t.color.empty()) j["color"] = rows(t.color);
    if (!t.opacity.empty()) j["opacity"] = rows(t.opacity);  // absent: the default ramp over the window
    j["opacity_unit_distance"] = t.opacity_unit_distance;
    if (!t.gradient_opacity.empty()) j["gradient_opacity"] = rows(t.gradient_opacity);
    return j;
}

json classification_json(const ClassificationSpec& c) {
    json j;
    j["type"] = name_of(names::kClassifications, c.type);
    if (c.type == ClassificationSpec::Type::Isovalue) {
        j["isovalues"] = json::array();
        for (const IsovalueContour& i : c.isovalues)
            j["isovalues"].push_back({{"value", i.value}, {"opacity", i.opacity}, {"thickness", i.thickness}, {"color", vec(i.color)}});
    } else {
        j["regions"] = json::array();
        for (const BoundaryRegion& r : c.regions)
            j["regions"].push_back({{"value", r.value}, {"opacity", r.opacity}, {"color", vec(r.color)}});
    }
    j["opacity_unit_distance"] = c.opacity_unit_distance;
    return j;
}

json shading_json(const ShadingSpec& s) {
    json j;
    j["model"] = name_of(names::kShadingModels, s.model);
    j["ka"] = s.ka;
    j["kd"] = s.kd;
    if (s.model != ShadingSpec::Model::Nodal) {  // nodal shading has no specular term (read_shading)
        j["ks"] = s.ks;
        j["n"] = s.n;
    }
    j["kc"] = s.kc;
    j["kl"] = s.kl;
    j["two_sided"] = s.two_sided;
    return j;
}

json gradient_json(const GradientSpec& g) {
    json j = json::object();
    if (g.scheme != GradientSpec::Scheme::Default) j["scheme"] = name_of(names::kGradientSchemes, g.scheme);
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
    j["interpolation"] = name_of(names::kInterpolations, v.interpolation);
    j["classify"] = name_of(names::kClassify, v.classify);
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
        for (const ClipPlaneSpec& c : v.clip_planes) j["clip_planes"].push_back({{"point", vec(c.point)}, {"normal", vec(c.normal)}});
    }
    if (v.crop) j["crop"] = {{"planes", vec(v.crop->planes)}, {"regions", v.crop->regions}};
    return j;
}

json light_json(const LightSpec& l) {
    json j;
    j["type"] = name_of(names::kLights, l.type);
    if (l.type == LightSpec::Type::Directional) j["direction"] = vec(l.direction);
    j["color"] = vec(l.color);
    return j;
}

json camera_json(const CameraSpec& c) {
    json j;
    j["type"] = name_of(names::kCameras, c.type);
    if (c.type == CameraSpec::Type::Matrices) {
        j["view"] = column_major(c.view);
        j["projection"] = column_major(c.projection);
        return j;
    }
    j["eye"] = vec(c.eye);
    j["target"] = vec(c.target);
    j["up"] = vec(c.up);
    if (c.type == CameraSpec::Type::Perspective)
        j["fov_y"] = c.fov_y;
    else
        j["height"] = c.height;
    if (c.near) j["near"] = *c.near;
    if (c.far) j["far"] = *c.far;
    return j;
}

// render.profile_options: each profile's own keys (read_render), written where they are not the
// defaults or where the profile always lists them.
json profile_options_json(const RenderSpec& r) {
    const ProfileOptions& o = r.profile_options;
    const ProfileRules& rules = r.profile_rules;
    json j;
    if (r.profile == ProfileId::CudaCurvilinear)
        j = {{"density", o.density}, {"transfer_scale", o.transfer_scale}, {"iso_threshold", o.iso_threshold}, {"brightness", o.brightness}};
    if (r.profile == ProfileId::GlslBasic) j = {{"intensity", o.intensity}};
    if (r.profile == ProfileId::CudaCurvilinear || r.profile == ProfileId::GlslBasic || r.profile == ProfileId::VtkGpu) {
        // listed when not the defaults; an option set as a rule is the rule's (ProfileRuleTable.h)
        if (o.texture_unit == ProfileOptions::TextureUnit::H100 && !option_set_as_rule(rules, "texture_unit"))
            j["texture_unit"] = name_of(names::kTextureUnits, o.texture_unit);
        if (o.texture_band) j["texture_band"] = true;
        if (o.data_unorm16) j["texture_format"] = name_of(names::kTextureFormats, o.data_unorm16);
    }
    if (r.profile == ProfileId::CudaCurvilinear && o.kernel == ProfileOptions::Kernel::Double && !option_set_as_rule(rules, "kernel"))
        j["kernel"] = name_of(names::kKernels, o.kernel);
    if (r.profile == ProfileId::CudaCurvilinear && o.tricubic) j["tricubic"] = true;
    if (r.profile == ProfileId::Fast && o.preintegration > 0) j["preintegration"] = o.preintegration;
    if (o.framebuffer_band) j["framebuffer_band"] = true;  // volumizer, placement "slices"
    if (r.profile == ProfileId::VtkJs)
        j = {{"jitter", o.jitter},
             {"fixed_normal", o.fixed_normal},
             {"flip_normal", o.flip_normal},
             {"ray_box", name_of(names::kVtkJsRayBoxes, o.ray_box_domain)},
             {"mip_correction", o.mip_correction},
             {"subpixel_bits", o.subpixel_bits}};
    return j;
}

// render.profile_options of "volpack": every input, defaults included, as read_volpack_options reads them.
json volpack_json(const VolPackSpec& v) {
    static constexpr const char* kAxes[] = {"x", "y", "z"};
    auto table = [](const VolPackTable& t) {
        if (!t.ramp.empty()) {
            json r = json::array();
            for (const auto& [x, y] : t.ramp) r.push_back({x, double(y)});
            return json{{"ramp", r}};
        }
        json e = json::array();
        for (float f : t.entries) e.push_back(double(f));
        return e;
    };
    json j;
    j["rotate"] = json::array();
    for (const auto& [axis, degrees] : v.rotate) j["rotate"].push_back({kAxes[int(axis)], degrees});
    j["concat"] = v.concat_left ? "left" : "right";
    j["window"] = v.window;
    j["scalar_table"] = table(v.scalar_table);
    if (v.gradient_table) j["gradient_table"] = table(*v.gradient_table);
    if (v.shaded) {
        json sh;
        sh["material"] = {{"ambient", vec(v.ambient)}, {"diffuse", vec(v.diffuse)}, {"specular", vec(v.specular)},
                          {"shininess", v.shininess}};
        if (v.lights) {
            sh["lights"] = json::array();
            for (const VolPackLight& l : *v.lights) sh["lights"].push_back({{"direction", vec(l.direction)}, {"color", vec(l.color)}});
        }
        sh["two_sided"] = v.two_sided;
        j["shading"] = sh;
    }
    j["min_voxel_opacity"] = v.min_voxel_opacity;
    j["max_ray_opacity"] = v.max_ray_opacity;
    if (v.depth_cue) j["depth_cue"] = {{"front", (*v.depth_cue)[0]}, {"density", (*v.depth_cue)[1]}};
    j["channels"] = v.channels;
    j["path"] = v.path == VolPackSpec::Path::Raw ? "raw" : "classified";
    if (v.axis) j["axis"] = kAxes[int(*v.axis)];
    if (v.warp_weights == VolPackSpec::WarpWeights::Exact) j["warp_weights"] = "exact";
    if (v.normal_code == VolPackSpec::NormalCode::Exact) j["normal_code"] = "exact";
    if (v.correction_order == VolPackSpec::CorrectionOrder::Sample) j["correction_order"] = "sample";
    return j;
}

json render_json(const RenderSpec& r) {
    if (r.profile == ProfileId::VolPack && r.profile_options.volpack)  // VolPack's inputs only
        return json{{"profile", "volpack"}, {"profile_options", volpack_json(*r.profile_options.volpack)}};
    json j;
    j["projection"] = name_of(names::kProjections, r.projection);
    j["order"] = name_of(names::kOrders, r.order);
    j["step"] = r.step;
    j["step_units"] = name_of(names::kStepUnits, r.step_units);
    if (r.isovalue) j["isovalue"] = *r.isovalue;
    if (r.early_termination) j["early_termination"] = *r.early_termination;
    j["gain"] = r.gain;
    j["integrator"] = name_of(names::kIntegrators, r.integrator);
    j["tolerance"] = r.tolerance;
    j["profile"] = name_of(names::kProfiles, r.profile);
    if (!r.profile_rules.empty()) {  // {"base": preset, the rules the scene sets}
        j["profile"] = json{{"base", name_of(names::kProfiles, r.profile)}};
        const nlohmann::json rules = profile_rules_object(r.profile_rules);
        for (const auto& [key, value] : rules.items()) j["profile"][key] = value;
    }
    if (json o = profile_options_json(r); !o.is_null()) j["profile_options"] = std::move(o);
    return j;
}

}  // namespace

json scene_json(const Scene& scene) {
    json j;
    if (scene.render.profile == ProfileId::VolPack) {  // the volume's file and VolPack's inputs
        const VolumeSpec& v = scene.volumes.front();
        j["volume"] = {{"source", source_json(v.source)}};
        if (v.origin) j["volume"]["origin"] = vec(*v.origin);
        if (v.spacing) j["volume"]["spacing"] = vec(*v.spacing);
        j["image"] = {{"width", scene.image.width}, {"height", scene.image.height}};
        j["render"] = render_json(scene.render);
        return j;
    }
    if (scene.volumes.size() == 1) {
        j["volume"] = volume_json(scene.volumes.front());
    } else {
        j["volumes"] = json::array();
        for (const VolumeSpec& v : scene.volumes) j["volumes"].push_back(volume_json(v));
    }
    j["lights"] = json::array();
    for (const LightSpec& l : scene.lights) j["lights"].push_back(light_json(l));
    if (scene.camera.type != CameraSpec::Type::Default) j["camera"] = camera_json(scene.camera);  // placed from the bounds
    j["image"] = {{"width", scene.image.width}, {"height", scene.image.height}, {"background", vec(scene.image.background)}};
    j["render"] = render_json(scene.render);
    return j;
}

nlohmann::json profile_rules_object(const ProfileRules& r) {
    nlohmann::json j = nlohmann::json::object();
    for (const ProfileRule& rule : profile_rule_table()) rule.write(r, j);  // each rule that is set
    return j;
}

}  // namespace volref
