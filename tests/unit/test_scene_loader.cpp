// Scene loading (core/scene/SceneLoader.h, docs/scene-format.md): defaults, a full scene, every class of
// error (each naming the file and the JSON path), --set overrides, and files on disk.
#include <gtest/gtest.h>

#include "ErrorOf.h"
#include "TempDir.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/Error.h"
#include "core/scene/SceneLoader.h"

namespace volref {
namespace {

namespace fs = std::filesystem;

const fs::path kBase = "/scenes/base";

Scene parse(const std::string& json, const std::vector<std::string>& overrides = {}) {
    return parse_scene(json, kBase, "scene.json", overrides);
}

// {"volume": {"source": "v.nrrd"<, volume_keys>}<, top_keys>}
std::string scene_with(const std::string& top_keys, const std::string& volume_keys = "") {
    std::string s = R"({"volume": {"source": "v.nrrd")";
    if (!volume_keys.empty()) s += ", " + volume_keys;
    s += "}";
    if (!top_keys.empty()) s += ", " + top_keys;
    return s + "}";
}
std::string volume_with(const std::string& volume_keys) { return scene_with("", volume_keys); }
std::string transfer_with(const std::string& transfer_keys) {
    return volume_with(R"("transfer": {)" + transfer_keys + "}");
}
std::string source_with(const std::string& source) {
    return R"({"volume": {"source": )" + source + "}}";
}

using test::error_of;

// Success when parsing `json` throws an Error whose one-line message starts with
// "scene.json: <path>: " and contains `phrase`.
testing::AssertionResult fails_with(const std::string& json, const std::string& path, const std::string& phrase,
                                    const std::vector<std::string>& overrides = {}) {
    const std::string m = error_of([&] { parse(json, overrides); });
    const std::string prefix = "scene.json: " + path + ": ";
    if (m.rfind(prefix, 0) != 0) return testing::AssertionFailure() << "message \"" << m << "\" does not start with \"" << prefix << "\"";
    if (m.find(phrase) == std::string::npos)
        return testing::AssertionFailure() << "message \"" << m << "\" does not contain \"" << phrase << "\"";
    if (m.find('\n') != std::string::npos) return testing::AssertionFailure() << "message has several lines: " << m;
    return testing::AssertionSuccess();
}

// The message of parsing `json` with `overrides` (which must fail).
std::string message_of(const std::string& json, const std::vector<std::string>& overrides = {}) {
    return error_of([&] { parse(json, overrides); });
}

void expect_vec(const glm::dvec3& v, double x, double y, double z) {
    EXPECT_DOUBLE_EQ(v.x, x);
    EXPECT_DOUBLE_EQ(v.y, y);
    EXPECT_DOUBLE_EQ(v.z, z);
}

struct TempDir : test::TempDir {
    TempDir() : test::TempDir("scene_test") {}
};

// ------------------------------------------------------------------------------------------------
// Defaults and a full scene
// ------------------------------------------------------------------------------------------------

TEST(SceneLoaderDefaults, MinimalSceneFillsEveryDefault) {
    const Scene s = parse(R"({"volume": {"source": "head.nrrd"}})");
    EXPECT_EQ(s.file, fs::path("scene.json"));

    // volume
    ASSERT_TRUE(s.volume().source.file.has_value());
    EXPECT_EQ(*s.volume().source.file, kBase / "head.nrrd");
    EXPECT_EQ(s.volume().source.format, "");
    EXPECT_FALSE(s.volume().source.field.has_value());
    EXPECT_FALSE(s.volume().origin.has_value());
    EXPECT_FALSE(s.volume().spacing.has_value());
    EXPECT_EQ(s.volume().interpolation, Interpolation::Trilinear);
    EXPECT_EQ(s.volume().bounds.type, BoundsSpec::Type::Box);
    EXPECT_FALSE(s.volume().bounds.min.has_value());
    EXPECT_FALSE(s.volume().bounds.max.has_value());
    EXPECT_EQ(s.volume().transfer.domain, TransferSpec::Domain::Data);
    EXPECT_FALSE(s.volume().transfer.window.has_value());
    EXPECT_TRUE(s.volume().transfer.color.empty());
    EXPECT_TRUE(s.volume().transfer.opacity.empty());
    EXPECT_EQ(s.volume().transfer.opacity_unit_distance, 1.0);
    EXPECT_TRUE(s.volume().transfer.gradient_opacity.empty());
    EXPECT_FALSE(s.volume().classification.has_value());
    EXPECT_EQ(s.volume().classify, VolumeSpec::Classify::Post);
    EXPECT_FALSE(s.volume().shading.has_value());  // unshaded
    EXPECT_EQ(s.volume().gradient.scheme, GradientSpec::Scheme::Default);
    EXPECT_FALSE(s.volume().gradient.cache);

    // lights: one white headlight
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightSpec::Type::Headlight);
    expect_vec(s.lights[0].color, 1, 1, 1);

    // camera
    EXPECT_EQ(s.camera.type, CameraSpec::Type::Default);
    expect_vec(s.camera.eye, 0, 0, 1);
    expect_vec(s.camera.target, 0, 0, 0);
    expect_vec(s.camera.up, 0, 1, 0);
    EXPECT_EQ(s.camera.fov_y, 30.0);
    EXPECT_EQ(s.camera.height, 1.0);

    // image
    EXPECT_EQ(s.image.width, 256);
    EXPECT_EQ(s.image.height, 256);
    EXPECT_EQ(s.image.background, glm::dvec4(0.0, 0.0, 0.0, 0.0));

    // render
    EXPECT_EQ(s.render.projection, Projection::Composite);
    EXPECT_EQ(s.render.order, CompositeOrder::FrontToBack);
    EXPECT_EQ(s.render.step, 0.5);
    EXPECT_EQ(s.render.step_units, StepUnits::Voxel);
    EXPECT_FALSE(s.render.isovalue.has_value());
    EXPECT_FALSE(s.render.early_termination.has_value());
    EXPECT_EQ(s.render.gain, 1.0);
}

TEST(SceneLoaderDefaults, EmptyObjectsKeepDefaults) {
    const Scene s = parse(scene_with(R"("image": {}, "render": {})", R"("transfer": {}, "bounds": {})"));
    EXPECT_EQ(s.image.width, 256);
    EXPECT_EQ(s.render.step, 0.5);
    EXPECT_EQ(s.volume().transfer.domain, TransferSpec::Domain::Data);
    EXPECT_TRUE(s.volume().transfer.color.empty());
    EXPECT_TRUE(s.volume().transfer.opacity.empty());
    EXPECT_EQ(s.volume().transfer.opacity_unit_distance, 1.0);
}

TEST(SceneLoaderDefaults, TransferWithoutColorOrOpacityLeavesThemEmpty) {
    const Scene a = parse(transfer_with(R"("opacity": [[0, 0], [1, 1]])"));
    EXPECT_TRUE(a.volume().transfer.color.empty());
    EXPECT_EQ(a.volume().transfer.opacity.size(), 2u);
    const Scene b = parse(transfer_with(R"("color": [[0, 1, 1, 1]])"));
    EXPECT_TRUE(b.volume().transfer.opacity.empty());
    EXPECT_EQ(b.volume().transfer.color.size(), 1u);
}

TEST(SceneLoaderFull, EveryKeyIsRead) {
    const Scene s = parse(R"({
      "description": "every key",
      "volume": {
        "source": {"file": "data/head.raw", "format": "raw"},
        "origin": [1, 2, 3],
        "spacing": [0.5, 0.25, 2],
        "interpolation": "nearest",
        "classify": "post",
        "bounds": {"type": "box", "min": [0, 0, 0], "max": [10, 20, 30]},
        "transfer": {
          "domain": "normalized",
          "window": [-100, 300],
          "color": [[0, 0.1, 0.1, 0.9], [0.5, 2, 0, 0], [0.5, 1, 1, 1]],
          "opacity": [[0, 0], [0.3, 0], [1, 0.4]],
          "opacity_unit_distance": 2.5
        }
      },
      "lights": [
        {"type": "headlight", "color": [0.5, 0.5, 0.5]},
        {"type": "directional", "direction": [0, 3, 4], "color": [1, 0.9, 0.8]}
      ],
      "camera": {"type": "perspective", "eye": [0, -400, 0], "target": [1, 2, 3], "up": [0, 0, 1], "fov_y": 45},
      "image": {"width": 640, "height": 480, "background": [0.1, 0.2, 0.3, 1]},
      "render": {"projection": "first-hit", "order": "back-to-front", "step": 0.25, "step_units": "world",
                 "isovalue": 42.5, "early_termination": 0.99, "integrator": "midpoint", "profile": "reference",
                 "gain": 3}
    })");
    const VolumeSpec& v = s.volume();
    EXPECT_EQ(*v.source.file, kBase / "data" / "head.raw");
    EXPECT_EQ(v.source.format, "raw");
    EXPECT_FALSE(v.source.field.has_value());
    expect_vec(*v.origin, 1, 2, 3);
    expect_vec(*v.spacing, 0.5, 0.25, 2);
    EXPECT_EQ(v.interpolation, Interpolation::Nearest);
    expect_vec(*v.bounds.min, 0, 0, 0);
    expect_vec(*v.bounds.max, 10, 20, 30);
    EXPECT_EQ(v.transfer.domain, TransferSpec::Domain::Normalized);
    ASSERT_TRUE(v.transfer.window.has_value());
    EXPECT_EQ((*v.transfer.window)[0], -100.0);
    EXPECT_EQ((*v.transfer.window)[1], 300.0);
    ASSERT_EQ(v.transfer.color.size(), 3u);
    EXPECT_EQ(v.transfer.color[0], (std::array<double, 4>{0, 0.1, 0.1, 0.9}));
    EXPECT_EQ(v.transfer.color[1], (std::array<double, 4>{0.5, 2, 0, 0}));  // equal values are allowed
    EXPECT_EQ(v.transfer.color[2], (std::array<double, 4>{0.5, 1, 1, 1}));
    ASSERT_EQ(v.transfer.opacity.size(), 3u);
    EXPECT_EQ(v.transfer.opacity[2], (std::array<double, 2>{1, 0.4}));
    EXPECT_EQ(v.transfer.opacity_unit_distance, 2.5);

    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].type, LightSpec::Type::Headlight);
    expect_vec(s.lights[0].color, 0.5, 0.5, 0.5);
    EXPECT_EQ(s.lights[1].type, LightSpec::Type::Directional);
    expect_vec(s.lights[1].direction, 0, 0.6, 0.8);  // normalised
    expect_vec(s.lights[1].color, 1, 0.9, 0.8);

    EXPECT_EQ(s.camera.type, CameraSpec::Type::Perspective);
    expect_vec(s.camera.eye, 0, -400, 0);
    expect_vec(s.camera.target, 1, 2, 3);
    expect_vec(s.camera.up, 0, 0, 1);
    EXPECT_EQ(s.camera.fov_y, 45.0);

    EXPECT_EQ(s.image.width, 640);
    EXPECT_EQ(s.image.height, 480);
    EXPECT_EQ(s.image.background, glm::dvec4(0.1, 0.2, 0.3, 1.0));

    EXPECT_EQ(s.render.projection, Projection::FirstHit);
    EXPECT_EQ(s.render.order, CompositeOrder::BackToFront);
    EXPECT_EQ(s.render.step, 0.25);
    EXPECT_EQ(s.render.step_units, StepUnits::World);
    EXPECT_EQ(*s.render.isovalue, 42.5);
    EXPECT_EQ(*s.render.early_termination, 0.99);
    EXPECT_EQ(s.render.gain, 3.0);
}

