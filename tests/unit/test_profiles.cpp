// Mirror profiles (render.profile, core/integrate/profiles/Profile.h) against hand calculations: a constant or
// linear box seen along -z by one orthographic pixel, each profile's formula worked out below.
#include <gtest/gtest.h>

#include <cmath>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/render/PreparedScene.h"

using namespace volref;
using namespace volref::test;

namespace {

// A box [0, n-1]^3 of value v, one pixel looking along -z at (cx, cy): the chord is n - 1 long.
Scene box_scene(ProfileId profile, double value, double opacity, std::int64_t n, double step) {
    Scene s = field_scene(constant_field(value, {n, n, n}));
    s.volume().transfer.color = {{0, 0.2, 0.4, 0.6}, {1, 0.2, 0.4, 0.6}};
    s.volume().transfer.opacity = {{0, opacity}, {1, opacity}};
    s.volume().transfer.opacity_unit_distance = 1.0;
    const double c = 0.5 * double(n - 1);
    s.camera = ortho_down_z(c, c, double(n) + 10.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = step;
    s.render.step_units = StepUnits::World;
    s.render.profile = profile;
    return s;
}

double alpha_of(ProfileId profile, double value, double opacity, std::int64_t n, double step) {
    return rgba(render_scene(box_scene(profile, value, opacity, n, step), {1, false}), 0, 0).a;
}


}  // namespace

// Chord 4, step 0.5, a = 0.1 per unit distance.
//   vtk-gpu: samples at 0.5, 1.0, ..., 4.0 (8; the first one step inside), each 1 - 0.9^0.5
//            (the table entry corrected for the step): A = 1 - 0.9^4.
//   glsl-basic: samples at 0, 0.5, ..., 4.0 (9), each alpha 0.1 uncorrected: A = 1 - 0.9^9.
//   ospray: 8 midpoints, each 1 - exp(-0.1 * 0.5): A = 1 - exp(-0.4).
//   reference: 8 segments, each 1 - 0.9^0.5: A = 1 - 0.9^4.
TEST(Profiles, ConstantBoxCompositeByHand) {
    EXPECT_NEAR(alpha_of(ProfileId::VtkGpu, 0.5, 0.1, 5, 0.5), 1.0 - std::pow(0.9, 4), 1e-12);
    EXPECT_NEAR(alpha_of(ProfileId::GlslBasic, 0.5, 0.1, 5, 0.5), 1.0 - std::pow(0.9, 9), 1e-12);
    EXPECT_NEAR(alpha_of(ProfileId::Ospray, 0.5, 0.1, 5, 0.5), 1.0 - std::exp(-0.4), 1e-12);
    EXPECT_NEAR(alpha_of(ProfileId::Reference, 0.5, 0.1, 5, 0.5), 1.0 - std::pow(0.9, 4), 1e-12);
    // The colour is premultiplied: C = A c, with glsl-basic's c = (v, v, v) (seed 002's
    // textureValue.rrr, issue 17), not the transfer function's (0.2, 0.4, 0.6).
    const glm::dvec4 p = rgba(render_scene(box_scene(ProfileId::GlslBasic, 0.5, 0.1, 5, 0.5), {1, false}), 0, 0);
    EXPECT_NEAR(p.g, 0.5 * (1.0 - std::pow(0.9, 9)), 1e-12);
}

// Termination. vtk-gpu, a = 0.9, step 0.5: each sample 1 - 0.1^0.5, A_k = 1 - 0.1^(k/2); A_4 = 0.99 <=
// 1 - 1/255 = 0.99608 < A_5 = 1 - 0.1^2.5: it stops after 5 samples (the chord of 4 holds 8).
// ospray, a = 1, step 0.5, chord 16: T_k = exp(-k / 2) <= 0.001 first at k = 14: A = 1 - exp(-7).
// glsl-basic, a = 1: the first sample is opaque: A = 1.
TEST(Profiles, TerminationThresholdsByHand) {
    EXPECT_NEAR(alpha_of(ProfileId::VtkGpu, 0.5, 0.9, 5, 0.5), 1.0 - std::pow(0.1, 2.5), 1e-12);
    EXPECT_NEAR(alpha_of(ProfileId::Ospray, 0.5, 1.0, 17, 0.5), 1.0 - std::exp(-7.0), 1e-12);
    EXPECT_EQ(alpha_of(ProfileId::GlslBasic, 0.5, 1.0, 5, 0.5), 1.0);
}

// vtk-gpu's MIP on f = z seen from above: the first sample is one step inside, at z = 3.5 (the
// reference's first midpoint is at z = 3.75). Its opacity is read from the 1024-entry table built at
// v_j = 4 j / 1023 (a_j = j / 1023) at texel position s 1024 - 0.5, s = 3.5 / 4: a = 895.5 / 1023,
// uncorrected (MIP). MinIP: the last sample at z = 0 (s = 0, texel -0.5 clamped to 0): a = 0.
TEST(Profiles, VtkGpuMipReadsTheTableAtTexelCentres) {
    const glm::dvec4 mip = rgba(render_scene(ramp_scene(ProfileId::VtkGpu, Projection::Mip), {1, false}), 0, 0);
    EXPECT_NEAR(mip.a, (0.875 * 1024.0 - 0.5) / 1023.0, 1e-12);
    EXPECT_NEAR(mip.r, mip.a, 1e-12);
    const glm::dvec4 minip = rgba(render_scene(ramp_scene(ProfileId::VtkGpu, Projection::Minip), {1, false}), 0, 0);
    EXPECT_NEAR(minip.a, 0.0, 1e-12);
    const glm::dvec4 ref = rgba(render_scene(ramp_scene(ProfileId::Reference, Projection::Mip), {1, false}), 0, 0);
    EXPECT_NEAR(ref.a, 3.75 / 4.0, 1e-12);
}

// vtk-gpu's average: the mean over its 8 samples (z = 3.5, 3.0, ..., 0) of a(v) s, with s = v / 4
// and a(v) the table read at s 1024 - 0.5 (clamped at 0): grey, alpha 1.
TEST(Profiles, VtkGpuAverageIsOpacityWeightedByHand) {
    double sum = 0.0;
    for (int k = 1; k <= 8; ++k) {
        const double s = (4.0 - 0.5 * k) / 4.0;
        const double a = std::max(0.0, s * 1024.0 - 0.5) / 1023.0;
        sum += a * s;
    }
    const glm::dvec4 p = rgba(render_scene(ramp_scene(ProfileId::VtkGpu, Projection::Average), {1, false}), 0, 0);
    EXPECT_NEAR(p.r, sum / 8.0, 1e-12);
    EXPECT_EQ(p.a, 1.0);
}

TEST(Profiles, UnsupportedCombinationsNameTheKey) {
    Scene s = ramp_scene(ProfileId::VtkGpu, Projection::FirstHit);
    s.render.isovalue = 1.0;
    try {
        render_scene(s, {1, false});
        FAIL() << "first-hit with a profile rendered";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("render.profile"), std::string::npos) << e.what();
    }
}

