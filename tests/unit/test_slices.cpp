// Slice-order renderers (issue 54; core/integrate/profiles/Slices.h, FrameBuffer.h, ProfileSlices.cpp;
// conventions section 9, "Slice-order renderers"): the surfaces' levels and crossings against closed
// forms, the frame buffer's iterated rounding against the hand-iterated integer and float recurrences,
// spherical shells with correction against a ray caster at fixed distances from the eye, the table
// reads, pre-interpolation tables, the band against every rounding variant, and the refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "ComparedRender.h"
#include "TestScenes.h"
#include "core/Error.h"
#include "core/camera/Camera.h"
#include "core/compare/ConventionSearch.h"
#include "core/explain/Explain.h"
#include "core/integrate/profiles/FrameBuffer.h"
#include "core/integrate/profiles/Profile.h"
#include "core/integrate/profiles/Slices.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;
using nlohmann::json;

namespace {

// A constant box [0, 4] x [0, 4] x [0, depth] of value 1, colour white, opacity `a` everywhere (rows over
// [0, 1]); one pixel looking down -z through (2, 2); base volumizer, step 1 (world units).
Scene slab(double a, std::int64_t depth) {
    Scene s = field_scene(constant_field(1.0, {5, 5, depth + 1}));
    s.volume().transfer.color = {{0, 1, 1, 1}, {1, 1, 1, 1}};
    s.volume().transfer.opacity = {{0, a}, {1, a}};
    s.volume().transfer.opacity_unit_distance = 1.0;
    s.camera = ortho_down_z(2.0, 2.0, double(depth) + 10.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 1.0;
    s.render.step_units = StepUnits::World;
    s.render.profile = ProfileId::Volumizer;
    return s;
}

Scene with(Scene s, const json& rules) {
    s.render.profile_rules = parse_profile_rules(rules, s.render.profile, "test");
    return s;
}

glm::dvec4 pixel(const Scene& s) { return rgba(render_scene(s, {1, false}), 0, 0); }

std::string error_of(const Scene& s) {
    try {
        render_scene(s, {1, false});
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// The 8-bit blend by hand: R((q_s f_s + Q f_d) / 255), or R(q_s f_s / 255) + R(Q f_d / 255).
int blend8(int qs, int fs, int q, int fd, bool truncate, bool rounded) {
    auto R = [&](double x) { return int(truncate ? std::floor(x) : std::floor(x + 0.5)); };
    if (!rounded) return std::clamp(R((double(qs) * fs + double(q) * fd) / 255.0), 0, 255);
    return std::min(255, R(double(qs) * fs / 255.0) + R(double(q) * fd / 255.0));
}

}  // namespace

// Volumizer's frame buffer on n = depth + 1 slices of a constant white medium: src-alpha on R, G, B and A,
// every blend stored as an 8-bit code; the integer recurrence by hand, for each rounding variant.
TEST(Slices, ConstantMediumRgba8IsTheIteratedRounding) {
    for (int variant = 0; variant < 4; ++variant) {
        const bool truncate = variant & 1, rounded = variant & 2;
        const Scene s = with(slab(0.2, 15), {{"base", "volumizer"},
                                            {"framebuffer_rounding", truncate ? "truncate" : "nearest"},
                                            {"blend_products", rounded ? "rounded" : "exact"}});
        const int qa = truncate ? 51 : 51;  // 0.2 * 255 = 51 exactly
        int c = 0, a = 0;
        for (int k = 0; k < 16; ++k) {  // 16 planes: depths 10 .. 25 through a 15-deep box, both faces kept
            c = blend8(255, qa, c, 255 - qa, truncate, rounded);
            a = blend8(qa, qa, a, 255 - qa, truncate, rounded);
        }
        const glm::dvec4 p = pixel(s);
        EXPECT_EQ(p.r, c / 255.0) << variant;
        EXPECT_EQ(p.g, c / 255.0);
        EXPECT_EQ(p.a, a / 255.0) << variant;
    }
    // blend_alpha "one": A <- a + A (1 - a).
    int a = 0;
    for (int k = 0; k < 16; ++k) a = blend8(51, 255, a, 204, false, false);
    EXPECT_EQ(pixel(with(slab(0.2, 15), {{"blend_alpha", "one"}})).a, a / 255.0);
}

// c = 1, a = 1/255 (code 1), rounding to nearest: C stops at 128/255 after 128 slices and stays there
// (each blend adds round((255 - C) / 255), which is 0 from C = 128), while 1 - (254/255)^200 = 0.545.
TEST(Slices, EightBitStallAt128) {
    const Scene s = slab(1.0 / 255.0, 199);  // 200 slices
    EXPECT_EQ(pixel(s).r, 128.0 / 255.0);
    EXPECT_NEAR(pixel(with(s, {{"framebuffer", "double"}, {"table_format", "float"}, {"texture_format", "float"}})).r,
                1.0 - std::pow(254.0 / 255.0, 200), 1e-13);
    // The thin medium of Example 3-1 (L = A = 10/255): from 0 every blend adds round(100 / 255) = 0.
    Scene thin = slab(10.0 / 255.0, 255);
    thin.volume().transfer.color = {{0, 10 / 255.0, 10 / 255.0, 10 / 255.0}, {1, 10 / 255.0, 10 / 255.0, 10 / 255.0}};
    EXPECT_EQ(pixel(thin).r, 0.0);
}

// Float buffers: the blend in float32 (each product, 1 - a and the sum rounded), stored float32 or binary16.
TEST(Slices, FloatFrameBuffersByHand) {
    const double a = 0.3;
    const Scene s = with(slab(a, 15), {{"table_format", "float"}, {"texture_format", "float"}, {"framebuffer", "rgba32f"}});
    float c = 0.0f, al = 0.0f;
    const float fa = float(a), one_minus = 1.0f - fa;
    for (int k = 0; k < 16; ++k) {
        const float p1 = 1.0f * fa, p2 = c * one_minus;
        c = p1 + p2;
        const float q1 = fa * fa, q2 = al * one_minus;
        al = q1 + q2;
    }
    const glm::dvec4 p = pixel(s);
    EXPECT_EQ(p.r, double(c));
    EXPECT_EQ(p.a, double(al));
    // binary16 by hand: 1/3 = 0x3555, 0.1 = 0x2E66, 65519 -> 65504, 65520 -> inf, ties to even at 2^-25, 3 2^-25.
    EXPECT_EQ(framebuffer::to_half(1.0 / 3.0), 0.333251953125);
    EXPECT_EQ(framebuffer::to_half(0.1), 0.0999755859375);
    EXPECT_EQ(framebuffer::to_half(65519.0), 65504.0);
    EXPECT_TRUE(std::isinf(framebuffer::to_half(65520.0)));
    EXPECT_EQ(framebuffer::to_half(0x1p-25), 0.0);
    EXPECT_EQ(framebuffer::to_half(3 * 0x1p-25), 0x1p-23);
    EXPECT_EQ(framebuffer::to_half(1.0 + 0x1p-11), 1.0);  // a tie to even
    EXPECT_EQ(framebuffer::to_half(1.0 + 3 * 0x1p-11), 1.0 + 0x1p-9);
    const glm::dvec4 h = pixel(with(slab(a, 15), {{"table_format", "float"}, {"texture_format", "float"}, {"framebuffer", "rgba16f"}}));
    EXPECT_EQ(h.r, framebuffer::to_half(h.r));  // stored as binary16
    EXPECT_NEAR(h.r, 1.0 - std::pow(1.0 - a, 16), 16 * 0x1p-11);
}

namespace {

Profile slicer(const json& rules) {
    RenderSpec r;
    r.profile = ProfileId::Reference;
    r.profile_rules = parse_profile_rules(rules, ProfileId::Reference, "test");
    return resolve_profile(r);
}

CameraSpec ortho(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up = {0, 1, 0}) {
    CameraSpec c;
    c.type = CameraSpec::Type::Orthographic;
    c.eye = eye;
    c.target = target;
    c.up = up;
    c.height = 10;
    return c;
}

CameraSpec perspective(glm::dvec3 eye, glm::dvec3 target, double fov) {
    CameraSpec c;
    c.type = CameraSpec::Type::Perspective;
    c.eye = eye;
    c.target = target;
    c.up = {0, 1, 0};
    c.fov_y = fov;
    return c;
}

SliceLattice lattice(const json& rules, const CameraSpec& spec, glm::dvec3 lo, glm::dvec3 hi, double step = 1.0,
                     std::array<std::int64_t, 3> dims = {129, 129, 129}) {
    const Camera cam(spec, 64, 64, lo, hi);
    return make_slice_lattice(slicer(rules), cam, spec, lo, hi, lo, glm::dvec3(1.0), dims, step, 1.0);
}

}  // namespace

// Volumizer's samplingPeriod (L1259): (1, 1, 1) gives SIZE planes head on and sqrt(3) SIZE along the
// major diagonal; axis slices keep SIZE planes at any view (their face sets do not depend on it).
TEST(Slices, PeriodCountsHeadOnAndDiagonal) {
    const glm::dvec3 lo(0.0), hi(128.0);
    const json period = {{"placement", "slices"}, {"slices", {{"period", {1, 1, 1}}}}};
    EXPECT_EQ(lattice(period, ortho({64, 64, 400}, {64, 64, 64}), lo, hi).levels.size(), 128u);
    const SliceLattice diag = lattice(period, ortho({400, 400, 400}, {64, 64, 64}, {0, 0, 1}), lo, hi);
    EXPECT_EQ(diag.levels.size(), std::size_t(std::ceil(128.0 * std::sqrt(3.0))));  // 222
    json axis = period;
    axis["slices"]["orientation"] = "axis";
    EXPECT_EQ(lattice(axis, ortho({400, 400, 400}, {64, 64, 64}, {0, 0, 1}), lo, hi).levels.size(), 128u);
    // An anisotropic period along z: D = 1 / |diag(1 / p) w| = 2 head on.
    json aniso = period;
    aniso["slices"]["period"] = {1, 1, 2};
    EXPECT_EQ(lattice(aniso, ortho({64, 64, 400}, {64, 64, 64}), lo, hi).levels.size(), 64u);
    // count, bound: the first plane on the far bound, the last on the near one; half: centred.
    const SliceLattice bound = lattice({{"placement", "slices"}, {"slices", {{"count", 5}}}}, ortho({64, 64, 400}, {64, 64, 64}), lo, hi);
    ASSERT_EQ(bound.levels.size(), 5u);
    EXPECT_DOUBLE_EQ(bound.levels.front(), 400.0);  // the far face z = 0 at depth 400
    EXPECT_DOUBLE_EQ(bound.levels.back(), 272.0);   // the near face z = 128
    EXPECT_DOUBLE_EQ(bound.levels[1], 368.0);
    const SliceLattice half =
        lattice({{"placement", "slices"}, {"slices", {{"count", 4}, {"first", "half"}}}}, ortho({64, 64, 400}, {64, 64, 64}), lo, hi);
    EXPECT_DOUBLE_EQ(half.levels.front(), 400.0 - 16.0);
    EXPECT_DOUBLE_EQ(half.levels.back(), 272.0 + 16.0);
    // spacing: floor(E / s - o) + 1 levels from the far bound; max_count clamps.
    EXPECT_EQ(lattice({{"placement", "slices"}, {"slices", {{"spacing", 3}}}}, ortho({64, 64, 400}, {64, 64, 64}), lo, hi).levels.size(),
              43u);  // floor(128 / 3) + 1
    EXPECT_EQ(lattice({{"placement", "slices"}, {"slices", {{"spacing", 3}, {"first", "half"}}}}, ortho({64, 64, 400}, {64, 64, 64}), lo, hi)
                  .levels.size(),
              43u);  // floor(42.67 - 0.5) + 1
    EXPECT_EQ(lattice({{"placement", "slices"}, {"slices", {{"spacing", 1}, {"max_count", 10}}}}, ortho({64, 64, 400}, {64, 64, 64}), lo, hi)
                  .levels.size(),
              10u);
}

// Perspective viewport planes: a ray at angle theta to the axis crosses depth zeta_k at t_k = zeta_k / cos theta
// and stands for d = s / cos theta.
TEST(Slices, PerspectiveViewportCrossings) {
    const glm::dvec3 lo(0.0), hi(32.0), eye(16, 16, 100);
    const CameraSpec spec = perspective(eye, {16, 16, 16}, 40.0);
    const SliceLattice L = lattice({{"placement", "slices"}, {"slices", {{"spacing", 0.5}}}}, spec, lo, hi, 0.5);
    EXPECT_DOUBLE_EQ(L.levels.front(), 100.0);  // the far face z = 0
    const Camera cam(spec, 64, 64, lo, hi);
    const Ray r = cam.ray(3.5, 60.5);
    const double cos_theta = glm::dot(r.direction, glm::dvec3(0, 0, -1));
    for (std::size_t k : {std::size_t(0), std::size_t(17), L.levels.size() - 1}) {
        double t = 0.0, d = 0.0;
        ASSERT_TRUE(L.crossing(r, k, t, d));
        EXPECT_NEAR(t, (100.0 - 0.5 * double(k)) / cos_theta, 1e-12);
        EXPECT_NEAR(d, 0.5 / cos_theta, 1e-14);
    }
}

// Axis slices switch their axis at 45 degrees (ties: x first): the same count on both sides for a cube,
// planes perpendicular to x below 45 degrees from x, to z past it.
TEST(Slices, AxisSwitchAt45Degrees) {
    const glm::dvec3 lo(0.0), hi(64.0), c(32.0);
    const json axis = {{"placement", "slices"}, {"slices", {{"orientation", "axis"}}}};
    const double e = 1e-3;
    const SliceLattice x = lattice(axis, ortho(c + 100.0 * glm::dvec3(1.0, 0.0, 1.0 - e), c), lo, hi);
    const SliceLattice z = lattice(axis, ortho(c + 100.0 * glm::dvec3(1.0 - e, 0.0, 1.0), c), lo, hi);
    const SliceLattice tie = lattice(axis, ortho(c + glm::dvec3(100.0, 0.0, 100.0), c), lo, hi);
    EXPECT_EQ(x.axis, 0);
    EXPECT_EQ(z.axis, 2);
    EXPECT_EQ(tie.axis, 0);
    EXPECT_EQ(x.levels.size(), z.levels.size());
    EXPECT_EQ(x.levels.size(), 65u);
    // looking towards -x and -z: lambda = -x_a, the far bound the low face.
    EXPECT_DOUBLE_EQ(x.levels.front(), 0.0);
    EXPECT_DOUBLE_EQ(x.levels.back(), -64.0);
}

// Spherical shells with exact correction are a ray caster sampling at fixed distances k s from the eye:
// the centre ray of a constant slab crosses the shells lambda_k = b_far - k s that lie in its chord
// [t0, t1], each of alpha 1 - (1 - a)^(s / l): A = 1 - (1 - a)^(n s / l).
TEST(Slices, SphericalShellsWithCorrectionAreARayCasterAtFixedDistances) {
    Scene s = slab(0.05, 20);
    s.camera = CameraSpec{};
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {2.0, 2.0, 27.3};
    s.camera.target = {2.0, 2.0, 0.0};
    s.camera.up = {0, 1, 0};
    s.camera.fov_y = 1.0;
    s.render.profile = ProfileId::Reference;
    const double step = 0.7;
    s.render.step = step;
    const Scene sph = with(s, {{"base", "reference"},
                               {"placement", "slices"},
                               {"slices", {{"orientation", "spherical"}}},
                               {"correction", "exact"},
                               {"blend", "premultiplied"}});
    // b_far: the farthest corner of [0, 4]^2 x [0, 20] from the eye; the chord [27.3 - 20, 27.3].
    double b_far = 0.0;
    for (int i = 0; i < 8; ++i)
        b_far = std::max(b_far, glm::length(glm::dvec3(i & 1 ? 4 : 0, i & 2 ? 4 : 0, i & 4 ? 20 : 0) - s.camera.eye));
    int n = 0;
    for (int k = 0; b_far - k * step >= 7.3 - 1e-12; ++k)
        if (b_far - k * step <= 27.3) ++n;
    const glm::dvec4 p = pixel(sph);
    EXPECT_NEAR(p.a, 1.0 - std::pow(0.95, n * step), 1e-13);
    EXPECT_NEAR(p.r, p.a, 1e-13);  // white, premultiplied
}

// OpenGL's colour-table index round(s (N - 1)): s = (j +- 0.49) / 255 reads entry j; 0.51 past it, entry j + 1.
TEST(Slices, NearestTableReads) {
    for (int j : {0, 17, 128, 254}) {
        for (double f : {-0.49, 0.49, 0.51}) {
            const double v = std::clamp((j + f) / 255.0, 0.0, 1.0);
            Scene s = slab(0.0, 4);
            s.volume().source.field = constant_field(v, {5, 5, 5});
            s.volume().transfer.opacity = {{0, 0}, {1, 1}};  // a(v) = v: entry j has opacity j / 255
            s.render.step = 100.0;                             // one plane, on the far face
            const glm::dvec4 p = pixel(with(s, {{"base", "volumizer"}, {"texture_format", "float"}, {"table_format", "float"},
                                                {"texture_window", {0, 1}}, {"framebuffer", "double"}, {"blend_alpha", "one"}}));
            const int entry = std::min(255, f > 0.5 ? j + 1 : j);
            EXPECT_NEAR(p.a, entry / 255.0, 1e-15) << j << " " << f;
        }
    }
}

// Pre-interpolation tables (Volumizer's, not opacity-weighted): halfway between a voxel (c, a) = (1, 0)
// and one (0, 1), with a transfer function transparent at 0.5, post-classification gives 0 and the
// unweighted pre-interpolation (c, a) = (0.5, 0.5): C = c a = 0.25.
TEST(Slices, PreUnweightedAgainstPost) {
    Scene s = field_scene(linear_field({1, 0, 0, 0}, {2, 2, 2}));  // f = x on [0, 1]^3
    s.volume().transfer.color = {{0, 1, 1, 1}, {0.5, 0, 0, 0}, {1, 0, 0, 0}};
    s.volume().transfer.opacity = {{0, 0}, {0.5, 0}, {1, 1}};
    s.camera = ortho_down_z(0.5, 0.5, 10.0, 0.1);
    s.image.width = s.image.height = 1;
    s.render.step = 100.0;  // one plane at z = 0
    s.render.step_units = StepUnits::World;
    const json common = {{"placement", "slices"}, {"correction", "none"}, {"framebuffer", "double"}, {"texture_window", {0, 1}}};
    json pre = common;
    pre["classify"] = "pre-unweighted";
    EXPECT_NEAR(pixel(with(s, common)).r, 0.0, 1e-15);
    EXPECT_NEAR(pixel(with(s, pre)).r, 0.25, 1e-15);
    EXPECT_NEAR(pixel(with(s, pre)).a, 0.25, 1e-15);  // A = a a
}

// 2D textures: axis slices at the data's own layers, bilinear within the layer: each fragment's value is
// its layer's (f = z: exactly the layer index), the count the layers'.
TEST(Slices, TwoDimensionalTexturesReadTheLayers) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {5, 5, 9}));
    s.volume().transfer.color = {{0, 1, 1, 1}, {8, 1, 1, 1}};
    s.volume().transfer.opacity = {{0, 0.1}, {8, 0.1}};
    s.camera = ortho_down_z(2.0, 2.0, 30.0, 1.0);
    s.camera.eye = {2.3, 2.0, 30.0};
    s.camera.target = {2.0, 2.0, 0.0};  // oblique: the ray crosses the layers between voxel columns
    s.image.width = s.image.height = 1;
    s.render.step = 0.37;
    s.render.step_units = StepUnits::World;
    const Scene two = with(s, {{"placement", "slices"}, {"correction", "none"}, {"slices", {{"orientation", "axis"}}}, {"texture", "2d"},
                               {"framebuffer", "double"}, {"blend", "premultiplied"}});
    // 9 layers, each alpha 0.1 (no correction): A = 1 - 0.9^9.
    EXPECT_NEAR(pixel(two).a, 1.0 - std::pow(0.9, 9), 1e-14);
}