TEST(SceneLoaderFull, OrthographicCamera) {
    const Scene s = parse(scene_with(R"("camera": {"type": "orthographic", "eye": [0, 0, 5], "height": 12})"));
    EXPECT_EQ(s.camera.type, CameraSpec::Type::Orthographic);
    expect_vec(s.camera.eye, 0, 0, 5);
    expect_vec(s.camera.target, 0, 0, 0);  // default
    expect_vec(s.camera.up, 0, 1, 0);      // default
    EXPECT_EQ(s.camera.height, 12.0);
}

TEST(SceneLoaderFull, PerspectiveCameraDefaults) {
    const Scene s = parse(scene_with(R"("camera": {"type": "perspective"})"));
    EXPECT_EQ(s.camera.type, CameraSpec::Type::Perspective);
    expect_vec(s.camera.eye, 0, 0, 1);
    expect_vec(s.camera.target, 0, 0, 0);
    expect_vec(s.camera.up, 0, 1, 0);
    EXPECT_EQ(s.camera.fov_y, 30.0);
}

TEST(SceneLoaderFull, MatricesAreColumnMajor) {
    // A translation by (1, 2, 3): OpenGL stores it in elements 12, 13, 14.
    const Scene s = parse(scene_with(R"("camera": {"type": "matrices",
        "view": [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,2,3,1],
        "projection": [2,0,0,0, 0,3,0,0, 0,0,-1,-1, 0,0,-0.2,0]})"));
    EXPECT_EQ(s.camera.type, CameraSpec::Type::Matrices);
    EXPECT_EQ(s.camera.view[3][0], 1.0);  // m[col][row]
    EXPECT_EQ(s.camera.view[3][1], 2.0);
    EXPECT_EQ(s.camera.view[3][2], 3.0);
    EXPECT_EQ(s.camera.view[0][3], 0.0);
    EXPECT_EQ(s.camera.projection[0][0], 2.0);
    EXPECT_EQ(s.camera.projection[2][3], -1.0);
    EXPECT_EQ(s.camera.projection[3][2], -0.2);
}

TEST(SceneLoaderFull, ProceduralFields) {
    {
        const Scene s = parse(source_with(R"({"field": "constant", "dims": [3, 4, 5], "value": 7})"));
        ASSERT_TRUE(s.volume().source.field.has_value());
        EXPECT_FALSE(s.volume().source.file.has_value());
        EXPECT_EQ(s.volume().source.field->kind, FieldSpec::Kind::Constant);
        EXPECT_EQ(s.volume().source.field->dims, (std::array<std::int64_t, 3>{3, 4, 5}));
        EXPECT_EQ(s.volume().source.field->value, 7.0);
    }
    {
        const Scene s = parse(source_with(R"({"field": "constant"})"));
        EXPECT_EQ(s.volume().source.field->dims, (std::array<std::int64_t, 3>{2, 2, 2}));  // default dims
        EXPECT_EQ(s.volume().source.field->value, 0.0);
    }
    {
        const Scene s = parse(source_with(R"({"field": "linear", "dims": [2, 2, 2], "coefficients": [1, 2, 3, 4]})"));
        EXPECT_EQ(s.volume().source.field->kind, FieldSpec::Kind::Linear);
        EXPECT_EQ(s.volume().source.field->coefficients, (std::array<double, 4>{1, 2, 3, 4}));
        const Scene d = parse(source_with(R"({"field": "linear"})"));
        EXPECT_EQ(d.volume().source.field->coefficients, (std::array<double, 4>{0, 0, 0, 0}));
    }
    {
        const Scene s = parse(source_with(R"({"field": "radial", "dims": [9, 9, 9], "center": [1, 2, 3]})"));
        EXPECT_EQ(s.volume().source.field->kind, FieldSpec::Kind::Radial);
        expect_vec(s.volume().source.field->center, 1, 2, 3);
        const Scene d = parse(source_with(R"({"field": "radial"})"));
        expect_vec(d.volume().source.field->center, 0, 0, 0);
    }
    {
        const Scene s = parse(source_with(R"({"field": "marschner-lobb", "dims": [41, 41, 41]})"));
        EXPECT_EQ(s.volume().source.field->kind, FieldSpec::Kind::MarschnerLobb);
        EXPECT_EQ(s.volume().source.field->fm, 6.0);
        EXPECT_EQ(s.volume().source.field->alpha, 0.25);
        const Scene t = parse(source_with(R"({"field": "marschner-lobb", "fm": 3, "alpha": 0.5})"));
        EXPECT_EQ(t.volume().source.field->fm, 3.0);
        EXPECT_EQ(t.volume().source.field->alpha, 0.5);
    }
    {
        const Scene s = parse(source_with(R"({"field": "gaussian"})"));
        EXPECT_EQ(s.volume().source.field->kind, FieldSpec::Kind::Gaussian);
        expect_vec(s.volume().source.field->center, 0, 0, 0);
        EXPECT_EQ(s.volume().source.field->sigma, 1.0);
        EXPECT_EQ(s.volume().source.field->amplitude, 1.0);
        const Scene t =
            parse(source_with(R"({"field": "gaussian", "center": [1, 1, 1], "sigma": 0.5, "amplitude": -2})"));
        expect_vec(t.volume().source.field->center, 1, 1, 1);
        EXPECT_EQ(t.volume().source.field->sigma, 0.5);
        EXPECT_EQ(t.volume().source.field->amplitude, -2.0);
    }
    {
        const Scene s = parse(source_with(R"({"field": "cells", "dims": [2, 1, 2], "values": [1, 2, 3, 4.5]})"));
        EXPECT_EQ(s.volume().source.field->kind, FieldSpec::Kind::Cells);
        EXPECT_EQ(s.volume().source.field->values, (std::vector<double>{1, 2, 3, 4.5}));
    }
}

TEST(SceneLoaderFull, IntegralFloatsAreIntegers) {
    const Scene s = parse(scene_with(R"("image": {"width": 512.0, "height": 3e2})"));
    EXPECT_EQ(s.image.width, 512);
    EXPECT_EQ(s.image.height, 300);
    const Scene f = parse(source_with(R"({"field": "constant", "dims": [2.0, 1, 1e1]})"));
    EXPECT_EQ(f.volume().source.field->dims, (std::array<std::int64_t, 3>{2, 1, 10}));
}

TEST(SceneLoaderFull, DimsAtTheLimitAreAccepted) {
    const Scene s = parse(source_with(R"({"field": "constant", "dims": [2048, 1024, 1024]})"));  // 2^31
    EXPECT_EQ(s.volume().source.field->dims, (std::array<std::int64_t, 3>{2048, 1024, 1024}));
}

TEST(SceneLoaderFull, SingleElementVolumesIsTheSameAsVolume) {
    const Scene s = parse(R"({"volumes": [{"source": "a.nrrd", "interpolation": "nearest"}]})");
    EXPECT_EQ(*s.volume().source.file, kBase / "a.nrrd");
    EXPECT_EQ(s.volume().interpolation, Interpolation::Nearest);
}

TEST(SceneLoaderFull, EnumValues) {
    const std::pair<const char*, Projection> projections[] = {
        {"composite", Projection::Composite}, {"mip", Projection::Mip},     {"minip", Projection::Minip},
        {"average", Projection::Average},     {"xray", Projection::Xray}};
    for (const auto& [name, value] : projections)
        EXPECT_EQ(parse(scene_with(std::string(R"("render": {"projection": ")") + name + "\"}")).render.projection, value)
            << name;
    EXPECT_EQ(parse(volume_with(R"("interpolation": "trilinear")")).volume().interpolation, Interpolation::Trilinear);
    EXPECT_EQ(parse(volume_with(R"("interpolation": "tricubic-bspline")")).volume().interpolation,
              Interpolation::TricubicBSpline);
    EXPECT_EQ(parse(volume_with(R"("interpolation": "tricubic-catmull-rom")")).volume().interpolation,
              Interpolation::TricubicCatmullRom);
    EXPECT_EQ(parse(volume_with(R"("classify": "post")")).volume().classify, VolumeSpec::Classify::Post);
    EXPECT_EQ(parse(volume_with(R"("classify": "pre")")).volume().classify, VolumeSpec::Classify::Pre);
    EXPECT_EQ(parse(scene_with(R"("render": {"step_units": "voxel"})")).render.step_units, StepUnits::Voxel);
    EXPECT_EQ(parse(scene_with(R"("render": {"order": "front-to-back"})")).render.order, CompositeOrder::FrontToBack);
    EXPECT_EQ(parse(transfer_with(R"("domain": "data")")).volume().transfer.domain, TransferSpec::Domain::Data);
}

