// glsl-basic reproduces seed 002's shader (issue 17; docs/conventions.md section 9): colour = the sample's
// value (textureValue.rrr), samples below 0.01 skipped, alpha = K times the opacity (not clamped), stop
// once A >= 1, normal = +grad f. One orthographic pixel looking along -z through a box [0, 4]^3, step 0.5:
// samples at z = 4, 3.5, ..., 0 (9), worked out by hand below. (The real GLSL program is checked
// against this profile by the glsl_* ctest tests, tests/gpu/glsl.)
#include <gtest/gtest.h>

#include <cmath>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;

namespace {

Scene box(FieldSpec field, double opacity, double intensity) {
    Scene s = field_scene(std::move(field));
    s.volume().transfer.color = {{0, 0.2, 0.4, 0.6}, {1, 0.2, 0.4, 0.6}};
    s.volume().transfer.opacity = {{0, opacity}, {1, opacity}};
    s.camera = ortho_down_z(2.0, 2.0, 14.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    s.render.profile = ProfileId::GlslBasic;
    s.render.profile_options.intensity = intensity;
    return s;
}

glm::dvec4 pixel(const Scene& s) { return rgba(render_scene(s, {1, false}), 0, 0); }

}  // namespace

// v = 0.5, a = 0.1, K = 2: each of the 9 samples has alpha 0.2 and colour (0.5, 0.5, 0.5) (not the
// transfer function's (0.2, 0.4, 0.6)): A = 1 - 0.8^9, C = 0.5 A.
TEST(GlslBasicProfile, ColourIsTheValueAndAlphaIsKTimesOpacity) {
    const glm::dvec4 p = pixel(box(constant_field(0.5, {5, 5, 5}), 0.1, 2.0));
    const double A = 1.0 - std::pow(0.8, 9);
    EXPECT_NEAR(p.a, A, 1e-12);
    EXPECT_NEAR(p.r, 0.5 * A, 1e-12);
    EXPECT_NEAR(p.g, 0.5 * A, 1e-12);
    EXPECT_NEAR(p.b, 0.5 * A, 1e-12);
}

// The 0.01 density cutoff: v = 0.009 is skipped (A = 0 although a = 0.5); v = 0.01 is kept:
// A = 1 - 0.5^9, C = 0.01 A.
TEST(GlslBasicProfile, SamplesBelowTheCutoffAreSkipped) {
    EXPECT_EQ(pixel(box(constant_field(0.009, {5, 5, 5}), 0.5, 1.0)).a, 0.0);
    const glm::dvec4 p = pixel(box(constant_field(0.01, {5, 5, 5}), 0.5, 1.0));
    EXPECT_NEAR(p.a, 1.0 - std::pow(0.5, 9), 1e-12);
    EXPECT_NEAR(p.r, 0.01 * (1.0 - std::pow(0.5, 9)), 1e-14);
}

// K = 2, a = 0.6: the first sample's alpha is 1.2 (K a is not clamped), A = 1.2 >= 1 stops the ray:
// A = 1.2, C = 0.5 * 1.2. (Had it gone on, the second sample would give A = 1.2 + (1 - 1.2) 1.2 = 0.96.)
TEST(GlslBasicProfile, KOvershootsAndTheRayStops) {
    const glm::dvec4 p = pixel(box(constant_field(0.5, {5, 5, 5}), 0.6, 2.0));
    EXPECT_NEAR(p.a, 1.2, 1e-12);
    EXPECT_NEAR(p.r, 0.6, 1e-12);
}

// f = 0.1 z + 0.2 (v_k = 0.6 - 0.05 k at z = 4 - 0.5 k), a = 0.1: unshaded C = sum_k 0.9^k 0.1 v_k.
// Shaded with one-sided Lambert (ka 0, kd 1, ks 0) and a headlight from +z: getNormalFromVol's normal is
// +grad f = +z, so N.L = 1 and every shaded colour equals the unshaded one. (The contract's N = -grad f
// would give N.L = -1, max(., 0) = 0, and C = 0.)
TEST(GlslBasicProfile, NormalIsPlusGradient) {
    Scene s = box(linear_field({0, 0, 0.1, 0.2}, {5, 5, 5}), 0.1, 1.0);
    double C = 0.0;
    for (int k = 0; k < 9; ++k) C += std::pow(0.9, k) * 0.1 * (0.6 - 0.05 * k);
    EXPECT_NEAR(pixel(s).r, C, 1e-12);
    ShadingSpec sh;
    sh.ka = 0.0;
    sh.kd = 1.0;
    sh.ks = 0.0;
    sh.two_sided = false;
    s.volume().shading = sh;
    EXPECT_NEAR(pixel(s).r, C, 1e-12);
}

// render.profile_options: glsl-basic takes `intensity` only; cuda-curvilinear's keys are not its.
TEST(GlslBasicProfile, ProfileOptionsIntensity) {
    const std::string head = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [2, 2, 2]}},
                                 "render": {"profile": "glsl-basic", "profile_options": )";
    EXPECT_EQ(parse_scene(head + R"({"intensity": 3}}})", ".", "test").render.profile_options.intensity, 3.0);
    EXPECT_THROW(parse_scene(head + R"({"density": 3}}})", ".", "test"), Error);
    EXPECT_THROW(parse_scene(head + R"({"intensity": -1}}})", ".", "test"), Error);
}
