// The scene format written back (core/scene/SceneWriter.h) through the loader's own names
// (core/scene/SceneNames.h), and volumes held in memory (VolumeSourceSpec::memory).
//
// The writer is checked three ways: against the defaults docs/scene-format.md states (written by
// hand below), as a fixed point of read -> write -> read -> write over every reference scene and a
// scene using every key, and against the loader on each field it reads back. A volume in memory is
// checked against the same volume read or generated: the images are bit for bit the same.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/render/PreparedVolume.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneNames.h"
#include "core/scene/SceneWriter.h"

namespace volref {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

Scene parse(const std::string& text) { return parse_scene(text, "/scenes", "scene.json"); }
json written(const Scene& s) { return scene_json(s); }
Scene reread(const Scene& s) { return parse_scene(written(s).dump(), "/elsewhere", "written.json"); }

TEST(SceneWriter, WritesEveryDefaultOfAMinimalScene) {
    // docs/scene-format.md's defaults, by hand.
    const json j = written(parse(R"({"volume": {"source": "head.nrrd"}})"));
    const json& v = j.at("volume");
    EXPECT_EQ(v.at("source"), json({{"file", "/scenes/head.nrrd"}}));
    EXPECT_FALSE(v.contains("origin"));
    EXPECT_FALSE(v.contains("spacing"));
    EXPECT_EQ(v.at("interpolation"), "trilinear");
    EXPECT_EQ(v.at("classify"), "post");
    EXPECT_EQ(v.at("bounds"), json({{"type", "box"}}));
    EXPECT_EQ(v.at("transfer"), json({{"domain", "data"}, {"opacity_unit_distance", 1.0}}));
    EXPECT_EQ(v.at("gradient"), json({{"cache", false}}));
    EXPECT_EQ(j.at("lights"), json::parse(R"([{"type": "headlight", "color": [1.0, 1.0, 1.0]}])"));
    EXPECT_FALSE(j.contains("camera"));  // the default camera: placed from the bounds
    EXPECT_EQ(j.at("image"), json::parse(R"({"width": 256, "height": 256, "background": [0.0, 0.0, 0.0, 0.0]})"));
    EXPECT_EQ(j.at("render"), json::parse(R"({"projection": "composite", "order": "front-to-back", "step": 0.5,
        "step_units": "voxel", "gain": 1.0, "integrator": "fixed", "tolerance": 1e-06, "profile": "reference"})"));
}

// A scene that sets every key the loader reads (but a profile's options, tested below).
const char* const kEveryKey = R"({
  "volumes": [
    {"source": {"file": "data/head.raw", "format": "raw"}, "origin": [1, 2, 3], "spacing": [0.5, 0.25, 2],
     "interpolation": "tricubic-catmull-rom", "classify": "pre",
     "bounds": {"type": "box", "min": [0, 0, 0], "max": [10, 20, 30]},
     "transfer": {"domain": "normalized", "window": [-100, 300], "color": [[0, 0.1, 0.1, 0.9], [1, 1, 1, 1]],
                  "opacity": [[0, 0], [1, 0.4]], "gradient_opacity": [[0, 0], [5, 1]], "opacity_unit_distance": 2.5},
     "shading": {"model": "phong", "ka": 0.2, "kd": 0.6, "ks": 0.3, "n": 20, "kc": 1, "kl": 0.5, "two_sided": true},
     "gradient": {"scheme": "analytic", "cache": "auto"},
     "transform": {"scale": [2, 1, 1], "rotate": {"axis": [0, 0, 1], "degrees": 30}, "translate": [1, 0, 0]},
     "clip_planes": [{"point": [1, 2, 3], "normal": [0, 0, 1]}],
     "crop": {"planes": [0, 1, 0, 2, 0, 3], "regions": "fence"}},
    {"source": {"field": "gaussian", "dims": [9, 8, 7], "center": [1, 2, 3], "sigma": 2, "amplitude": 5},
     "bounds": {"type": "spherical", "center": [1, 1, 1], "radius": [1, 4], "longitude": [-40, 40],
                "latitude": [-10, 30], "axes": ["radius", "longitude", "latitude"], "tessellate": 12},
     "classification": {"type": "isovalue", "isovalues": [{"value": 3, "opacity": 0.5, "thickness": 2, "color": [1, 0, 0]}],
                        "opacity_unit_distance": 3}},
    {"source": {"field": "cells", "dims": [2, 2, 1], "values": [1, 2, 3, 4]},
     "bounds": {"type": "cylindrical", "center": [0, 0, 0], "radius": [1, 2], "angle": [0, 90], "height": [0, 3]},
     "classification": {"type": "boundary", "regions": [{"value": 1, "opacity": 0, "color": [0, 0, 0]},
                                                         {"value": 4, "opacity": 1, "color": [1, 1, 1]}]},
     "shading": {"model": "nodal", "ka": 0.3}},
    {"source": {"field": "marschner-lobb", "dims": [5, 5, 5], "fm": 4, "alpha": 0.5}, "bounds": {"type": "mesh", "file": "shape.obj"}},
    {"source": {"field": "linear", "dims": [3, 3, 3], "coefficients": [1, 2, 3, 4]}, "gradient": {"scheme": "forward", "cache": true}},
    {"source": {"field": "radial", "dims": [3, 3, 3], "center": [1, 1, 1]}},
    {"source": {"field": "constant", "dims": [2, 2, 2], "value": 7}}
  ],
  "lights": [{"type": "directional", "direction": [0, 0, -1], "color": [0.5, 0.5, 1]}, {"type": "headlight", "color": [1, 1, 1]}],
  "camera": {"type": "perspective", "eye": [0, 0, 50], "target": [1, 2, 3], "up": [0, 1, 0], "fov_y": 40},
  "image": {"width": 33, "height": 17, "background": [0.1, 0.2, 0.3, 1]},
  "render": {"projection": "first-hit", "order": "back-to-front", "step": 0.25, "step_units": "world", "isovalue": 3,
             "early_termination": 0.9, "integrator": "adaptive", "tolerance": 0.0001, "gain": 2,
             "profile": {"base": "vtk-gpu", "placement": "from-entry", "first": 0.5, "step_count": "before-exit",
                         "ray_box": {"min": [0, 0, 0], "max": [1, 1, 1]}, "step_voxel": "extent-over-samples",
                         "correction": "pow", "correction_floor": 0.01, "density_scale": 2, "compositing": "opacity-sum",
                         "termination": {"alpha_at_least": 0.95}, "table": 256, "table_coordinate": "data-range",
                         "texture_unit": "h100", "normal": "+gradient", "gradient": "forward", "gradient_offset": 0.5,
                         "clamp_shaded": true}}
})";