TEST(SceneLoaderFull, LightsAndBounds) {
    EXPECT_TRUE(parse(scene_with(R"("lights": [])")).lights.empty());  // [] means no lights
    // the smallest magnitude a number may have (issue 32: 0 or [1e-100, 1e100]) normalises exactly
    const Scene s = parse(scene_with(R"("lights": [{}, {"type": "directional", "direction": [1e-100, 0, 0]}])"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{}, {"type": "directional", "direction": [1e-300, 0, 0]}])"),
                           "lights[1].direction[0]", "the number 1e-300 is beyond volref's range"));
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].type, LightSpec::Type::Headlight);  // type defaults to headlight
    expect_vec(s.lights[1].direction, 1, 0, 0);
    const Scene b = parse(volume_with(R"("bounds": {"min": [1, 1, 1]})"));  // min alone is allowed
    expect_vec(*b.volume().bounds.min, 1, 1, 1);
    EXPECT_FALSE(b.volume().bounds.max.has_value());
}

TEST(SceneLoaderFull, RangeEndsThatAreIncluded) {
    const Scene s = parse(scene_with(R"("render": {"early_termination": 1}, "image": {"width": 32768, "height": 8192,
                                         "background": [0, 1, 0, 1]})",
                                     R"("transfer": {"opacity": [[0, 0], [1, 1]], "color": [[0, 0, 0, 0]]})"));
    EXPECT_EQ(*s.render.early_termination, 1.0);
    EXPECT_EQ(s.image.width, 32768);
    EXPECT_EQ(s.image.height, 8192);  // exactly 2^28 pixels
}

TEST(SceneLoaderFull, DescriptionIsIgnored) {
    EXPECT_NO_THROW(parse(scene_with(R"("description": "a note for humans")")));
    EXPECT_TRUE(fails_with(scene_with(R"("description": 3)"), "description", "expected a string, got 3"));
}

// ------------------------------------------------------------------------------------------------
// Gradient opacity, classification, shading, gradients
// ------------------------------------------------------------------------------------------------

std::string classification_with(const std::string& keys) { return volume_with(R"("classification": {)" + keys + "}"); }
std::string shading_with(const std::string& keys) { return volume_with(R"("shading": {)" + keys + "}"); }

void expect_shading(const ShadingSpec& s, ShadingSpec::Model model, double ka, double kd, double ks, double n,
                    double kc, double kl, bool two_sided) {
    EXPECT_EQ(s.model, model);
    EXPECT_EQ(s.ka, ka);
    EXPECT_EQ(s.kd, kd);
    EXPECT_EQ(s.ks, ks);
    EXPECT_EQ(s.n, n);
    EXPECT_EQ(s.kc, kc);
    EXPECT_EQ(s.kl, kl);
    EXPECT_EQ(s.two_sided, two_sided);
}

TEST(SceneLoaderGradientOpacity, RowsAreRead) {
    // A factor may exceed 1; equal |grad f| make a step.
    const Scene s = parse(transfer_with(R"("gradient_opacity": [[0, 0], [10, 0.5], [10, 2], [100, 3]])"));
    const auto& g = s.volume().transfer.gradient_opacity;
    ASSERT_EQ(g.size(), 4u);
    EXPECT_EQ(g[0], (std::array<double, 2>{0, 0}));
    EXPECT_EQ(g[1], (std::array<double, 2>{10, 0.5}));
    EXPECT_EQ(g[2], (std::array<double, 2>{10, 2}));
    EXPECT_EQ(g[3], (std::array<double, 2>{100, 3}));
    EXPECT_EQ(parse(transfer_with(R"("gradient_opacity": [[5, 1]])")).volume().transfer.gradient_opacity.size(), 1u);
    // Absent: none.
    EXPECT_TRUE(parse(transfer_with(R"("opacity": [[0, 1]])")).volume().transfer.gradient_opacity.empty());
}

TEST(SceneLoaderGradientOpacity, Errors) {
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": [])"), "volume.transfer.gradient_opacity",
                           "expected at least one row [|grad f|, factor]"));
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": [[0, 1], [-1, 1]])"),
                           "volume.transfer.gradient_opacity[1][0]", "expected a number >= 0, got -1"));
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": [[0, -0.5]])"), "volume.transfer.gradient_opacity[0][1]",
                           "expected a number >= 0, got -0.5"));
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": [[0, 1], [20, 1], [10, 1]])"),
                           "volume.transfer.gradient_opacity[2]", "sorted by |grad f| (non-decreasing): 10 follows 20"));
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": [[0, 1, 1]])"), "volume.transfer.gradient_opacity[0]",
                           "expected a row [|grad f|, factor] of 2 numbers"));
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": {})"), "volume.transfer.gradient_opacity",
                           "expected an array"));
    EXPECT_TRUE(fails_with(transfer_with(R"("gradient_opacity": [[0, "1"]])"), "volume.transfer.gradient_opacity[0][1]",
                           "expected a number >= 0"));
}

TEST(SceneLoaderClassification, IsovalueDefaults) {
    const Scene s = parse(classification_with(R"("type": "isovalue", "isovalues": [{"value": 5}])"));
    ASSERT_TRUE(s.volume().classification.has_value());
    const ClassificationSpec& c = *s.volume().classification;
    EXPECT_EQ(c.type, ClassificationSpec::Type::Isovalue);
    ASSERT_EQ(c.isovalues.size(), 1u);
    EXPECT_EQ(c.isovalues[0].value, 5.0);
    EXPECT_EQ(c.isovalues[0].opacity, 1.0);
    EXPECT_EQ(c.isovalues[0].thickness, 1.0);
    expect_vec(c.isovalues[0].color, 1, 1, 1);
    EXPECT_TRUE(c.regions.empty());
    EXPECT_EQ(c.opacity_unit_distance, 1.0);
    // The transfer function keeps its defaults (it is not used).
    EXPECT_TRUE(s.volume().transfer.color.empty());
    EXPECT_TRUE(s.volume().transfer.opacity.empty());
}

TEST(SceneLoaderClassification, IsovalueFull) {
    const Scene s = parse(volume_with(R"("interpolation": "tricubic-bspline", "classify": "pre",
        "classification": {"type": "isovalue", "opacity_unit_distance": 2.5, "isovalues": [
            {"value": 0.5, "opacity": 0.8, "thickness": 0.25, "color": [1, 0.5, 0]},
            {"value": -3, "opacity": 0, "thickness": 4, "color": [0, 0, 2]}]})"));
    EXPECT_EQ(s.volume().interpolation, Interpolation::TricubicBSpline);
    EXPECT_EQ(s.volume().classify, VolumeSpec::Classify::Pre);
    const ClassificationSpec& c = *s.volume().classification;
    EXPECT_EQ(c.type, ClassificationSpec::Type::Isovalue);
    EXPECT_EQ(c.opacity_unit_distance, 2.5);
    ASSERT_EQ(c.isovalues.size(), 2u);  // in the given order (they need not be sorted)
    EXPECT_EQ(c.isovalues[0].value, 0.5);
    EXPECT_EQ(c.isovalues[0].opacity, 0.8);
    EXPECT_EQ(c.isovalues[0].thickness, 0.25);
    expect_vec(c.isovalues[0].color, 1, 0.5, 0);
    EXPECT_EQ(c.isovalues[1].value, -3.0);
    EXPECT_EQ(c.isovalues[1].opacity, 0.0);
    EXPECT_EQ(c.isovalues[1].thickness, 4.0);
    expect_vec(c.isovalues[1].color, 0, 0, 2);
}

TEST(SceneLoaderClassification, BoundaryDefaults) {
    const Scene s = parse(classification_with(R"("type": "boundary", "regions": [{"value": 0}, {"value": 1}])"));
    const ClassificationSpec& c = *s.volume().classification;
    EXPECT_EQ(c.type, ClassificationSpec::Type::Boundary);
    ASSERT_EQ(c.regions.size(), 2u);
    EXPECT_EQ(c.regions[0].value, 0.0);
    EXPECT_EQ(c.regions[1].value, 1.0);
    for (const BoundaryRegion& r : c.regions) {
        EXPECT_EQ(r.opacity, 1.0);
        expect_vec(r.color, 1, 1, 1);
    }
    EXPECT_TRUE(c.isovalues.empty());
    EXPECT_EQ(c.opacity_unit_distance, 1.0);
}

TEST(SceneLoaderClassification, BoundaryFull) {
    const Scene s = parse(classification_with(R"("type": "boundary", "opacity_unit_distance": 0.5, "regions": [
        {"value": -10, "opacity": 0, "color": [0, 0, 0]},
        {"value": 20, "opacity": 0.2, "color": [0.9, 0.8, 0.7]},
        {"value": 80, "opacity": 1, "color": [1, 1, 3]}])"));
    const ClassificationSpec& c = *s.volume().classification;
    EXPECT_EQ(c.type, ClassificationSpec::Type::Boundary);
    EXPECT_EQ(c.opacity_unit_distance, 0.5);
    ASSERT_EQ(c.regions.size(), 3u);
    EXPECT_EQ(c.regions[0].value, -10.0);
    EXPECT_EQ(c.regions[0].opacity, 0.0);
    expect_vec(c.regions[0].color, 0, 0, 0);
    EXPECT_EQ(c.regions[1].value, 20.0);
    EXPECT_EQ(c.regions[1].opacity, 0.2);
    expect_vec(c.regions[1].color, 0.9, 0.8, 0.7);
    EXPECT_EQ(c.regions[2].value, 80.0);
    EXPECT_EQ(c.regions[2].opacity, 1.0);
    expect_vec(c.regions[2].color, 1, 1, 3);
}

TEST(SceneLoaderClassification, Errors) {
    EXPECT_EQ(message_of(volume_with(R"("transfer": {}, "classification": {"type": "isovalue", "isovalues": [{"value": 1}]})")),
              "scene.json: volume.classification: give either \"transfer\" or \"classification\", not both");
    EXPECT_TRUE(fails_with(volume_with(R"("classification": [])"), "volume.classification", "expected an object"));
    EXPECT_TRUE(fails_with(classification_with(R"("isovalues": [{"value": 1}])"), "volume.classification.type",
                           "required"));
    // Without "type", a misspelt key is reported as unknown rather than "type: required".
    EXPECT_TRUE(fails_with(classification_with(R"("typ": "isovalue")"), "volume.classification.typ", "unknown key"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "levoy")"), "volume.classification.type",
                           "expected one of \"isovalue\", \"boundary\", got \"levoy\""));
    // Each type takes only its own keys.
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1}], "regions": [])"),
                           "volume.classification.regions", "unknown key for classification type \"isovalue\""));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "isovalues": [], "regions": [{"value": 1}, {"value": 2}])"),
                           "volume.classification.isovalues", "unknown key for classification type \"boundary\""));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1}], "window": [0, 1])"),
                           "volume.classification.window", "unknown key"));

    // isovalue
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue")"), "volume.classification.isovalues", "required"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [])"),
                           "volume.classification.isovalues", "expected at least one isovalue contour"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": 5)"),
                           "volume.classification.isovalues", "expected an array, got 5"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [5])"),
                           "volume.classification.isovalues[0]", "expected an object, got 5"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1}, {"opacity": 1}])"),
                           "volume.classification.isovalues[1].value", "required"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": "1"}])"),
                           "volume.classification.isovalues[0].value", "expected a number, got \"1\""));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1, "opacity": 1.5}])"),
                           "volume.classification.isovalues[0].opacity", "expected a number in [0, 1], got 1.5"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1, "thickness": 0}])"),
                           "volume.classification.isovalues[0].thickness", "expected a number > 0, got 0"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1, "color": [1, -1, 1]}])"),
                           "volume.classification.isovalues[0].color[1]", "expected a number >= 0, got -1"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1, "color": [1, 1]}])"),
                           "volume.classification.isovalues[0].color", "expected an array of 3 numbers >= 0"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1, "width": 2}])"),
                           "volume.classification.isovalues[0].width", "unknown key for an isovalue contour"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "isovalue", "isovalues": [{"value": 1}],
                                                  "opacity_unit_distance": 0)"),
                           "volume.classification.opacity_unit_distance", "expected a number > 0, got 0"));

    // boundary
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary")"), "volume.classification.regions", "required"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1}])"),
                           "volume.classification.regions", "expected at least two regions, got 1"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [])"),
                           "volume.classification.regions", "expected at least two regions, got 0"));
    EXPECT_EQ(message_of(classification_with(R"("type": "boundary", "regions": [{"value": 1}, {"value": 1}])")),
              "scene.json: volume.classification.regions[1].value: region values must be strictly increasing: 1 "
              "follows 1");
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1}, {"value": 5}, {"value": 3}])"),
                           "volume.classification.regions[2].value", "strictly increasing: 3 follows 5"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1}, {"opacity": 1}])"),
                           "volume.classification.regions[1].value", "required"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1, "opacity": -0.1}, {"value": 2}])"),
                           "volume.classification.regions[0].opacity", "in [0, 1]"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1}, {"value": 2, "color": [0, 0, -1]}])"),
                           "volume.classification.regions[1].color[2]", ">= 0"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1, "thickness": 1}, {"value": 2}])"),
                           "volume.classification.regions[0].thickness", "unknown key for a boundary region"));
    EXPECT_TRUE(fails_with(classification_with(R"("type": "boundary", "regions": [{"value": 1}, {"value": 2}],
                                                  "opacity_unit_distance": -1)"),
                           "volume.classification.opacity_unit_distance", "> 0"));
}