// The band covers every rounding variant of the frame buffer and both 8-bit texture units (exact weights,
// llvmpipe's fixed8): each variant's pixel lies within [pixel - band, pixel + band] on every channel.
TEST(Slices, FrameBufferBandCoversTheVariants) {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {17, 17, 17};
    Scene s = field_scene(ml);
    s.volume().transfer.color = {{0, 0.1, 0.3, 0.9}, {0.5, 0.9, 0.6, 0.1}, {1, 1, 1, 0.5}};
    s.volume().transfer.opacity = {{0, 0}, {0.4, 0.02}, {1, 0.3}};
    s.camera = perspective({30, -20, 40}, {8, 8, 8}, 30.0);
    s.image.width = s.image.height = 24;
    s.render.profile = ProfileId::Volumizer;
    s.render.step = 0.5;
    Scene banded = s;
    banded.render.profile_options.framebuffer_band = true;
    const Image base = render_scene(banded, {1, false});
    ASSERT_EQ(base.channel_count(), 5u);
    double largest = 0.0;
    for (const char* filter : {"exact", "fixed8"})
    for (const char* rounding : {"nearest", "truncate"})
        for (const char* products : {"exact", "rounded", "llvmpipe"}) {
            const Image v = render_scene(with(s, {{"base", "volumizer"}, {"framebuffer_rounding", rounding}, {"blend_products", products},
                                                  {"texture_filter", filter}}), {1, false});
            for (int y = 0; y < 24; ++y)
                for (int x = 0; x < 24; ++x) {
                    const double band = base.at(x, y, 4);
                    largest = std::max(largest, band);
                    for (std::size_t c = 0; c < 4; ++c)
                        EXPECT_LE(std::fabs(v.at(x, y, c) - base.at(x, y, c)), band + 1e-15) << rounding << products << x << "," << y;
                }
        }
    EXPECT_GT(largest, 1.0 / 255.0);  // the band is not zero where the variants differ
}