// `volref trace` with a profile: the glsl-basic box of ConstantBoxCompositeByHand has 9 samples at
// t0, t0 + 0.5, ..., each alpha 0.1; after sample k, A = 1 - 0.9^(k+1); the last row is the pixel.
TEST(Profiles, TraceRecordsTheProfilesSamples) {
    const Scene s = box_scene(ProfileId::GlslBasic, 0.5, 0.1, 5, 0.5);
    const PreparedScene prepared(s, {1, false});
    SampleList list;
    const PixelValue traced = prepared.trace_pixel(0, 0, list);
    ASSERT_EQ(list.rows.size(), 9u);
    for (std::size_t k = 0; k < list.rows.size(); ++k) {
        EXPECT_NEAR(list.rows[k].t - list.rows[0].t, 0.5 * double(k), 1e-12);
        EXPECT_NEAR(list.rows[k].alpha, 0.1, 1e-15);
        EXPECT_NEAR(list.rows[k].accumulated.a, 1.0 - std::pow(0.9, double(k + 1)), 1e-12);
    }
    EXPECT_NEAR(list.rows[0].sample.position.z, 4.0, 1e-12);  // the first sample at the entry (z = 4)
    const PixelValue rendered = prepared.render_pixel(0, 0);
    EXPECT_EQ(traced.rgba, rendered.rgba);
    EXPECT_EQ(list.rows.back().accumulated, rendered.rgba);
}

// cuda-curvilinear on the constant box (dims 5, chord 4), step 0.5625 voxel: a voxel is size / n =
// 4 / 5, so h = 0.45 and the samples lie at 0, 0.45, ..., 3.6 (9). Each lerps sum towards
// col = (0.2, 0.4, 0.6, 0.1) by w = 0.1 * density = 0.2: sum = col (1 - 0.8^9).
TEST(Profiles, CudaCurvilinearConstantBoxByHand) {
    Scene s = box_scene(ProfileId::CudaCurvilinear, 0.5, 0.1, 5, 0.5625);
    s.render.step_units = StepUnits::Voxel;
    s.render.profile_options.density = 2.0;
    const glm::dvec4 p = rgba(render_scene(s, {1, false}), 0, 0);
    const double f = 1.0 - std::pow(0.8, 9);
    EXPECT_NEAR(p.r, 0.2 * f, 1e-12);
    EXPECT_NEAR(p.b, 0.6 * f, 1e-12);
    EXPECT_NEAR(p.a, 0.1 * f, 1e-12);
}

// cuda-curvilinear on f = z (opacity a = v / 4 = s), step 0.5 world: samples at z = 4, 3.5, ..., 0.
// Iso threshold 0.5 keeps s = 1, 0.875, 0.75, 0.625, 0.5. The 9-entry table holds a_j = j / 8 and is
// read at 9 s - 0.5 (clamped to [0, 8]): a = 1, 0.921875, 0.78125, 0.640625, 0.5. Back to front
// (from s = 0.5), density 0.5: w = a / 2, R = lerp(R, 1, w) (white), A = lerp(A, a, w).
// X-ray: brightness times the largest s (1, at the entry).
TEST(Profiles, CudaCurvilinearIsoThresholdAndXrayByHand) {
    Scene s = ramp_scene(ProfileId::CudaCurvilinear, Projection::Composite);
    s.render.profile_options.iso_threshold = 0.5;
    s.render.profile_options.density = 0.5;
    const glm::dvec4 p = rgba(render_scene(s, {1, false}), 0, 0);
    double R = 0.0, A = 0.0;
    for (double a : {0.5, 0.640625, 0.78125, 0.921875, 1.0}) {
        R = R + (1.0 - R) * (0.5 * a);
        A = A + (a - A) * (0.5 * a);
    }
    EXPECT_NEAR(p.r, R, 1e-12);
    EXPECT_NEAR(p.a, A, 1e-12);
    Scene x = ramp_scene(ProfileId::CudaCurvilinear, Projection::Xray);
    x.render.profile_options.brightness = 0.7;
    EXPECT_NEAR(rgba(render_scene(x, {1, false}), 0, 0).r, 0.7, 1e-12);
}