TEST(SceneWriter, EveryKeyIsAFixedPointAndReadsBackTheSame) {
    const Scene s = parse(kEveryKey);
    const json j = written(s);
    const Scene t = reread(s);
    EXPECT_EQ(written(t), j);
    // Field by field against the first read (the loader's own tests check that read against the text).
    ASSERT_EQ(t.volumes.size(), 7u);
    const VolumeSpec &a = s.volumes[0], &b = t.volumes[0];
    EXPECT_EQ(*b.source.file, *a.source.file);
    EXPECT_EQ(b.source.format, "raw");
    EXPECT_EQ(*b.origin, *a.origin);
    EXPECT_EQ(*b.spacing, *a.spacing);
    EXPECT_EQ(b.interpolation, Interpolation::TricubicCatmullRom);
    EXPECT_EQ(b.classify, VolumeSpec::Classify::Pre);
    EXPECT_EQ(b.transfer.domain, TransferSpec::Domain::Normalized);
    EXPECT_EQ(b.transfer.color, a.transfer.color);
    EXPECT_EQ(b.transfer.gradient_opacity, a.transfer.gradient_opacity);
    EXPECT_EQ(b.shading->model, ShadingSpec::Model::Phong);
    EXPECT_EQ(b.gradient.scheme, GradientSpec::Scheme::Analytic);
    EXPECT_TRUE(b.gradient.cache_auto);
    EXPECT_EQ(*b.transform, *a.transform);
    EXPECT_EQ(b.crop->regions, a.crop->regions);
    EXPECT_EQ(t.volumes[1].bounds.sphere.axes, (std::array<int, 3>{2, 0, 1}));
    EXPECT_EQ(t.volumes[1].bounds.tessellate, 12);
    EXPECT_EQ(t.volumes[1].source.field->kind, FieldSpec::Kind::Gaussian);
    EXPECT_EQ(t.volumes[2].classification->type, ClassificationSpec::Type::Boundary);
    EXPECT_EQ(t.volumes[2].shading->model, ShadingSpec::Model::Nodal);
    EXPECT_EQ(t.volumes[3].bounds.mesh, s.volumes[3].bounds.mesh);
    EXPECT_EQ(t.volumes[4].gradient.scheme, GradientSpec::Scheme::Forward);
    EXPECT_EQ(t.volumes[6].source.field->value, 7.0);
    EXPECT_EQ(t.camera.type, CameraSpec::Type::Perspective);
    EXPECT_EQ(t.camera.fov_y, 40.0);
    EXPECT_EQ(t.lights[0].type, LightSpec::Type::Directional);
    EXPECT_EQ(t.image.background, s.image.background);
    const RenderSpec &r = t.render, &q = s.render;
    EXPECT_EQ(r.projection, Projection::FirstHit);
    EXPECT_EQ(r.order, CompositeOrder::BackToFront);
    EXPECT_EQ(r.step_units, StepUnits::World);
    EXPECT_EQ(r.integrator, IntegrationMethod::Adaptive);
    EXPECT_EQ(r.profile, ProfileId::VtkGpu);
    EXPECT_EQ(r.profile_rules.placement, q.profile_rules.placement);
    EXPECT_EQ(r.profile_rules.box, q.profile_rules.box);
    EXPECT_EQ(r.profile_rules.termination, ProfileRules::Stop::AlphaAtLeast);
    EXPECT_EQ(r.profile_rules.termination_value, 0.95);
    EXPECT_EQ(r.profile_rules.texture_unit, ProfileOptions::TextureUnit::H100);
    EXPECT_EQ(r.profile_options.texture_unit, ProfileOptions::TextureUnit::H100);
    EXPECT_EQ(r.profile_rules.normal_along_gradient, std::optional<bool>(true));
    EXPECT_EQ(r.profile_rules.clamp_shaded, std::optional<bool>(true));
}