// The volumizer preset's rules, given back as render.profile, render the preset bit for bit.
TEST(Slices, PresetRulesRenderAsThePreset) {
    const Scene s = slab(0.3, 7);
    const json rules = profile_rules_json(profile(ProfileId::Volumizer));
    EXPECT_EQ(rules.at("placement"), "slices");
    EXPECT_EQ(rules.at("framebuffer"), "rgba8");
    EXPECT_EQ(pixel(with(s, rules)), pixel(s));
    Scene ref = s;
    ref.render.profile = ProfileId::Reference;
    EXPECT_EQ(pixel(with(ref, rules)), pixel(s));
}

// One line naming the key for what a slicer cannot honour.
TEST(Slices, Refusals) {
    const Scene s = slab(0.2, 7);
    EXPECT_NE(error_of(with(s, {{"slices", {{"orientation", "spherical"}}}})).find("render.profile.slices.orientation"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"slices", {{"range", "view_volume"}}}})).find("camera.near and camera.far"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"texture", "2d"}})).find("render.profile.texture"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"slices", {{"order", "front-to-back"}}}})).find("premultiplied"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"blend", "max"}})).find("render.profile.blend"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"slices", {{"spacing", 1e-12}}}})).find("per-ray sample limit"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"correction", "pow"}})).find("render.profile.correction"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"step_count", "before-exit"}})).find("render.profile.step_count"), std::string::npos);
    Scene mip = s;
    mip.render.projection = Projection::Mip;
    EXPECT_NE(error_of(mip).find("render.profile.blend"), std::string::npos);
    Scene ref = slab(0.2, 7);
    ref.render.profile = ProfileId::Reference;
    EXPECT_NE(error_of(with(ref, {{"framebuffer", "rgba8"}})).find("render.profile.framebuffer: applies to placement \"slices\""),
              std::string::npos);
    auto parse_error = [](const std::string& text) {
        try {
            parse_scene(text, ".", "scene");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const std::string head = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]}}, )";
    EXPECT_NE(parse_error(head + R"("render": {"profile": {"base": "volumizer", "slices": {"count": 4, "spacing": 1}}}})")
                  .find("render.profile.slices.count: set one of spacing, count and period"),
              std::string::npos);
    EXPECT_NE(parse_error(head + R"("render": {"profile": {"base": "volumizer", "texture_window": [1, 0]}}})").find("render.profile.texture_window"),
              std::string::npos);
    EXPECT_NE(parse_error(head + R"("camera": {"type": "perspective", "near": 2}, "render": {"profile": "volumizer"}})").find("camera.near"),
              std::string::npos);
    EXPECT_NE(parse_error(head + R"("camera": {"type": "perspective", "near": 2, "far": 1}, "render": {"profile": "volumizer"}})")
                  .find("camera.far: must exceed near"),
              std::string::npos);
}