TEST(SceneLoaderShading, Defaults) {
    const Scene s = parse(shading_with(""));
    ASSERT_TRUE(s.volume().shading.has_value());
    expect_shading(*s.volume().shading, ShadingSpec::Model::BlinnPhong, 0.1, 0.7, 0.2, 10, 1, 0, false);
    const Scene p = parse(shading_with(R"("model": "phong")"));
    expect_shading(*p.volume().shading, ShadingSpec::Model::Phong, 0.1, 0.7, 0.2, 10, 1, 0, false);
    // Nodal: no specular term, ks is stored as 0.
    const Scene n = parse(shading_with(R"("model": "nodal")"));
    expect_shading(*n.volume().shading, ShadingSpec::Model::Nodal, 0.1, 0.7, 0, 10, 1, 0, false);
}

TEST(SceneLoaderShading, Full) {
    const Scene s = parse(scene_with(R"("lights": [{"type": "directional", "direction": [0, 0, 2]}])",
                                     R"("shading": {"model": "phong", "ka": 0, "kd": 1.5, "ks": 0.75, "n": 64,
                                                    "kc": 0.5, "kl": 0.01, "two_sided": true})"));
    expect_shading(*s.volume().shading, ShadingSpec::Model::Phong, 0, 1.5, 0.75, 64, 0.5, 0.01, true);
    ASSERT_EQ(s.lights.size(), 1u);
    expect_vec(s.lights[0].direction, 0, 0, 1);
    const Scene b = parse(shading_with(R"("model": "blinn-phong", "ks": 0, "n": 0.5, "two_sided": false)"));
    expect_shading(*b.volume().shading, ShadingSpec::Model::BlinnPhong, 0.1, 0.7, 0, 0.5, 1, 0, false);
    const Scene n = parse(shading_with(R"("model": "nodal", "ka": 0.2, "kd": 0.6, "kc": 0, "kl": 2, "two_sided": true)"));
    expect_shading(*n.volume().shading, ShadingSpec::Model::Nodal, 0.2, 0.6, 0, 10, 0, 2, true);
}

TEST(SceneLoaderShading, Errors) {
    EXPECT_TRUE(fails_with(volume_with(R"("shading": true)"), "volume.shading", "expected an object, got true"));
    EXPECT_TRUE(fails_with(shading_with(R"("model": "gouraud")"), "volume.shading.model",
                           "expected one of \"blinn-phong\", \"phong\", \"nodal\", got \"gouraud\""));
    EXPECT_TRUE(fails_with(shading_with(R"("shininess": 10)"), "volume.shading.shininess",
                           "unknown key (expected one of: model, ka, kd, ks, n, kc, kl, two_sided)"));
    EXPECT_TRUE(fails_with(shading_with(R"("ka": -0.1)"), "volume.shading.ka", "expected a number >= 0, got -0.1"));
    EXPECT_TRUE(fails_with(shading_with(R"("kd": -1)"), "volume.shading.kd", ">= 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("ks": -1)"), "volume.shading.ks", ">= 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("n": 0)"), "volume.shading.n", "expected a number > 0, got 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("kc": -1)"), "volume.shading.kc", ">= 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("kl": -1)"), "volume.shading.kl", ">= 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("kd": "0.7")"), "volume.shading.kd", "expected a number >= 0, got \"0.7\""));
    // Depth cueing 1 / (kc + kl d) needs kc > 0 or kl > 0.
    EXPECT_TRUE(fails_with(shading_with(R"("kc": 0)"), "volume.shading.kc", "kc and kl are both 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("kc": 0, "kl": 0)"), "volume.shading.kc", "give kc > 0 or kl > 0"));
    EXPECT_TRUE(fails_with(shading_with(R"("kl": 0, "kc": 0, "model": "nodal")"), "volume.shading.kc", "both 0"));
    // two_sided is a JSON boolean.
    EXPECT_TRUE(fails_with(shading_with(R"("two_sided": 1)"), "volume.shading.two_sided",
                           "expected true or false, got 1"));
    EXPECT_TRUE(fails_with(shading_with(R"("two_sided": "true")"), "volume.shading.two_sided",
                           "expected true or false, got \"true\""));
    // Nodal shading has no specular term.
    EXPECT_EQ(message_of(shading_with(R"("model": "nodal", "ks": 0.2)")),
              "scene.json: volume.shading.ks: the nodal model has no specular term");
    EXPECT_TRUE(fails_with(shading_with(R"("model": "nodal", "ks": 0)"), "volume.shading.ks",
                           "the nodal model has no specular term"));
    EXPECT_TRUE(fails_with(shading_with(R"("model": "nodal", "n": 10)"), "volume.shading.n",
                           "the nodal model has no specular term"));
}

