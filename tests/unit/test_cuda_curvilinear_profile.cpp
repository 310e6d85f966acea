// cuda-curvilinear marches as seed 001's kernel does (issue 17, part 3, first item):
// `for (float s = outAbs; s >= inAbs; s -= step)`: the samples are counted from the exit, t1 - k h,
// k = 0 .. floor(L / h), and composited in that order (sum = lerp(sum, col, col.w * density)).
// One orthographic pixel looking along -z at f = z on the box [0, 4]^3 (5^3 voxels): the ray enters at
// z = 4 and leaves at z = 0; with step 0.75 (L / h = 5.33, not an integer) the samples lie at
// z = 0, 0.75, 1.5, 2.25, 3.0, 3.75, not at the entry's z = 4, 3.25, ..., 0.25.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "TestScenes.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;

namespace {

Scene ramp(Projection projection) { return ramp_scene(ProfileId::CudaCurvilinear, projection, 0.75); }

}  // namespace

// X-ray: brightness times the largest s = v / 4 over the samples: 3.75 / 4 (the entry's z = 4 is not
// sampled; marching from the entry would give 1).
TEST(CudaCurvilinearProfile, MarchesFromTheExitXray) {
    Scene s = ramp(Projection::Xray);
    s.render.profile_options.brightness = 0.5;
    EXPECT_NEAR(rgba(render_scene(s, {1, false}), 0, 0).r, 0.5 * 0.9375, 1e-12);
}

// Composite: s_k = 0.1875 k at z = 0.75 k, k = 0 .. 5, in that order (far to near). The 9-entry table
// holds a_j = j / 8 (white), read at 9 s - 0.5 clamped to [0, 8]: a = clamp(9 s - 0.5, 0, 8) / 8.
// density 1: R = lerp(R, 1, a), A = lerp(A, a, a).
TEST(CudaCurvilinearProfile, MarchesFromTheExitComposite) {
    const glm::dvec4 p = rgba(render_scene(ramp(Projection::Composite), {1, false}), 0, 0);
    double R = 0.0, A = 0.0;
    for (int k = 0; k <= 5; ++k) {
        const double s = 0.1875 * k;
        const double a = std::clamp(9.0 * s - 0.5, 0.0, 8.0) / 8.0;
        R = R + (1.0 - R) * a;
        A = A + (a - A) * a;
    }
    EXPECT_NEAR(p.r, R, 1e-12);
    EXPECT_NEAR(p.a, A, 1e-12);
}

namespace {

// A one-pixel orthographic view (the ray through the eye) of a shell whose data are the radial index.
std::string shell_scene(const std::string& bounds, std::array<int, 3> dims, int radial_axis, const std::string& camera,
                        const std::string& render) {
    std::string values;
    for (int k = 0; k < dims[2]; ++k)
        for (int j = 0; j < dims[1]; ++j)
            for (int i = 0; i < dims[0]; ++i) {
                const int r = radial_axis == 0 ? i : radial_axis == 1 ? j : k;
                values += (values.empty() ? "" : ", ") + std::to_string(r);
            }
    return R"({"volume": {"source": {"field": "cells", "dims": [)" + std::to_string(dims[0]) + ", " +
           std::to_string(dims[1]) + ", " + std::to_string(dims[2]) + R"(], "values": [)" + values + R"(]},
               "bounds": )" + bounds + R"(,
               "transfer": {"color": [[0, 1, 0, 0], [3, 0, 0, 1]], "opacity": [[0, 0.5], [3, 1]]}},
              "camera": )" + camera + R"(,
              "image": {"width": 1, "height": 1},
              "render": )" + render + "}";
}

const std::string kCylinder = R"({"type": "cylindrical", "center": [0, 0, 0], "radius": [0, 1], "angle": [0, 360], "height": [0, 1]})";
const std::string kAcrossTheHeight = R"({"type": "orthographic", "eye": [0, 0.5, 5], "target": [0, 0.5, 0], "up": [0, 1, 0], "height": 0.01})";

glm::dvec4 render_json(const std::string& json) { return rgba(render_scene(parse_scene(json, ".", "test"), {1, false}), 0, 0); }

// The seed's interpolateCyl on this cylinder (R = 1, 360 degrees, height 1, dims (4, 8, 2), data = the
// radial index i): x_r = r / (1 / 4) = 4 r, outVal when 4 r > 3; tex3D at 4 r - 0.5 (clamped at 0) gives
// v = max(4 r - 0.5, 0) (the data are linear in i); the height's x = 0.5 / (1 / 2) = 1 = n - 1 is in range.
double seed_cylinder_value(double r) { return 4.0 * r > 3.0 ? 0.0 : std::max(4.0 * r - 0.5, 0.0); }

}  // namespace