// camera.near / far: range view_volume places the planes from far to near in eye depth, and the depth
// test drops the fragments outside [near, far].
TEST(Slices, ViewVolumeRangeAndDepthClip) {
    Scene s = slab(0.1, 15);  // the box at depths [10, 25]
    s.render.step = 1.0;
    s.camera.near = 12.0;
    s.camera.far = 20.5;
    // levels 20.5, 19.5, ..., 12.5: 9 planes, all inside the box.
    const glm::dvec4 p = pixel(with(s, {{"slices", {{"range", "view_volume"}}}, {"framebuffer", "double"}, {"table_format", "float"},
                                        {"texture_format", "float"}, {"blend_alpha", "one"}}));
    EXPECT_NEAR(p.a, 1.0 - std::pow(0.9, 9), 1e-14);
    // object range, clipped: levels 25, 24, ..., 10; kept 20 .. 12: 9 planes.
    const glm::dvec4 q = pixel(with(s, {{"framebuffer", "double"}, {"table_format", "float"}, {"texture_format", "float"}, {"blend_alpha", "one"}}));
    EXPECT_NEAR(q.a, 1.0 - std::pow(0.9, 9), 1e-14);
}

// explain composite --framebuffer: each row's stored codes are the hand recurrence's, the exact column
// (q_s f_s + Q f_d) / 255 before the rounding.
TEST(Slices, ExplainWorksAnEightBitBlend) {
    const std::vector<explain::CompositeSample> samples{{{1.0, 0.5, 0.0}, 0.4}, {{0.2, 1.0, 1.0}, 0.1}, {{1.0, 1.0, 1.0}, 0.75}};
    const explain::Explanation e = explain::composite_framebuffer(samples, CompositeOrder::BackToFront, explain::FrameBufferRules{});
    const explain::Section& t = e.sections.at(1);
    ASSERT_EQ(t.rows.size(), 3u);
    int c = 0, a = 0;
    for (std::size_t j = 0; j < 3; ++j) {
        const explain::CompositeSample& x = samples[2 - j];  // far first
        const int qa = int(std::floor(255.0 * x.opacity + 0.5)), qc = int(std::floor(255.0 * x.color.r + 0.5));
        EXPECT_DOUBLE_EQ(t.rows[j][5], (double(qc) * qa + double(c) * (255 - qa)) / 255.0);
        c = blend8(qc, qa, c, 255 - qa, false, false);
        a = blend8(qa, qa, a, 255 - qa, false, false);
        EXPECT_EQ(t.rows[j][9], double(c));
        EXPECT_EQ(t.rows[j][12], double(a));
    }
}

