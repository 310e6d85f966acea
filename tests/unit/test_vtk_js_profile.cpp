// The vtk-js profile (issue 22; core/integrate/profiles/VtkJsIntegrator.h) against hand calculations:
// one orthographic pixel looking along -z through a constant or linear box. The real vtk.js images are
// the ctest test `vtkjs_parity` (tests/gpu/web/).
#include <gtest/gtest.h>

#include <cmath>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;

namespace {

// A constant box, dims n^3 and spacing 1 (domain [0, n-1]^3, texel box [-0.5, n-0.5]^3), colour 0.5,
// opacity a0 everywhere; one pixel looking along -z at (x, y); step h (world), unit distance 1.
Scene box(double a0, std::int64_t n, double h, double x, double y) {
    Scene s = field_scene(constant_field(0.5, {n, n, n}));
    s.volume().transfer.color = {{0, 0.5, 0.5, 0.5}, {1, 0.5, 0.5, 0.5}};
    s.volume().transfer.opacity = {{0, a0}, {1, a0}};
    s.volume().transfer.opacity_unit_distance = 1.0;
    s.camera = ortho_down_z(x, y, double(n) + 10.0, 0.01);
    s.image.width = s.image.height = 1;
    s.render.step = h;
    s.render.step_units = StepUnits::World;
    s.render.profile = ProfileId::VtkJs;
    return s;
}

glm::dvec4 pixel(const Scene& s) { return rgba(render_scene(s, {1, false}), 0, 0); }

// The 8-bit colour table entry of 0.5: Uint8ClampedArray(127.5) rounds half to even: 128.
constexpr double kHalf8 = 128.0 / 255.0;

}  // namespace

// Equal samples: T = (1-a)^j (1-a)^m (1-a)^(R-j-m) = (1-a)^R whatever the jitter, a = 1-(1-a0)^h, R = chord / h
// with the chord the texel box's n = 8 (not the domain's 7).
TEST(VtkJsProfile, ConstantBoxTransmittanceOverTheTexelBox) {
    for (double j : {1.0, 0.37, 0.01}) {
        Scene s = box(0.05, 8, 0.5, 3.5, 3.5);
        s.render.profile_options.jitter = j;
        const glm::dvec4 p = pixel(s);
        const double a = double(float(1.0 - std::pow(1.0 - double(float(0.05)), 0.5)));  // the float table entry
        const double A = 1.0 - std::pow(1.0 - a, 8.0 / 0.5);
        EXPECT_NEAR(p.a, A, 1e-12) << "jitter " << j;
        EXPECT_NEAR(p.r, kHalf8 * A, 1e-12) << "jitter " << j;
    }
}

// ray_box "domain" (a convention compare --fit tries): the chord is 7.
TEST(VtkJsProfile, DomainRayBoxOption) {
    Scene s = box(0.05, 8, 0.5, 3.5, 3.5);
    s.render.profile_options.ray_box_domain = true;
    const double a = double(float(1.0 - std::pow(1.0 - double(float(0.05)), 0.5)));
    EXPECT_NEAR(pixel(s).a, 1.0 - std::pow(1.0 - a, 7.0 / 0.5), 1e-12);
}

// A ray through the half-voxel margin (x = -0.25: outside the domain, inside the texel box) reads the
// boundary (CLAMP_TO_EDGE) over the whole chord of 8.
TEST(VtkJsProfile, TheMarginOutsideTheDomainIsRendered) {
    const glm::dvec4 p = pixel(box(0.05, 8, 0.5, -0.25, 3.5));
    const double a = double(float(1.0 - std::pow(1.0 - double(float(0.05)), 0.5)));
    EXPECT_NEAR(p.a, 1.0 - std::pow(1.0 - a, 16.0), 1e-12);
    EXPECT_EQ(pixel(box(0.05, 8, 0.5, -0.75, 3.5)), glm::dvec4(0.0));  // outside the texel box: background
}

// Termination: a = 0.8 (h = l = 1): A = 0.8, 0.96, 0.992 > 0.99 -> A = 1 with C = 0.992 c (the rest of
// the colour never added).
TEST(VtkJsProfile, TerminationSetsAlphaOneWithoutTheRestOfTheColour) {
    const glm::dvec4 p = pixel(box(0.8, 8, 1.0, 3.5, 3.5));
    const double a = double(float(0.8));
    const double A3 = 1.0 - std::pow(1.0 - a, 3.0);
    EXPECT_EQ(p.a, 1.0);
    EXPECT_NEAR(p.r, kHalf8 * A3, 1e-12);
}