TEST(SceneLoaderGradient, DefaultsAndSchemes) {
    const Scene d = parse(volume_with(R"("gradient": {})"));
    EXPECT_EQ(d.volume().gradient.scheme, GradientSpec::Scheme::Default);
    EXPECT_FALSE(d.volume().gradient.cache);
    const Scene c = parse(volume_with(R"("gradient": {"scheme": "central", "cache": true})"));
    EXPECT_EQ(c.volume().gradient.scheme, GradientSpec::Scheme::Central);
    EXPECT_TRUE(c.volume().gradient.cache);
    const Scene f = parse(volume_with(R"("interpolation": "nearest", "gradient": {"scheme": "forward", "cache": false})"));
    EXPECT_EQ(f.volume().gradient.scheme, GradientSpec::Scheme::Forward);
    EXPECT_FALSE(f.volume().gradient.cache);
    for (const char* interpolation : {"tricubic-bspline", "tricubic-catmull-rom"}) {
        const Scene a = parse(volume_with(std::string(R"("interpolation": ")") + interpolation +
                                          R"(", "gradient": {"scheme": "analytic", "cache": true})"));
        EXPECT_EQ(a.volume().gradient.scheme, GradientSpec::Scheme::Analytic) << interpolation;
        EXPECT_TRUE(a.volume().gradient.cache) << interpolation;
    }
    const Scene au = parse(volume_with(R"("gradient": {"cache": "auto"})"));
    EXPECT_TRUE(au.volume().gradient.cache_auto);
    EXPECT_FALSE(au.volume().gradient.cache);
    // Default stays Default whatever the interpolation (the renderer resolves it).
    const Scene t = parse(volume_with(R"("interpolation": "tricubic-bspline", "gradient": {"cache": true})"));
    EXPECT_EQ(t.volume().gradient.scheme, GradientSpec::Scheme::Default);
}

TEST(SceneLoaderGradient, Errors) {
    EXPECT_TRUE(fails_with(volume_with(R"("gradient": "central")"), "volume.gradient", "expected an object"));
    EXPECT_TRUE(fails_with(volume_with(R"("gradient": {"scheme": "sobel"})"), "volume.gradient.scheme",
                           "expected one of \"central\", \"forward\", \"analytic\", got \"sobel\""));
    EXPECT_TRUE(fails_with(volume_with(R"("gradient": {"scheme": "analytic"})"), "volume.gradient.scheme",
                           "analytic gradients need a tricubic interpolation"));
    EXPECT_TRUE(fails_with(volume_with(R"("interpolation": "nearest", "gradient": {"scheme": "analytic"})"),
                           "volume.gradient.scheme", "analytic gradients need a tricubic interpolation"));
    EXPECT_TRUE(fails_with(volume_with(R"("gradient": {"cache": "yes"})"), "volume.gradient.cache",
                           "expected true, false or \"auto\", got \"yes\""));
    EXPECT_TRUE(fails_with(volume_with(R"("gradient": {"cache": 1})"), "volume.gradient.cache",
                           "expected true or false, got 1"));
    EXPECT_TRUE(fails_with(volume_with(R"("gradient": {"step": 1})"), "volume.gradient.step",
                           "unknown key (expected one of: scheme, cache)"));
}

TEST(SceneLoaderGradient, OverridesReachTheNewKeys) {
    const std::string base = classification_with(R"("type": "isovalue", "isovalues": [{"value": 1}])");
    const Scene s = parse(base, {"volume.shading.two_sided=true", "volume.shading.model=nodal",
                                 "volume.classification.isovalues[0].opacity=0.5", "volume.gradient.scheme=forward"});
    EXPECT_TRUE(s.volume().shading->two_sided);
    EXPECT_EQ(s.volume().shading->model, ShadingSpec::Model::Nodal);
    EXPECT_EQ(s.volume().classification->isovalues[0].opacity, 0.5);
    EXPECT_EQ(s.volume().gradient.scheme, GradientSpec::Scheme::Forward);
    EXPECT_TRUE(fails_with(base, "volume.shading.ks", "no specular term (set by --set volume.shading.ks=0.3)",
                           {"volume.shading.model=nodal", "volume.shading.ks=0.3"}));
}

// ------------------------------------------------------------------------------------------------
// Errors
// ------------------------------------------------------------------------------------------------

TEST(SceneLoaderErrors, MessageFormatIsExact) {
    EXPECT_EQ(message_of(transfer_with(R"("opacity": [[0, 0], [1, 0.5], [2, 1.5]])")),
              "scene.json: volume.transfer.opacity[2][1]: expected a number in [0, 1], got 1.5");
}

TEST(SceneLoaderErrors, UnknownKeys) {
    EXPECT_TRUE(fails_with(scene_with(R"("rendr": {})"), "rendr", "unknown key (expected one of: description, volume"));
    // A misspelt "volume" is reported as unknown, not as "volume: required".
    EXPECT_TRUE(fails_with(R"({"volum": {"source": "v.nrrd"}})", "volum", "unknown key"));
    EXPECT_TRUE(fails_with(volume_with(R"("sorce": 1)"), "volume.sorce", "unknown key"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity_unit_distanse": 1)"), "volume.transfer.opacity_unit_distanse",
                           "unknown key"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"steps": 1})"), "render.steps", "unknown key"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"depth": 1})"), "image.depth", "unknown key"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{}, {"type": "headlight", "direction": [1, 0, 0]}])"),
                           "lights[1].direction", "unknown key for a headlight"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "box", "tessellate": 4})"), "volume.bounds.tessellate",
                           "unknown key"));
    EXPECT_TRUE(fails_with(source_with(R"({"file": "a.nrrd", "dims": [1, 1, 1]})"), "volume.source.dims",
                           "unknown key for a file source"));
    EXPECT_TRUE(fails_with(source_with(R"({"fiel": "a.nrrd"})"), "volume.source.fiel", "unknown key"));
}

TEST(SceneLoaderErrors, FieldsTakeOnlyTheirOwnParameters) {
    EXPECT_TRUE(fails_with(source_with(R"({"field": "radial", "sigma": 2})"), "volume.source.sigma",
                           "unknown key for field \"radial\""));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "center": [0, 0, 0]})"), "volume.source.center",
                           "unknown key for field \"constant\""));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "gaussian", "values": [1]})"), "volume.source.values",
                           "unknown key for field \"gaussian\""));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "cells", "value": 1, "values": [1, 2, 3, 4, 5, 6, 7, 8]})"),
                           "volume.source.value", "unknown key"));
}

TEST(SceneLoaderErrors, WrongTypes) {
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"step": "0.5"})"), "render.step",
                           "expected a number > 0, got \"0.5\""));
    EXPECT_TRUE(fails_with(scene_with(R"("render": 3)"), "render", "expected an object, got 3"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"projection": 1})"), "render.projection", "expected a string"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": {})"), "lights", "expected an array"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [3])"), "lights[0]", "expected an object"));
    EXPECT_TRUE(fails_with(volume_with(R"("origin": [0, 0])"), "volume.origin", "expected an array of 3 numbers"));
    EXPECT_TRUE(fails_with(volume_with(R"("origin": [0, null, 0])"), "volume.origin[1]", "expected a number, got null"));
    EXPECT_TRUE(fails_with(transfer_with(R"("color": [[0, 1, 1]])"), "volume.transfer.color[0]",
                           "expected a row [value, r, g, b] of 4 numbers"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity": [0, 1])"), "volume.transfer.opacity[0]",
                           "expected a row [value, a] of 2 numbers, got 0"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity": [[true, 1]])"), "volume.transfer.opacity[0][0]",
                           "expected a number, got true"));
    EXPECT_TRUE(fails_with(source_with("12"), "volume.source", "expected a file path or an object"));
    EXPECT_TRUE(fails_with(source_with(R"("")"), "volume.source", "expected a file path"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"background": [0, 0, 0]})"), "image.background",
                           "expected an array of 4 numbers in [0, 1]"));
    EXPECT_TRUE(fails_with("[1, 2]", "(top level)", "expected an object, got [1,2]"));
}

TEST(SceneLoaderErrors, OutOfRange) {
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"step": 0})"), "render.step", "expected a number > 0, got 0"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"step": -1})"), "render.step", "> 0"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"early_termination": 0})"), "render.early_termination",
                           "expected a number in (0, 1], got 0"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"early_termination": 1.5})"), "render.early_termination", "(0, 1]"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"gain": 0})"), "render.gain", "> 0"));
    EXPECT_TRUE(fails_with(volume_with(R"("spacing": [1, 0, 1])"), "volume.spacing[1]", "expected a number > 0, got 0"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity_unit_distance": 0)"), "volume.transfer.opacity_unit_distance",
                           "> 0"));
    EXPECT_TRUE(fails_with(transfer_with(R"("color": [[0, 1, -0.5, 1]])"), "volume.transfer.color[0][2]",
                           "expected a number >= 0, got -0.5"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity": [[0, -0.1]])"), "volume.transfer.opacity[0][1]", "in [0, 1]"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"background": [0, 0, 0, 1.5]})"), "image.background[3]",
                           "expected a number in [0, 1], got 1.5"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"width": 0})"), "image.width",
                           "expected an integer in [1, 32768], got 0"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"height": 40000})"), "image.height", "[1, 32768]"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{"color": [1, -1, 1]}])"), "lights[0].color[1]", ">= 0"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "gaussian", "sigma": 0})"), "volume.source.sigma", "> 0"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "marschner-lobb", "alpha": -0.5})"), "volume.source.alpha", ">= 0"));
}

TEST(SceneLoaderErrors, UnknownEnumValues) {
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"projection": "maximum"})"), "render.projection",
                           "expected one of \"composite\", \"mip\", \"minip\", \"average\", \"first-hit\", \"xray\", "
                           "got \"maximum\""));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"order": "random"})"), "render.order", "expected one of"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"step_units": "mm"})"), "render.step_units", "expected one of"));
    EXPECT_TRUE(fails_with(transfer_with(R"("domain": "normalised")"), "volume.transfer.domain", "expected one of"));
    EXPECT_TRUE(fails_with(volume_with(R"("interpolation": "cubic")"), "volume.interpolation",
                           "expected one of \"nearest\", \"trilinear\", \"tricubic-bspline\", \"tricubic-catmull-rom\""));
    EXPECT_TRUE(fails_with(volume_with(R"("classify": "before")"), "volume.classify",
                           "expected one of \"post\", \"pre\", got \"before\""));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "sphere"})"), "volume.source.field", "expected one of"));
    EXPECT_TRUE(fails_with(source_with(R"({"file": "a.vtk", "format": "xyz"})"), "volume.source.format",
                           "expected one of \"nrrd\", \"raw\""));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "fisheye"})"), "camera.type", "expected one of"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{"type": "spot"}])"), "lights[0].type", "expected one of"));
}

TEST(SceneLoaderErrors, UnsortedAndEmptyRows) {
    EXPECT_TRUE(fails_with(transfer_with(R"("color": [[0, 1, 1, 1], [1, 1, 1, 1], [5, 1, 1, 1], [3, 1, 1, 1]])"),
                           "volume.transfer.color[3]", "sorted by value (non-decreasing): 3 follows 5"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity": [[10, 0], [2, 1]])"), "volume.transfer.opacity[1]", "sorted"));
    EXPECT_TRUE(fails_with(transfer_with(R"("color": [])"), "volume.transfer.color", "at least one row"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity": [])"), "volume.transfer.opacity", "at least one row"));
}

TEST(SceneLoaderErrors, Window) {
    EXPECT_TRUE(fails_with(transfer_with(R"("window": [0, 1])"), "volume.transfer.window",
                           "a window applies only to \"domain\": \"normalized\""));
    EXPECT_TRUE(fails_with(transfer_with(R"("domain": "normalized", "window": [5, 5])"), "volume.transfer.window",
                           "lo < hi"));
    EXPECT_TRUE(fails_with(transfer_with(R"("domain": "normalized", "window": [0])"), "volume.transfer.window",
                           "expected an array of 2 numbers"));
}