// --fit --scene names a slicer's orientation, frame buffer and correction on an image volref rendered
// with them (the real slicer's images: tests/gpu/slicing).
TEST(Slices, ConventionSearchNamesTheSlicingRules) {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {17, 17, 17};
    Scene s = field_scene(ml);
    s.volume().transfer.color = {{0, 0.1, 0.3, 0.9}, {1, 1, 0.8, 0.2}};
    s.volume().transfer.opacity = {{0, 0}, {0.3, 0.0}, {1, 0.35}};
    s.camera = perspective({34, -12, 30}, {8, 8, 8}, 30.0);
    s.image.width = s.image.height = 20;
    s.render.profile = ProfileId::Volumizer;
    s.render.step = 0.75;
    auto other = [&](const json& rules) { return compared_image(render_scene(with(s, rules), {0, false})); };
    const compare::SearchResult r = compare::search_conventions(
        other({{"slices", {{"orientation", "axis"}}}, {"framebuffer", "rgba32f"}, {"correction", "exact"}}), s);
    EXPECT_TRUE(r.explained) << r.verdict;
    EXPECT_EQ(r.best.rules.value("slices.orientation", ""), "axis") << r.best.rules.dump();
    EXPECT_EQ(r.best.rules.value("framebuffer", ""), "rgba32f") << r.best.rules.dump();
    EXPECT_EQ(r.best.rules.value("correction", ""), "exact") << r.best.rules.dump();
}