// Zero opacity: vtk.js writes (C / A, A) = (0 / 0, 0) into a float framebuffer: NaN colour.
TEST(VtkJsProfile, ZeroAlphaIsNaNInTheFloatFramebuffer) {
    const glm::dvec4 p = pixel(box(0.0, 8, 0.5, 3.5, 3.5));
    EXPECT_TRUE(std::isnan(p.r) && std::isnan(p.g) && std::isnan(p.b));
    EXPECT_EQ(p.a, 0.0);
}

// Samples whose table alpha is below 0.001 are dropped: a0 = 0.0015 at h = 0.5 gives 7.5e-4 (dropped: NaN
// pixel); a0 = 0.0025 gives 1.25e-3 (kept).
TEST(VtkJsProfile, AlphaBelowOneThousandthIsDropped) {
    EXPECT_EQ(pixel(box(0.0015, 8, 0.5, 3.5, 3.5)).a, 0.0);
    const double a = double(float(1.0 - std::pow(1.0 - double(float(0.0025)), 0.5)));
    EXPECT_NEAR(pixel(box(0.0025, 8, 0.5, 3.5, 3.5)).a, 1.0 - std::pow(1.0 - a, 16.0), 1e-12);
}

// MIP reads the corrected opacity table: alpha = 1 - (1 - a0)^(h / l); mip_correction false: a0.
TEST(VtkJsProfile, MipUsesTheCorrectedOpacity) {
    Scene s = box(0.4, 8, 0.25, 3.5, 3.5);
    s.render.projection = Projection::Mip;
    const double a = double(float(1.0 - std::pow(1.0 - double(float(0.4)), 0.25)));
    glm::dvec4 p = pixel(s);
    EXPECT_NEAR(p.a, a, 1e-12);
    EXPECT_NEAR(p.r, kHalf8 * a, 1e-12);
    s.render.profile_options.mip_correction = false;
    EXPECT_NEAR(pixel(s).a, double(float(0.4)), 1e-12);
}

// Shading: f = x + y on dims (8, 4, 6), spacing 1: the gradient (1, 1, 0); vtk.js multiplies it by
// diag(dims * spacing) = (8, 4, 6): N = (8, 4, 0) / sqrt(80); fixed_normal: (1, 1, 0) / sqrt(2). A directional
// light towards -x travels along +x: N.L = N_x; V = +z is perpendicular to R (no specular). Shaded colour
// c (kd N_x + ka), constant along the ray, so C = shaded A.
TEST(VtkJsProfile, ShippedNormalIsScaledByTheExtent) {
    Scene s = field_scene(linear_field({1, 1, 0, 0}, {8, 4, 6}));
    s.volume().transfer.color = {{0, 0.5, 0.5, 0.5}, {10, 0.5, 0.5, 0.5}};
    s.volume().transfer.opacity = {{0, 0.1}, {10, 0.1}};
    ShadingSpec sh;
    sh.ka = 0.2;
    sh.kd = 0.7;
    sh.ks = 0.5;
    s.volume().shading = sh;
    LightSpec l;
    l.type = LightSpec::Type::Directional;
    l.direction = glm::dvec3(-1.0, 0.0, 0.0);
    s.lights = {l};
    s.camera = ortho_down_z(3.5, 1.5, 20.0, 0.01);
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    s.render.profile = ProfileId::VtkJs;
    const double a = double(float(1.0 - std::pow(1.0 - double(float(0.1)), 0.5)));
    const double A = 1.0 - std::pow(1.0 - a, 6.0 / 0.5);  // the texel box's z chord: 6
    glm::dvec4 p = pixel(s);
    EXPECT_NEAR(p.a, A, 1e-12);
    EXPECT_NEAR(p.r, kHalf8 * (0.7 * 8.0 / std::sqrt(80.0) + 0.2) * A, 1e-9);
    s.render.profile_options.fixed_normal = true;
    EXPECT_NEAR(pixel(s).r, kHalf8 * (0.7 / std::sqrt(2.0) + 0.2) * A, 1e-9);
    // Flipped: N.L < 0 under one-sided lighting: ambient only; two-sided: |N.L| again.
    s.render.profile_options.flip_normal = true;
    EXPECT_NEAR(pixel(s).r, kHalf8 * 0.2 * A, 1e-9);
    s.volume().shading->two_sided = true;
    EXPECT_NEAR(pixel(s).r, kHalf8 * (0.7 / std::sqrt(2.0) + 0.2) * A, 1e-9);
}