TEST(SceneLoaderErrors, NonFiniteNumbers) {
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"step": 1e999})"), "render.step", "1e999 is out of range"));
    EXPECT_TRUE(fails_with(transfer_with(R"("opacity": [[0, 0], [-1e999, 1]])"), "volume.transfer.opacity[1][0]",
                           "-1e999 is out of range"));
    EXPECT_TRUE(fails_with(volume_with(R"("origin": [0, 0, 1E400])"), "volume.origin[2]", "out of range"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"width": 1e999})"), "image.width", "out of range"));
    // The position is given too.
    EXPECT_NE(message_of("{\"volume\": {\"source\": \"v.nrrd\",\n \"origin\": [0, 1e999, 0]}}").find("line 2, column 16"),
              std::string::npos);
}

TEST(SceneLoaderErrors, Integers) {
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [2, 2.5, 2]})"), "volume.source.dims[1]",
                           "expected an integer >= 1, got 2.5"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [2, 0, 2]})"), "volume.source.dims[1]",
                           "expected an integer >= 1, got 0"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [2, 2]})"), "volume.source.dims",
                           "expected an array of 3 integers"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [2, "2", 2]})"), "volume.source.dims[1]",
                           "expected an integer"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"width": 100.5})"), "image.width",
                           "expected an integer in [1, 32768], got 100.5"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [2, 18446744073709551615, 2]})"),
                           "volume.source.dims[1]", "expected an integer"));
}

TEST(SceneLoaderErrors, TooManyVoxelsOrPixels) {
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [2048, 2048, 1024]})"), "volume.source.dims",
                           "2048 x 2048 x 1024 voxels exceed the limit of 2^31"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [4294967296, 4294967296, 4294967296]})"),
                           "volume.source.dims", "procedural fields"));  // the product overflows 64 bits
    EXPECT_TRUE(fails_with(source_with(R"({"field": "constant", "dims": [1, 1, 3000000000]})"), "volume.source.dims",
                           "2^31"));
    EXPECT_TRUE(fails_with(scene_with(R"("image": {"width": 20000, "height": 20000})"), "image.height",
                           "20000 x 20000 = 400000000 pixels exceed the limit of 2^28"));
}

TEST(SceneLoaderErrors, Cells) {
    EXPECT_TRUE(fails_with(source_with(R"({"field": "cells", "dims": [2, 2, 2], "values": [1, 2, 3]})"),
                           "volume.source.values", "expected 8 values (dims 2 x 2 x 2), got 3"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "cells", "dims": [1, 1, 1]})"), "volume.source.values", "required"));
    EXPECT_TRUE(fails_with(source_with(R"({"field": "cells", "dims": [1, 1, 2], "values": [1, "x"]})"),
                           "volume.source.values[1]", "expected a number"));
}

TEST(SceneLoaderErrors, Sources) {
    EXPECT_TRUE(fails_with(source_with(R"({"file": "a.nrrd", "field": "constant"})"), "volume.source",
                           "either \"file\" or \"field\""));
    EXPECT_TRUE(fails_with(source_with("{}"), "volume.source", "expected an object with \"file\" or \"field\""));
    EXPECT_TRUE(fails_with(R"({"volume": {}})", "volume.source", "required"));
    EXPECT_TRUE(fails_with(R"({"volume": {"source": "v.nrrd", "origin": [0, 0, 0], "spacing": "1"}})",
                           "volume.spacing", "expected an array of 3 numbers > 0"));
}

TEST(SceneLoaderErrors, NotImplementedYet) {
    // transform, clip_planes, crop and several volumes are implemented (issue 9): tests/unit/test_multi_volume.cpp.
    // render.integrator and render.tolerance are implemented (issue 6): tests/unit/test_adaptive.cpp.
    EXPECT_EQ(parse(scene_with(R"("render": {"integrator": "adaptive", "tolerance": 1e-8})")).render.integrator,
              IntegrationMethod::Adaptive);
    EXPECT_EQ(parse(scene_with(R"("render": {"integrator": "midpoint"})")).render.integrator, IntegrationMethod::Fixed);
    EXPECT_EQ(parse(scene_with(R"("render": {})")).render.tolerance, 1e-6);
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"tolerance": 0})"), "render.tolerance", "expected a number > 0"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"integrator": "exact"})"), "render.integrator", "\"adaptive\""));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"profile": "vtk"})"), "render.profile", "\"vtk-gpu\""));
    EXPECT_EQ(parse(scene_with(R"("render": {"profile": "vtk-cpu"})")).render.profile, ProfileId::VtkCpu);
    EXPECT_EQ(parse(scene_with(R"("render": {"profile": "vtk-gpu"})")).render.profile, ProfileId::VtkGpu);
    EXPECT_EQ(parse(scene_with(R"("render": {})")).render.profile, ProfileId::Reference);
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"profile": "ospray", "profile_options": {}})"),
                           "render.profile_options", "only the cuda-curvilinear"));
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"profile": "cuda-curvilinear", "profile_options": {"gain": 1}})"),
                           "render.profile_options.gain", "unknown key"));
    EXPECT_EQ(parse(scene_with(R"("render": {"profile": "cuda-curvilinear", "profile_options": {"density": 0.25}})"))
                  .render.profile_options.density,
              0.25);
    EXPECT_EQ(parse(R"({"volumes": [{"source": "a.nrrd"}, {"source": "b.nrrd"}]})").volumes.size(), 2u);
}

TEST(SceneLoaderErrors, VolumeAndVolumes) {
    EXPECT_EQ(message_of(R"({"render": {}})"), "scene.json: volume: required");
    EXPECT_TRUE(fails_with(R"({"volume": {"source": "a.nrrd"}, "volumes": [{"source": "a.nrrd"}]})", "volumes",
                           "either \"volume\" or \"volumes\", not both"));
    EXPECT_TRUE(fails_with(R"({"volumes": []})", "volumes", "expected at least one volume"));
    EXPECT_TRUE(fails_with(R"({"volumes": {}})", "volumes", "expected an array"));
    // Paths inside "volumes" name the element.
    EXPECT_TRUE(fails_with(R"({"volumes": [{"source": "a.nrrd", "spacing": [1, 1, -1]}]})", "volumes[0].spacing[2]",
                           "> 0"));
}

TEST(SceneLoaderErrors, Lights) {
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{"type": "directional"}])"), "lights[0].direction", "required"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{"type": "directional", "direction": [0, 0, 0]}])"),
                           "lights[0].direction", "non-zero"));
}

TEST(SceneLoaderErrors, CameraDegeneracies) {
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "eye": [1, 2, 3], "target": [1, 2, 3]})"),
                           "camera.eye", "the eye is at the target"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "orthographic", "up": [0, 0, 0]})"), "camera.up",
                           "non-zero"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "up": [0, 0, -2]})"), "camera.up",
                           "parallel"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "eye": [0, 0, 1e-100], "up": [0, 0, 1e100]})"),
                           "camera.up", "parallel"));
    // issue 32: beyond [1e-100, 1e100] a number is refused where it stands (target - eye no longer overflows)
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "eye": [0, 0, -1e308], "target": [0, 0, 1e308]})"),
                           "camera.eye[2]", "the number -1e308 is beyond volref's range"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "fov_y": 180})"), "camera.fov_y",
                           "expected a number in (0, 180), got 180"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "fov_y": 0})"), "camera.fov_y", "(0, 180)"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "orthographic", "height": 0})"), "camera.height", "> 0"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"eye": [0, 0, 1]})"), "camera.type", "required"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "perspective", "height": 2})"), "camera.height",
                           "unknown key for camera type \"perspective\""));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "orthographic", "fov_y": 2})"), "camera.fov_y",
                           "unknown key for camera type \"orthographic\""));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "matrices", "eye": [0, 0, 1]})"), "camera.eye",
                           "unknown key"));
}

TEST(SceneLoaderErrors, CameraMatrices) {
    const std::string identity = "[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]";
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "matrices", "view": [1,0,0,0, 0,1,0,0, 0,0,0,0, 0,0,0,1],
                                       "projection": )" + identity + "}"),
                           "camera.view", "not invertible (determinant 0)"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "matrices", "view": )" + identity +
                                      R"(, "projection": [1e-100,0,0,0, 0,1e-100,0,0, 0,0,1e-100,0, 0,0,0,1e-100]})"),
                           "camera.projection", "not invertible"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "matrices", "view": [1, 2, 3], "projection": )" + identity + "}"),
                           "camera.view", "expected an array of 16 numbers"));
    EXPECT_TRUE(fails_with(scene_with(R"("camera": {"type": "matrices", "view": )" + identity + "}"), "camera.projection",
                           "required"));
}

TEST(SceneLoaderErrors, Bounds) {
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"min": [0, 0, 0], "max": [1, 0, 1]})"), "volume.bounds.max",
                           "expected max > min on every axis"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "sphere"})"), "volume.bounds.type", "expected one of"));
}

TEST(SceneLoaderErrors, FirstHitNeedsAnIsovalue) {
    EXPECT_EQ(message_of(scene_with(R"("render": {"projection": "first-hit"})")),
              "scene.json: render.isovalue: required by projection first-hit");
    EXPECT_EQ(*parse(scene_with(R"("render": {"projection": "first-hit", "isovalue": -3})")).render.isovalue, -3.0);
}