// for_each_crossing visits exactly the levels a loop over all of them keeps (it looks only at the levels
// the chord can reach), in order, for every orientation, on random rays.
TEST(Slices, CrossingsEqualABruteForceLoop) {
    const glm::dvec3 lo(0.0), hi(20.0, 12.0, 16.0);
    std::uint64_t seed = 12345;
    auto uniform = [&]() {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        return double(seed >> 11) * 0x1p-53;
    };
    for (const char* orientation : {"viewport", "axis", "spherical"})
        for (const char* order : {"back-to-front", "front-to-back"}) {
            const CameraSpec spec = perspective({31, -17, 29}, {10, 6, 8}, 50.0);
            const SliceLattice L = lattice({{"placement", "slices"}, {"slices", {{"orientation", orientation}, {"spacing", 0.37}, {"order", order}}}},
                                           spec, lo, hi, 0.37);
            const Camera cam(spec, 64, 64, lo, hi);
            std::size_t total = 0;
            for (int i = 0; i < 200; ++i) {
                const Ray r = cam.ray(64.0 * uniform(), 64.0 * uniform());
                const double t0 = 20.0 + 20.0 * uniform();
                const std::vector<Interval> iv{{t0, t0 + 3.0 * uniform()}, {t0 + 4.0, t0 + 4.0 + 10.0 * uniform()}};
                std::vector<std::size_t> seen, expected;
                L.for_each_crossing(r, iv, [&](double, double, std::size_t k) {
                    seen.push_back(k);
                    return true;
                });
                for (std::size_t j = 0; j < L.levels.size(); ++j) {
                    const std::size_t k = std::string(order) == "back-to-front" ? j : L.levels.size() - 1 - j;
                    double t = 0.0, d = 0.0;
                    if (!L.crossing(r, k, t, d) || t < 0.0) continue;
                    for (const Interval& x : iv)
                        if (t >= x.t0 && t <= x.t1) {
                            expected.push_back(k);
                            break;
                        }
                }
                ASSERT_EQ(seen, expected) << orientation << " " << order << " ray " << i;
                total += expected.size();
            }
            EXPECT_GT(total, 1000u) << orientation;
        }
}