// A cylinder seen across its height: the ray x = 0, y = 0.5 along -z crosses it from z = 1 to z = -1
// (t = 4 .. 6), step 0.25: from the exit the samples lie at z = -1, -0.75, ..., 1, r = |z|:
// v = 0 (outVal), 2.5, 1.5, 0.5, 0, 0.5, 1.5, 2.5, 0 (outVal); s = v / 3.
// X-ray: brightness times max s = 2.5 / 3 (volref's own shell sampler reads r = 1 as v = 3: s = 1).
TEST(CudaCurvilinearProfile, CylinderAcrossItsHeightXray) {
    const std::string render = R"({"projection": "xray", "step": 0.25, "step_units": "world", "profile": "cuda-curvilinear",
                                   "profile_options": {"brightness": 0.8, "kernel": "double"}})";
    EXPECT_NEAR(render_json(shell_scene(kCylinder, {4, 8, 2}, 0, kAcrossTheHeight, render)).r, 0.8 * 2.5 / 3.0, 1e-12);
    // Iso threshold 0.9 (in s): no sample reaches it: maxVal stays 0.
    const std::string iso = R"({"projection": "xray", "step": 0.25, "step_units": "world", "profile": "cuda-curvilinear",
                                "profile_options": {"iso_threshold": 0.9, "kernel": "double"}})";
    EXPECT_EQ(render_json(shell_scene(kCylinder, {4, 8, 2}, 0, kAcrossTheHeight, iso)).r, 0.0);
}

// The same ray composited: the 9-entry table over [0, 3] holds colour (1 - j/8, 0, j/8) and opacity
// 0.5 + 0.5 j/8, read at pos = clamp(9 s - 0.5, 0, 8); sum = lerp(sum, col, col.a) from z = -1 to z = 1.
// The outVal samples (s = 0) read entry 0: red, a = 0.5 (iso threshold 0 keeps them).
TEST(CudaCurvilinearProfile, CylinderAcrossItsHeightComposite) {
    const std::string render = R"({"projection": "composite", "step": 0.25, "step_units": "world", "profile": "cuda-curvilinear",
                                   "profile_options": {"kernel": "double"}})";
    const glm::dvec4 p = render_json(shell_scene(kCylinder, {4, 8, 2}, 0, kAcrossTheHeight, render));
    glm::dvec4 sum(0.0);
    for (int k = 0; k <= 8; ++k) {
        const double z = -1.0 + 0.25 * k;
        const double s = seed_cylinder_value(std::fabs(z)) / 3.0;
        const double pos = std::clamp(9.0 * s - 0.5, 0.0, 8.0);
        const glm::dvec4 col(1.0 - pos / 8.0, 0.0, pos / 8.0, 0.5 + 0.5 * pos / 8.0);
        sum += (col - sum) * col.a;
    }
    EXPECT_NEAR(p.r, sum.r, 1e-12);
    EXPECT_NEAR(p.b, sum.b, 1e-12);
    EXPECT_NEAR(p.a, sum.a, 1e-12);
}

// A spherical sector: longitude [0, 90], latitude [-45, 45], radius [0, 1], dims (lon 3, lat 3, R 4),
// data = the radial index k. The ray y = 0, z = -0.3 along +x enters at x = 0 (t = 5) and leaves at
// x1 = sqrt(1 - 0.09) (t = 5 + x1). From the exit, step 0.1: x = x1 - 0.1 k, k = 0 .. 9. The seed's
// interpolateSpher: lon = atan2(0.3, x) (degrees), x_lon = lon / (90 / 3) (outVal past 2), x_lat =
// (0 + 45) / (90 / 3) = 1.5, x_R = R / (1 / 4) (outVal past 3); v = max(4 R - 0.5, 0).
// X-ray: max over the samples of v / 3.
TEST(CudaCurvilinearProfile, SphericalSectorXray) {
    const std::string sector = R"({"type": "spherical", "center": [0, 0, 0], "radius": [0, 1], "longitude": [0, 90], "latitude": [-45, 45]})";
    const std::string camera = R"({"type": "orthographic", "eye": [-5, 0, -0.3], "target": [0, 0, -0.3], "up": [0, 1, 0], "height": 0.01})";
    const std::string render = R"({"projection": "xray", "step": 0.1, "step_units": "world", "profile": "cuda-curvilinear",
                                   "profile_options": {"kernel": "double"}})";
    const double x1 = std::sqrt(1.0 - 0.09);
    double best = 0.0;
    for (int k = 0; k <= 9; ++k) {
        const double x = x1 - 0.1 * k;
        const double R = std::hypot(x, 0.3);
        const double lon = std::atan2(0.3, x) * 180.0 / 3.14159265358979323846;
        const bool out = lon / 30.0 > 2.0 || 4.0 * R > 3.0;
        best = std::max(best, out ? 0.0 : std::max(4.0 * R - 0.5, 0.0) / 3.0);
    }
    EXPECT_NEAR(best, (4.0 * std::hypot(x1 - 0.3, 0.3) - 0.5) / 3.0, 1e-15);  // the sample at x1 - 0.3
    EXPECT_NEAR(render_json(shell_scene(sector, {3, 3, 4}, 2, camera, render)).r, best, 1e-9);
}