TEST(VtkJsProfile, SceneOptionsAndErrors) {
    const std::string base = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]},
        "transfer": {"color": [[0, 1, 1, 1], [2, 1, 1, 1]], "opacity": [[0, 0.1], [2, 0.1]]}},
        "camera": {"type": "orthographic", "eye": [1.5, 1.5, 10], "target": [1.5, 1.5, 0], "up": [0, 1, 0], "height": 4},
        "image": {"width": 2, "height": 2}, "render": {"profile": "vtk-js")";
    const Scene s = parse_scene(base + R"(, "profile_options": {"jitter": 0.5, "fixed_normal": true, "ray_box": "domain"}}})",
                                ".", "s.json");
    EXPECT_EQ(s.render.profile_options.jitter, 0.5);
    EXPECT_TRUE(s.render.profile_options.fixed_normal);
    EXPECT_TRUE(s.render.profile_options.ray_box_domain);
    EXPECT_THROW(parse_scene(base + R"(, "profile_options": {"jitter": 0}}})", ".", "s.json"), Error);
    EXPECT_THROW(parse_scene(base + R"(, "profile_options": {"density": 1}}})", ".", "s.json"), Error);
    // One colour row: vtk.js divides by the node range's width.
    const std::string one_row = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]},
        "transfer": {"color": [[0, 1, 1, 1]], "opacity": [[0, 0.1], [2, 0.1]]}},
        "camera": {"type": "orthographic", "eye": [1.5, 1.5, 10], "target": [1.5, 1.5, 0], "up": [0, 1, 0], "height": 4},
        "image": {"width": 2, "height": 2}, "render": {"profile": "vtk-js"}})";
    try {
        render_scene(parse_scene(one_row, ".", "s.json"), {1, false});
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("node range"), std::string::npos) << e.what();
    }
}

// The pixel's ray as the rasteriser interpolates it over vtk.js's snapped proxy quad (issue 28, part 5).
// One orthographic pixel, height 0.01, eye x = 3.5005 over the texel box [-0.5, 7.5]: the quad spans
// window x [-399.55, 400.45], snapped to 1/16: [-399.5625, 400.4375], so the pixel centre 0.5 gets the
// varying of -399.55 + 400.0625 * 800 / 800 = 0.5125: the ray at x = 3.5005 + 0.0125 * 0.01 = 3.500625.
// f = x, MIP: the pixel reads the table at the ray's x. subpixel_bits 0: through the pixel centre.
TEST(VtkJsProfile, RayThroughTheSnappedProxyQuad) {
    auto scene = [](double eye_x, int bits) {
        Scene s = field_scene(linear_field({1, 0, 0, 0}, {8, 8, 8}));
        s.volume().transfer.color = {{0, 1, 1, 1}, {8, 1, 1, 1}};
        s.volume().transfer.opacity = {{0, 0}, {8, 0.8}};
        s.camera = ortho_down_z(eye_x, 3.5, 20.0, 0.01);
        s.image.width = s.image.height = 1;
        s.render.projection = Projection::Mip;
        s.render.step = 0.5;
        s.render.step_units = StepUnits::World;
        s.render.profile = ProfileId::VtkJs;
        s.render.profile_options.subpixel_bits = bits;
        return s;
    };
    const double snapped = pixel(scene(3.5005, 4)).a;
    EXPECT_NEAR(snapped, pixel(scene(3.500625, 0)).a, 1e-12);
    EXPECT_GT(std::abs(snapped - pixel(scene(3.5005, 0)).a), 1e-6);
    // A quad whose corners lie on the grid (eye x = 3.5: [-399.5, 400.5]) leaves the ray at the centre.
    EXPECT_NEAR(pixel(scene(3.5, 4)).a, pixel(scene(3.5, 0)).a, 1e-12);
}