// GL_MAX (the mip projection): per channel the largest fragment, not (a c, a) at the largest value: a
// colour ramp falling as the opacity rises gives the colour of the nearest slice and the alpha of the
// farthest. f = z on [0, 4], 5 planes at z = 4, 3, ..., 0 (far first from the eye looking up +z).
TEST(Slices, MaxBlendIsPerChannel) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {5, 5, 5}));
    s.volume().transfer.color = {{0, 1, 1, 1}, {4, 0, 0, 0}};
    s.volume().transfer.opacity = {{0, 0}, {4, 1}};
    s.camera = ortho_down_z(2.0, 2.0, 14.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 1.0;
    s.render.step_units = StepUnits::World;
    s.render.projection = Projection::Mip;
    s.render.profile = ProfileId::Volumizer;
    const glm::dvec4 p = pixel(with(s, {{"blend", "max"}, {"texture_format", "float"}, {"table_format", "float"}, {"table_lookup", "linear"},
                                        {"framebuffer", "double"}}));
    EXPECT_NEAR(p.r, 1.0, 1e-15);  // the slice at z = 0: colour 1, opacity 0
    EXPECT_NEAR(p.a, 1.0, 1e-15);  // the slice at z = 4: colour 0, opacity 1
    const glm::dvec4 q = pixel(with(s, {{"blend", "max"}}));  // 8-bit: the same codes
    EXPECT_EQ(q.r, 1.0);
    EXPECT_EQ(q.a, 1.0);
}