TEST(SceneLoaderErrors, JsonSyntax) {
    const std::string m = message_of("{\"volume\": {\"source\": \"v.nrrd\"},\n  \"render\": {\"step\": x}}");
    EXPECT_EQ(m.rfind("scene.json: line 2, column ", 0), 0u) << m;
    EXPECT_NE(m.find("syntax error"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
    EXPECT_EQ(message_of("").rfind("scene.json: line 1, column 1: ", 0), 0u);
    EXPECT_NE(message_of(R"({"volume": {"source": "v.nrrd"},})").find("line 1"), std::string::npos);
    // Comments are not JSON.
    EXPECT_NE(message_of("{\"volume\": {\"source\": \"v.nrrd\"} // note\n}").find("syntax error"), std::string::npos);
}

TEST(SceneLoaderErrors, DuplicateKeys) {
    EXPECT_TRUE(fails_with(scene_with(R"("render": {"step": 1, "step": 2})"), "render.step", "duplicate key"));
    EXPECT_TRUE(fails_with(R"({"volume": {"source": "a.nrrd"}, "volume": {"source": "b.nrrd"}})", "volume",
                           "duplicate key"));
    EXPECT_TRUE(fails_with(scene_with(R"("lights": [{}, {"color": [1, 1, 1], "color": [1, 1, 1]}])"), "lights[1].color",
                           "duplicate key"));
}

TEST(SceneLoaderErrors, MessagesAreOneLine) {
    const std::string m = message_of(scene_with("\"bad\\nkey\": 1"));
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(m.rfind("scene.json: bad\\nkey: unknown key", 0), 0u) << m;
    const std::string v = message_of(scene_with(R"("render": {"projection": "a\nb"})"));
    EXPECT_EQ(v.find('\n'), std::string::npos) << v;
}

// ------------------------------------------------------------------------------------------------
// --set overrides
// ------------------------------------------------------------------------------------------------

TEST(SceneOverrides, CreateAndReplaceValues) {
    const std::string base = scene_with("", R"("transfer": {"opacity": [[0, 0], [1, 0.5], [2, 1]]})");
    const Scene s = parse(base, {"render.step=0.25",                    // creates "render"
                                 "render.projection=mip",               // not JSON: a string
                                 "render.order=\"back-to-front\"",      // a JSON string
                                 "image.background=[0, 0, 0, 1]",       // a JSON array
                                 "image.background[1]=0.5",             // an element of it
                                 "volume.transfer.opacity[1][1]=0.75",  // an element of an existing array
                                 "camera.type=orthographic",            // creates "camera"
                                 "camera.height=4",
                                 "volume.source=other/v.nrrd"});
    EXPECT_EQ(s.render.step, 0.25);
    EXPECT_EQ(s.render.projection, Projection::Mip);
    EXPECT_EQ(s.render.order, CompositeOrder::BackToFront);
    EXPECT_EQ(s.image.background, glm::dvec4(0, 0.5, 0, 1));
    EXPECT_EQ(s.volume().transfer.opacity[1], (std::array<double, 2>{1, 0.75}));
    EXPECT_EQ(s.camera.type, CameraSpec::Type::Orthographic);
    EXPECT_EQ(s.camera.height, 4.0);
    EXPECT_EQ(*s.volume().source.file, kBase / "other" / "v.nrrd");
}

TEST(SceneOverrides, AppliedInOrder) {
    const Scene s = parse(scene_with(R"("render": {"step": 1})"), {"render.step=2", "render.step=3"});
    EXPECT_EQ(s.render.step, 3.0);
    // A later override of a whole object replaces an earlier one under it.
    const Scene t = parse(scene_with(""), {"render.step=2", "render={\"gain\": 4}"});
    EXPECT_EQ(t.render.step, 0.5);
    EXPECT_EQ(t.render.gain, 4.0);
}

TEST(SceneOverrides, AppliedBeforeValidation) {
    // The file alone is invalid (first-hit without isovalue); the override completes it.
    const Scene s = parse(scene_with(R"("render": {"projection": "first-hit"})"), {"render.isovalue=12"});
    EXPECT_EQ(*s.render.isovalue, 12.0);
    // An override can remove a problem key's value by replacing its object.
    EXPECT_NO_THROW(parse(volume_with(R"("shading": {})"), {"volume={\"source\": \"v.nrrd\"}"}));
}

TEST(SceneOverrides, ValidationErrorsNameTheOverride) {
    EXPECT_EQ(message_of(scene_with(""), {"render.step=-1"}),
              "scene.json: render.step: expected a number > 0, got -1 (set by --set render.step=-1)");
    EXPECT_TRUE(fails_with(scene_with(""), "render.projection", "got \"maximum\" (set by --set render.projection=maximum)",
                           {"render.projection=maximum"}));
    EXPECT_TRUE(fails_with(scene_with(""), "render.stepp", "unknown key", {"render.stepp=1"}));
    EXPECT_TRUE(fails_with(scene_with(""), "image.background[3]", "in [0, 1]", {"image.background=[0, 0, 0, 2]"}));
}

TEST(SceneOverrides, Malformed) {
    EXPECT_EQ(message_of(scene_with(""), {"render.step"}), "--set render.step: missing '='");
    EXPECT_EQ(message_of(scene_with(""), {"render..step=1"}).rfind("--set render..step=1: malformed path", 0), 0u);
    EXPECT_EQ(message_of(scene_with(""), {"=1"}).rfind("--set =1: malformed path", 0), 0u);
    EXPECT_EQ(message_of(scene_with(""), {"render.=1"}).rfind("--set render.=1: malformed path", 0), 0u);
    EXPECT_EQ(message_of(scene_with(""), {"[0]=1"}).rfind("--set [0]=1: malformed path", 0), 0u);
    EXPECT_EQ(message_of(scene_with(""), {"image.background[x]=1"}).rfind("--set image.background[x]=1: malformed path", 0),
              0u);
    EXPECT_EQ(message_of(scene_with(""), {"image.background[1=1"}).rfind("--set image.background[1=1: malformed path", 0),
              0u);
    EXPECT_EQ(message_of(scene_with(""), {"render step=1"}).rfind("--set render step=1: malformed path", 0), 0u);
    EXPECT_EQ(message_of(scene_with(""), {"render.step=1", "bad"}), "--set bad: missing '='");
}

TEST(SceneOverrides, IndicesMustExist) {
    const std::string base = scene_with("", R"("transfer": {"opacity": [[0, 0], [1, 0.5], [2, 1]]})");
    EXPECT_EQ(message_of(base, {"volume.transfer.opacity[3][1]=0.5"}),
              "--set volume.transfer.opacity[3][1]=0.5: volume.transfer.opacity[3]: index past the end (the array has 3 "
              "elements)");
    EXPECT_EQ(message_of(base, {"volume.transfer.opacity[1][2]=0.5"}).rfind(
                  "--set volume.transfer.opacity[1][2]=0.5: volume.transfer.opacity[1][2]: index past the end", 0),
              0u);
    EXPECT_EQ(message_of(base, {"volume.transfer.color[0]=[0, 1, 1, 1]"}),
              "--set volume.transfer.color[0]=[0, 1, 1, 1]: volume.transfer.color: no such array");
    EXPECT_EQ(message_of(base, {"volume.source[0]=1"}).rfind("--set volume.source[0]=1: volume.source: expected an array",
                                                             0),
              0u);
    EXPECT_EQ(message_of(base, {"volume.source.file=a.nrrd"}).rfind(
                  "--set volume.source.file=a.nrrd: volume.source: expected an object", 0),
              0u);
}

TEST(SceneOverrides, ValuesThatAreNotJsonAreStrings) {
    const Scene s = parse(scene_with(""), {"volume.source=my file.nrrd", "description="});
    EXPECT_EQ(*s.volume().source.file, kBase / "my file.nrrd");
    // A value that overflows a double is an error, not the string "1e999".
    EXPECT_EQ(message_of(scene_with(""), {"render.step=1e999"}).rfind("--set render.step=1e999: render.step: ", 0), 0u);
    EXPECT_TRUE(fails_with(scene_with(""), "render.step", "expected a number > 0, got \"fast\"", {"render.step=fast"}));
}

// ------------------------------------------------------------------------------------------------
// Files
// ------------------------------------------------------------------------------------------------

TEST(SceneLoaderFiles, RelativePathsAreResolvedAgainstTheSceneFolder) {
    TempDir dir;
    const fs::path file = dir.write("scenes/s.json", R"({"volume": {"source": "../data/head.nrrd"}})");
    const Scene s = load_scene(file);
    EXPECT_EQ(s.file, file);
    EXPECT_EQ(*s.volume().source.file, fs::weakly_canonical(dir.path / "data" / "head.nrrd"));
    EXPECT_TRUE(s.volume().source.file->is_absolute());

    const fs::path abs = dir.write("a.json", R"({"volume": {"source": {"file": "/abs/x.raw"}}})");
    EXPECT_EQ(*load_scene(abs).volume().source.file, fs::path("/abs/x.raw"));

    // Overrides are applied by load_scene too.
    const Scene o = load_scene(file, {"volume.source=v2.nrrd", "render.step=2"});
    EXPECT_EQ(*o.volume().source.file, fs::weakly_canonical(dir.path / "scenes" / "v2.nrrd"));
    EXPECT_EQ(o.render.step, 2.0);
}

TEST(SceneLoaderFiles, RelativeSceneFileName) {
    TempDir dir;
    dir.write("rel.json", R"({"volume": {"source": "v.nrrd"}})");
    struct CurrentDir {  // restores the working directory even if load_scene throws
        fs::path old = fs::current_path();
        ~CurrentDir() { fs::current_path(old); }
    } restore;
    fs::current_path(dir.path);
    const Scene s = load_scene("rel.json");
    EXPECT_EQ(*s.volume().source.file, fs::weakly_canonical(dir.path / "v.nrrd"));
}

TEST(SceneLoaderFiles, MissingFile) {
    TempDir dir;
    const fs::path file = dir.path / "missing.json";
    const std::string m = error_of([&] { load_scene(file); });
    EXPECT_EQ(m.rfind(file.string() + ": ", 0), 0u) << m;
    EXPECT_NE(m.find("no such file"), std::string::npos) << m;
    const std::string d = error_of([&] { load_scene(dir.path); });
    EXPECT_NE(d.find("directory"), std::string::npos) << d;
}

TEST(SceneLoaderFiles, SyntaxErrorNamesFileAndLine) {
    TempDir dir;
    const fs::path file = dir.write("bad.json", "{\n  \"volume\": {\"source\": \"v.nrrd\"},\n  \"render\": {\"step\": 0.5,}\n}\n");
    const std::string m = error_of([&] { load_scene(file); });
    EXPECT_EQ(m.rfind(file.string() + ": line 3, column ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

TEST(SceneLoaderFiles, ValidationErrorNamesFile) {
    TempDir dir;
    const fs::path file = dir.write("scene.json", R"({"volume": {"source": "v.nrrd"}, "render": {"step": 0}})");
    EXPECT_EQ(error_of([&] { load_scene(file); }), file.string() + ": render.step: expected a number > 0, got 0");
}


TEST(SceneLoaderBounds, ShellsAndMeshes) {
    const Scene c = parse(volume_with(
        R"("bounds": {"type": "cylindrical", "center": [1, 2, 3], "radius": [0.5, 2], "angle": [300, 420], "height": [-1, 1], "tessellate": 64})"));
    EXPECT_EQ(c.volume().bounds.type, BoundsSpec::Type::Cylindrical);
    EXPECT_EQ(c.volume().bounds.cylinder.center, glm::dvec3(1, 2, 3));
    EXPECT_EQ(c.volume().bounds.cylinder.r0, 0.5);
    EXPECT_EQ(c.volume().bounds.cylinder.a1, 420.0);
    EXPECT_EQ(c.volume().bounds.cylinder.h0, -1.0);
    EXPECT_EQ(c.volume().bounds.tessellate, 64);
    const Scene d = parse(volume_with(R"("bounds": {"type": "cylindrical", "radius": [0, 1], "height": [0, 2]})"));
    EXPECT_EQ(d.volume().bounds.cylinder.center, glm::dvec3(0.0));
    EXPECT_EQ(d.volume().bounds.cylinder.a0, 0.0);
    EXPECT_EQ(d.volume().bounds.cylinder.a1, 360.0);
    EXPECT_EQ(d.volume().bounds.cylinder.h1, 2.0);
    EXPECT_EQ(d.volume().bounds.tessellate, 0);
    const Scene e = parse(volume_with(R"("bounds": {"type": "spherical", "radius": [0, 1]})"));
    EXPECT_EQ(e.volume().bounds.sphere.lon1, 360.0);
    EXPECT_EQ(e.volume().bounds.sphere.lat0, -90.0);
    EXPECT_EQ(e.volume().bounds.sphere.axes, (std::array<int, 3>{0, 1, 2}));
    const Scene s = parse(volume_with(
        R"("bounds": {"type": "spherical", "radius": [1, 2], "longitude": [0, 90], "latitude": [-30, 60], "axes": ["radius", "longitude", "latitude"]})"));
    EXPECT_EQ(s.volume().bounds.type, BoundsSpec::Type::Spherical);
    EXPECT_EQ(s.volume().bounds.sphere.lat0, -30.0);
    EXPECT_EQ(s.volume().bounds.sphere.lon1, 90.0);
    EXPECT_EQ(s.volume().bounds.sphere.axes, (std::array<int, 3>{2, 0, 1}));
    const Scene m = parse(volume_with(R"("bounds": {"type": "mesh", "file": "shape.obj"})"));
    EXPECT_EQ(m.volume().bounds.type, BoundsSpec::Type::Mesh);
    EXPECT_EQ(m.volume().bounds.mesh.filename(), "shape.obj");
    EXPECT_TRUE(m.volume().bounds.mesh.is_absolute());
}

TEST(SceneLoaderBounds, Errors) {
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "radius": [2, 1], "height": [0, 1]})"),
                           "volume.bounds.radius", "lo < hi"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "radius": [-1, 1], "height": [0, 1]})"),
                           "volume.bounds.radius[0]", ">= 0"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "angle": [0, 400]})"),
                           "volume.bounds.angle", "at most 360"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "spherical", "radius": [0, 1], "latitude": [-100, 0]})"),
                           "volume.bounds.latitude[0]", ""));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "spherical", "radius": [0, 1], "axes": ["radius", "radius", "latitude"]})"),
                           "volume.bounds.axes[1]", "given twice"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "spherical", "radius": [0, 1], "height": [0, 1]})"),
                           "volume.bounds.height", "unknown key"));
    // A shell places the samples: its extent has no default.
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "height": [0, 1]})"), "volume.bounds.radius",
                           "required"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "radius": [0, 1]})"), "volume.bounds.height",
                           "required"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "spherical"})"), "volume.bounds.radius", "required"));
    // An unknown key is reported before a missing one (it may be the missing one, misspelt).
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "radious": [0, 1]})"),
                           "volume.bounds.radious", "unknown key"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "mesh"})"), "volume.bounds.file", "required"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "box", "tessellate": 8})"), "volume.bounds.tessellate",
                           "unknown key"));
    EXPECT_TRUE(fails_with(volume_with(R"("bounds": {"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "tessellate": 2})"),
                           "volume.bounds.tessellate", ">= 3"));
}