TEST(SceneWriter, OtherCamerasAndEveryProfilesOptionsAreFixedPoints) {
    const char* const variants[] = {
        R"("camera": {"type": "orthographic", "eye": [0, 0, 5], "target": [0, 0, 0], "up": [1, 0, 0], "height": 3})",
        R"("camera": {"type": "matrices", "view": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,-5,1], "projection": [1,0,0,0, 0,2,0,0, 0,0,-1,-1, 0,0,-0.2,0]})",
        R"("render": {"profile": "cuda-curvilinear", "profile_options": {"density": 2, "transfer_scale": 3, "iso_threshold": 0.1,
            "brightness": 4, "texture_unit": "h100", "texture_band": true, "texture_format": "unorm16", "kernel": "double", "tricubic": true}})",
        R"("render": {"profile": "glsl-basic", "profile_options": {"intensity": 2}})",
        R"("render": {"profile": "vtk-js", "profile_options": {"jitter": 0.5, "fixed_normal": true, "flip_normal": true,
            "ray_box": "domain", "mip_correction": false, "subpixel_bits": 8}})",
        R"("render": {"profile": {"base": "cuda-curvilinear", "arithmetic": "double", "compositing": "lerp", "correction": "extinction",
            "termination": "none", "placement": "from-exit", "step_count": "through-exit", "ray_box": "texel",
            "table_coordinate": "data-range-times-transfer-scale", "gradient": "central-in-domain", "gradient_offset_texture": 0.25}})",
        R"("render": {"profile": "fast"})", R"("render": {"profile": "vtk-cpu", "integrator": "midpoint"})"};
    for (const char* v : variants) {
        const Scene s = parse(std::string(R"({"volume": {"source": "v.nrrd"}, )") + v + "}");
        const Scene t = reread(s);
        EXPECT_EQ(written(t), written(s)) << v;
        EXPECT_EQ(t.camera.type, s.camera.type) << v;
        EXPECT_EQ(t.camera.view, s.camera.view) << v;
        EXPECT_EQ(t.camera.projection, s.camera.projection) << v;
        EXPECT_EQ(t.render.profile, s.render.profile) << v;
        EXPECT_EQ(t.render.profile_options.kernel, s.render.profile_options.kernel) << v;
        EXPECT_EQ(t.render.profile_options.data_unorm16, s.render.profile_options.data_unorm16) << v;
        EXPECT_EQ(t.render.profile_options.subpixel_bits, s.render.profile_options.subpixel_bits) << v;
        EXPECT_EQ(t.render.profile_options.ray_box_domain, s.render.profile_options.ray_box_domain) << v;
        EXPECT_EQ(t.render.profile_rules.compositing, s.render.profile_rules.compositing) << v;
        EXPECT_EQ(t.render.profile_rules.arithmetic, s.render.profile_rules.arithmetic) << v;
    }
    // "midpoint" is read as fixed and written by its name, "fixed".
    EXPECT_EQ(written(parse(R"({"volume": {"source": "v.nrrd"}, "render": {"integrator": "midpoint"}})"))["render"]["integrator"], "fixed");
}