// Mesa's llvmpipe (measured by tests/gpu/slicing/gl_probe on the real program): its 8-bit product
// (t + (t >> 8) + 128) >> 8 is round(t / 255) but for 24 pairs of codes, all >= 152, one less.
TEST(Slices, LlvmpipeProductsByHand) {
    int differ = 0;
    for (int a = 0; a < 256; ++a)
        for (int b = 0; b < 256; ++b) {
            const double p = framebuffer::llvmpipe_product(a, b), r = std::floor(a * b / 255.0 + 0.5);
            if (p != r) {
                ++differ;
                EXPECT_EQ(p, r - 1.0);
                EXPECT_GE(std::min(a, b), 152);
            }
        }
    EXPECT_EQ(differ, 24);
    EXPECT_EQ(framebuffer::llvmpipe_product(152, 229), 136.0);
    // binary16 toward zero: 1/3 -> 0x3555 (below), 0.1 -> 0x2E66 (below), 1 + 3 2^-11 -> 1 + 2^-10.
    EXPECT_EQ(framebuffer::to_half_toward_zero(1.0 / 3.0), 0.333251953125);
    EXPECT_EQ(framebuffer::to_half_toward_zero(1.0 + 3 * 0x1p-11), 1.0 + 0x1p-10);
    EXPECT_EQ(framebuffer::to_half_toward_zero(-(1.0 + 3 * 0x1p-11)), -(1.0 + 0x1p-10));
}

// texture_filter "fixed8": llvmpipe's 8-bit filter. Texels 0 and 255 on an axis of 2, read at index 0.3:
// x = float(0.8 / 2), i = rint(256 * 2 x) - 128 = 205 - 128 = 77, s = (0 + ((77 * 255 + 128) >> 8)) / 255
// = 77 / 255, where the exact filter gives 0.3.
TEST(Slices, Fixed8FilterByHand) {
    Scene s = field_scene(linear_field({1, 0, 0, 0}, {2, 2, 2}));  // f = x on [0, 1]^3
    s.volume().transfer.color = {{0, 1, 1, 1}, {1, 1, 1, 1}};
    s.volume().transfer.opacity = {{0, 0}, {1, 1}};
    s.camera = ortho_down_z(0.3, 0.5, 10.0, 0.01);
    s.image.width = s.image.height = 1;
    s.render.step = 100.0;  // one plane at z = 0
    s.render.step_units = StepUnits::World;
    const json rules = {{"placement", "slices"}, {"correction", "none"}, {"framebuffer", "double"}, {"texture_format", "unorm8"},
                        {"texture_window", {0, 1}}, {"blend_alpha", "one"}};
    json fixed = rules;
    fixed["texture_filter"] = "fixed8";
    EXPECT_NEAR(pixel(with(s, rules)).a, 0.3, 1e-12);
    EXPECT_EQ(pixel(with(s, fixed)).a, 77.0 / 255.0);
    json bad = fixed;
    bad["texture_format"] = "float";
    EXPECT_NE(error_of(with(s, bad)).find("render.profile.texture_filter"), std::string::npos);
}

// fixed8's table read takes llvmpipe's coordinate fl(k fl(1/255)) (gl_probe's texel8 check on the real
// program): for k = 127 on 256 entries read "texture", 65536 fl(127 fl(1/255)) is the tie 32639.5, which
// rounds to even: entry 127 with weight 0 (the correctly rounded 127 / 255 gives entry 126, weight 255).
// Entries 126 and 127 are opacity 0 and 1: llvmpipe's pixel is 1, the other reading 254 / 255.
TEST(Slices, Fixed8TableCoordinateIsLlvmpipes) {
    Scene s = slab(0.0, 4);
    s.volume().source.field = constant_field(127.0 / 255.0, {5, 5, 5});
    s.volume().transfer.opacity = {{0, 0}, {126.0 / 255.0, 0}, {127.0 / 255.0, 1}, {1, 1}};
    s.render.step = 100.0;  // one plane
    const glm::dvec4 p = pixel(with(s, {{"base", "volumizer"}, {"texture_filter", "fixed8"}, {"table_lookup", "texture"},
                                        {"texture_window", {0, 1}}, {"framebuffer", "double"}, {"blend_alpha", "one"}}));
    EXPECT_EQ(p.a, 1.0);
}