// volref resample --shell (and the volref_bounds key of its files) and a scene's volume.bounds read a
// shell with one function: the same input is accepted or rejected alike, and a rejection is the same
// message after the path, "--shell: <key>: <problem>" against "scene.json: volume.bounds.<key>: <problem>".
TEST(SceneLoaderBounds, ShellAloneReadsAsInAScene) {
    const std::vector<std::string> bad = {
        R"({"type": "cylindrical", "radius": [2, 1], "height": [0, 1]})",
        R"({"type": "cylindrical", "radius": [-1, 1], "height": [0, 1]})",
        R"({"type": "cylindrical", "radius": [0, 1], "height": [1, 1]})",
        R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "angle": [0, 400]})",
        R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "longitude": [0, 90]})",
        R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "tessellate": 2})",
        R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "tessellate": 4.5})",
        R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "center": [0, 0]})",
        R"({"type": "cylindrical", "height": [0, 1]})",
        R"({"type": "cylindrical", "radius": [0, 1]})",
        R"({"type": "cylindrical", "radious": [0, 1], "height": [0, 1]})",
        R"({"type": "spherical"})",
        R"({"type": "spherical", "radius": [0, 1], "latitude": [-100, 0]})",
        R"({"type": "spherical", "radius": [0, 1], "latitude": [10, 0]})",
        R"({"type": "spherical", "radius": [0, 1], "longitude": [0, 361]})",
        R"({"type": "spherical", "radius": [0, 1], "axes": ["radius", "radius", "latitude"]})",
        R"({"type": "spherical", "radius": [0, 1], "axes": ["radius", "longitude"]})",
        R"({"type": "spherical", "radius": [0, 1], "axes": ["radius", "longitude", 3]})",
        R"({"type": "spherical", "radius": [0, 1], "height": [0, 1]})",
        R"({"type": "spherical", "radius": [0, "1"]})",
    };
    for (const std::string& shell : bad) {
        const std::string in_scene = message_of(volume_with(R"("bounds": )" + shell));
        const std::string alone = error_of([&] { parse_shell(shell, "--shell"); });
        const std::string scene_prefix = "scene.json: volume.bounds.", shell_prefix = "--shell: ";
        ASSERT_EQ(in_scene.rfind(scene_prefix, 0), 0u) << shell << "\n" << in_scene;
        ASSERT_EQ(alone.rfind(shell_prefix, 0), 0u) << shell << "\n" << alone;
        EXPECT_EQ(alone.substr(shell_prefix.size()), in_scene.substr(scene_prefix.size())) << shell;
    }
    // Accepted alike, with the same values.
    const std::string good =
        R"({"type": "spherical", "center": [1, 2, 3], "radius": [0.5, 2], "longitude": [300, 420], "latitude": [-30, 60], "axes": ["radius", "longitude", "latitude"], "tessellate": 16})";
    const BoundsSpec a = parse_shell(good, "--shell"), b = parse(volume_with(R"("bounds": )" + good)).volume().bounds;
    EXPECT_EQ(a.type, BoundsSpec::Type::Spherical);
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.sphere.center, b.sphere.center);
    EXPECT_EQ(a.sphere.r0, b.sphere.r0);
    EXPECT_EQ(a.sphere.lon1, b.sphere.lon1);
    EXPECT_EQ(a.sphere.lat0, b.sphere.lat0);
    EXPECT_EQ(a.sphere.axes, b.sphere.axes);
    EXPECT_EQ(a.tessellate, b.tessellate);
    // Alone, the type is required and must be a shell.
    EXPECT_EQ(error_of([] { parse_shell(R"({"radius": [0, 1]})", "--shell"); }), "--shell: type: required");
    EXPECT_EQ(error_of([] { parse_shell(R"({"type": "box"})", "s.json"); }),
              "s.json: type: expected one of \"cylindrical\", \"spherical\", got \"box\"");
    EXPECT_EQ(error_of([] { parse_shell("[1]", "--shell"); }).rfind("--shell: ", 0), 0u);
    EXPECT_EQ(error_of([] { parse_shell(R"({"type": "spherical")", "--shell"); }).rfind("--shell: line 1", 0), 0u);
}
}  // namespace
}  // namespace volref

namespace volref {
namespace {

// {"volume": {"source": "v.nrrd", "x": [[...]]}} with `depth` containers in all (the two objects
// included).
std::string nested_scene(std::size_t depth) {
    return R"({"volume": {"source": "v.nrrd", "x": )" + std::string(depth - 2, '[') + std::string(depth - 2, ']') +
           "}}";
}


// conventions::kMaxJsonDepth: 256 levels of arrays and objects are read (the deepest level's own
// problem is reported: an unknown key), 257 and 100,000 are refused in one line naming the outer path,
// without walking (or crashing on) the nesting.
TEST(SceneLoaderErrors, NestingDeeperThanTheLimitIsOneLineNotACrash) {
    EXPECT_NE(error_of([&] { parse(nested_scene(256)); }).find("volume.x: unknown key"), std::string::npos);
    const std::string expected = "scene.json: volume.x: nested deeper than 256 arrays and objects";
    EXPECT_EQ(error_of([&] { parse(nested_scene(257)); }), expected);
    EXPECT_EQ(error_of([&] { parse(nested_scene(100000)); }), expected);
}

}  // namespace
}  // namespace volref