TEST(SceneWriter, EveryReferenceSceneIsAFixedPoint) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(fs::path(VOLREF_SOURCE_DIR) / "reference_scenes")) {
        if (e.path().extension() != ".json") continue;
        const Scene s = load_scene(e.path());
        const Scene t = reread(s);
        EXPECT_EQ(written(t), written(s)) << e.path();
        EXPECT_EQ(t.volumes.size(), s.volumes.size()) << e.path();
        ++n;
    }
    EXPECT_GE(n, 15);
}

TEST(SceneNames, CanonicalNamesAliasesAndListings) {
    using namespace scene_names;
    EXPECT_STREQ(name_of(kIntegrators, IntegrationMethod::Fixed), "fixed");  // not the alias "midpoint"
    EXPECT_STREQ(name_of(kTextureUnits, ProfileOptions::TextureUnit::H100), "h100");  // not "hardware"
    EXPECT_EQ(value_of(kIntegrators, "midpoint"), IntegrationMethod::Fixed);
    EXPECT_EQ(value_of(kProjections, "first-hit"), Projection::FirstHit);
    EXPECT_FALSE(value_of(kProjections, "Composite").has_value());
    EXPECT_EQ(listing(kOrders), "front-to-back or back-to-front");
    EXPECT_EQ(listing(kShadingModels), "blinn-phong, phong or nodal");
    EXPECT_THROW(name_of(kTextureUnits, ProfileOptions::TextureUnit::Admissible), Error);  // tests only: no name
}

// ---- volumes in memory ---------------------------------------------------------------------------

Image render_small(const Scene& s) {
    RenderOptions o;
    o.threads = 2;
    return render_scene(s, o);
}

// `s` with every volume replaced by the volume a render prepares for it, held in memory.
Scene in_memory(const Scene& s) {
    Scene m = s;
    for (std::size_t k = 0; k < s.volumes.size(); ++k) {
        VolumeModel model;
        build_volume_model(s.volumes[k], model);
        VolumeSpec& vs = m.volumes[k];
        vs.source.memory = model.data;
        vs.source.field.reset();
        vs.source.file = "in-memory-" + std::to_string(k);
        // Not applied again: the volume in memory is complete (its own origin and spacing).
        if (vs.origin) vs.origin = *vs.origin + glm::dvec3(100.0);
        if (vs.spacing) vs.spacing = *vs.spacing * 3.0;
    }
    return m;
}

TEST(VolumeInMemory, RendersAsTheVolumeItHolds) {
    // Cartesian with origin and spacing (nrrd-gaussian reads a file), shells, several volumes.
    for (const char* name : {"nrrd-gaussian.json", "ultrasound-sector.json", "radar-sweep.json", "two-volumes-clipped.json"}) {
        const Scene s = load_scene(fs::path(VOLREF_SOURCE_DIR) / "reference_scenes" / name, {"image.width=24", "image.height=20"});
        const Image a = render_small(s), b = render_small(in_memory(s));
        ASSERT_EQ(a.pixels.size(), b.pixels.size()) << name;
        EXPECT_EQ(a.pixels, b.pixels) << name;
        double sum = 0.0;
        for (double x : a.pixels) sum += x;
        EXPECT_GT(sum, 0.0) << name;  // something drawn
    }
}

TEST(VolumeInMemory, IsSharedNotCopied) {
    const Scene s = in_memory(load_scene(fs::path(VOLREF_SOURCE_DIR) / "reference_scenes" / "default.json"));
    VolumeModel model;
    build_volume_model(s.volume(), model);
    EXPECT_EQ(model.data.get(), s.volume().source.memory.get());
    EXPECT_EQ(share_volume(s.volume()).get(), s.volume().source.memory.get());
}

}  // namespace
}  // namespace volref
