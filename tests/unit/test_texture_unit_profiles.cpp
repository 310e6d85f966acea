// The texture unit as a profile option (issues 17, 27): render.profile_options.texture_unit
// ("exact" / "h100", "hardware" its deprecated alias) and texture_band (the "error" channel) for vtk-gpu,
// glsl-basic and cuda-curvilinear (ProfileIntegrator, TextureUnit.h, conventions section 9 "The texture unit").
//   - one-ray cases worked by hand: the h100 rule's 3D fetch through glsl-basic (a pixel moved by a
//     hand-computed amount) and its 9-entry table through cuda-curvilinear, and the band of a glsl-basic ray;
//   - the band on random scenes, unshaded and shaded: the h100 rule and Monte Carlo units of its family
//     (TextureUnit::Admissible: weights within L1 distance kL1Max of exact, a quarter at kL1Max exactly,
//     and the rounding terms) must stay within the exact render's band, pixel by pixel and channel by channel;
//   - the loader's one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;

namespace {

using TU = ProfileOptions::TextureUnit;

std::size_t channel(const Image& im, const std::string& name) {
    for (std::size_t c = 0; c < im.channels.size(); ++c)
        if (im.channels[c] == name) return c;
    ADD_FAILURE() << "no channel " << name;
    return 0;
}

double q256(double f) { return std::floor(f * 256.0 + 0.5) / 256.0; }  // the rule's 1D weight, by hand

// f = x on [0, 4]^3 (5^3 voxels), glsl-basic, one orthographic ray along -z at (1.3, 2.0): samples at
// z = 4, 3.5, ..., 0 (9, from the entry), opacity 0.1 everywhere (K = 1), colour = the value.
Scene glsl_ramp_x() {
    Scene s = field_scene(linear_field({1, 0, 0, 0}, {5, 5, 5}));
    s.volume().transfer.color = {{0, 1, 1, 1}, {4, 1, 1, 1}};
    s.volume().transfer.opacity = {{0, 0.1}, {4, 0.1}};
    s.camera = ortho_down_z(1.3, 2.0, 14.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    s.render.profile = ProfileId::GlslBasic;
    return s;
}

}  // namespace

// The h100 fetch through glsl-basic's normalised coordinates u = (i + 0.5) / 5, cut to 20 bits:
// x = 1.3: u = float32(0.36), floor(u 2^20) 2^-20 5 = 1.7999983, t = 1.2999983, a_x = floor(76.7996 + 0.5) = 77;
// y = 2: u = 0.5 exactly, t = 2, a_y = 0; z integer: t = z - 1e-6 or 0, a_z = 256 (all on texel z) or 0;
// z half-integer: t = z - 4e-6, a_z = floor(127.999 + 0.5) = 128. Corner weights (TextureUnit.h, step 2):
// a_z = 256 or 0: one slice, X1 = rnd(77 * 256) = 77, X0 = 179, v = (179 * 1 + 77 * 2) / 256 = 333/256;
// a_z = 128: Z0 = Z1 = 128, X1 = rnd(77 * 128 = 9856) = (9856 + 128) >> 8 = 39, X0 = 89 in each slice,
// v = 2 (89 + 39 * 2) / 256 = 334/256. The texels 1 and 2 are exact in 28 bits. Exact: v = 1.3.
// R = sum_k 0.1 * 0.9^k v_k, A = 1 - 0.9^9 in both.
TEST(TextureUnitProfiles, GlslBasicH100FetchByHand) {
    EXPECT_EQ(q256(0.3), 77.0 / 256.0);
    Scene s = glsl_ramp_x();
    const glm::dvec4 e = rgba(render_scene(s, {1, false}), 0, 0);
    s.render.profile_options.texture_unit = TU::H100;
    const glm::dvec4 h = rgba(render_scene(s, {1, false}), 0, 0);
    double Rh = 0.0, Re = 0.0;
    for (int k = 0; k <= 8; ++k) {
        const double v = k % 2 == 0 ? 333.0 / 256.0 : 334.0 / 256.0;  // z = 4 - 0.5 k
        Rh += 0.1 * std::pow(0.9, k) * v;
        Re += 0.1 * std::pow(0.9, k) * 1.3;
    }
    EXPECT_NEAR(e.r, Re, 1e-12);
    EXPECT_NEAR(h.r, Rh, 1e-12);
    EXPECT_NEAR(h.g, Rh, 1e-12);
    EXPECT_GT(std::fabs(h.r - e.r), 1e-3);  // 1.35e-3: the pixel moved by the hand-computed amount
    EXPECT_NEAR(h.a, 1.0 - std::pow(0.9, 9), 1e-12);
    EXPECT_NEAR(e.a, h.a, 1e-15);
}

// The band of the same ray: alpha is exact (constant opacity, every value far above the 0.01 cutoff),
// so T_k = 0.9^k exactly and only the colour (= the value) moves: R's band = sum_k 0.1 * 0.9^k d, with
// every fetch's band d = (kL1Max / 2 + sum_axis 5 (2^-20 + 2^-24)) (2 - 1) + 2^-22 * 2 (the corners are
// 1 and 2 in the exact cell and in the unit's; TextureUnit.h). A's band is 0.
TEST(TextureUnitProfiles, GlslBasicBandByHand) {
    Scene s = glsl_ramp_x();
    s.render.profile_options.texture_band = true;
    const Image im = render_scene(s, {1, false});
    const double d = (0.0295867919921875 / 2.0 + 15.0 * (std::ldexp(1.0, -20) + std::ldexp(1.0, -24))) * 1.0 + std::ldexp(2.0, -22);
    double band = 0.0;
    for (int k = 0; k <= 8; ++k) band += 0.1 * std::pow(0.9, k) * d;
    EXPECT_NEAR(im.at(0, 0, channel(im, "error")), band, 1e-9);
    EXPECT_GT(band, 0.005);  // about 0.00907: the hand value is not a trivial zero
    // The h100 render lies inside it.
    Scene h = glsl_ramp_x();
    h.render.profile_options.texture_unit = TU::H100;
    EXPECT_LE(std::fabs(rgba(render_scene(h, {1, false}), 0, 0).r - im.at(0, 0, 0)), band);
}

// cuda-curvilinear on f = z (s = z / 4), opacity a = s (white), iso threshold 0.5, density 0.5, transfer
// scale 0.9: the 9-entry table (a_j = j / 8) is read at pos = 9 (0.9 s) - 0.5 for the kept s = 0.5,
// 0.625, 0.75, 0.875, 1: pos = 3.55, 4.5625, 5.575, 6.5875, 7.6; the h100 rule reads u = float32(0.9 s)
// cut to 20 bits (0.45 -> 0.4499998, 9 u - 0.5 = 3.5499983, 256 * 0.5499983 = 140.7996), so the weights are
// q(0.55) = 141/256, q(0.5625) = 144/256, q(0.575) = 147/256, q(0.5875) = 150/256, q(0.6) = 154/256;
// a = ((256 - 256 q) i + 256 q (i + 1)) / 2048 = (i + q) / 8, exact in float32. The 3D fetches are exact
// (unnormalised coordinates, fractions 0 and 0.5: integer weights 0 and 128). Back to front (s = 0.5 first):
// R = lerp(R, 1, a / 2), A = lerp(A, a, a / 2).
TEST(TextureUnitProfiles, CudaCurvilinearH100TableByHand) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {5, 5, 5}));
    s.volume().transfer.color = {{0, 1, 1, 1}, {4, 1, 1, 1}};
    s.volume().transfer.opacity = {{0, 0}, {4, 1}};
    s.camera = ortho_down_z(2.0, 2.0, 14.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    s.render.profile = ProfileId::CudaCurvilinear;
    s.render.profile_options.iso_threshold = 0.5;
    s.render.profile_options.density = 0.5;
    s.render.profile_options.transfer_scale = 0.9;
    s.render.profile_options.texture_unit = TU::H100;
    const glm::dvec4 p = rgba(render_scene(s, {1, false}), 0, 0);
    const int i[5] = {3, 4, 5, 6, 7};
    const double q[5] = {141, 144, 147, 150, 154};
    EXPECT_EQ(q256(0.55), 141.0 / 256.0);
    EXPECT_EQ(q256(0.6), 154.0 / 256.0);
    double R = 0.0, A = 0.0;
    for (int k = 0; k < 5; ++k) {
        const double a = (i[k] + q[k] / 256.0) / 8.0;
        R = R + (1.0 - R) * (0.5 * a);
        A = A + (a - A) * (0.5 * a);
    }
    EXPECT_NEAR(p.r, R, 1e-12);
    EXPECT_NEAR(p.a, A, 1e-12);
    // Exact weights: a = pos / 8 (differs: the hand value above is not the exact one).
    s.render.profile_options.texture_unit = TU::Exact;
    double Re = 0.0;
    for (double pos : {3.55, 4.5625, 5.575, 6.5875, 7.6}) Re = Re + (1.0 - Re) * (0.5 * pos / 8.0);
    EXPECT_NEAR(rgba(render_scene(s, {1, false}), 0, 0).r, Re, 1e-12);
    EXPECT_GT(std::fabs(Re - R), 5e-7);  // 8.8e-7: the rounding of the five weights nearly cancels in R
}

namespace {

std::string number_list(const std::vector<double>& v) {
    std::string s;
    char buf[64];
    for (double x : v) {
        std::snprintf(buf, sizeof buf, "%s%.17g", s.empty() ? "" : ", ", x);
        s += buf;
    }
    return s;
}

// A random scene: random voxels in [0, 1], a random piecewise-linear transfer function, an oblique
// perspective camera, 8 x 8 pixels. bounds: "" (a box, the Cartesian grid) or a shell's bounds.
Scene random_scene(std::mt19937_64& g, ProfileId profile, Projection projection, const std::string& bounds,
                   const std::string& shading = "") {
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::uniform_int_distribution<int> D(3, 6);
    const int nx = D(g), ny = D(g), nz = D(g);
    std::vector<double> values(std::size_t(nx * ny * nz));
    for (double& v : values) v = U(g);
    std::vector<double> ox = {0.0, U(g), U(g), 1.0};
    std::sort(ox.begin(), ox.end());
    std::string opacity, color;
    for (double x : ox) opacity += std::string(opacity.empty() ? "" : ", ") + "[" + number_list({x, 0.7 * U(g)}) + "]";
    for (double x : {0.0, 0.5, 1.0}) color += std::string(color.empty() ? "" : ", ") + "[" + number_list({x, U(g), U(g), U(g)}) + "]";
    const double theta = 6.283185307179586 * U(g), phi = 0.3 + 0.8 * U(g);
    const bool shell = !bounds.empty();
    const glm::dvec3 c = shell ? glm::dvec3(0.0, 0.0, 0.5) : glm::dvec3(nx - 1, ny - 1, nz - 1) * 0.5;
    const double r = shell ? 5.0 : 3.0 * double(std::max({nx, ny, nz}));
    const glm::dvec3 eye = c + r * glm::dvec3(std::cos(theta) * std::sin(phi), std::sin(theta) * std::sin(phi), std::cos(phi));
    const std::string proj = projection == Projection::Composite ? "composite" : projection == Projection::Mip ? "mip"
                             : projection == Projection::Average ? "average" : "xray";
    const std::string prof = profile == ProfileId::VtkGpu ? "vtk-gpu" : profile == ProfileId::GlslBasic ? "glsl-basic" : "cuda-curvilinear";
    std::string options;
    if (profile == ProfileId::GlslBasic) options = R"(, "profile_options": {"intensity": )" + number_list({0.5 + 1.5 * U(g)}) + "}";
    if (profile == ProfileId::CudaCurvilinear)
        options = R"(, "profile_options": {"density": )" + number_list({0.5 + 1.5 * U(g)}) + R"(, "transfer_scale": )" +
                  number_list({0.7 + 0.6 * U(g)}) + R"(, "iso_threshold": )" + number_list({0.4 * U(g)}) +
                  R"(, "brightness": )" + number_list({0.5 + U(g)}) + R"(, "kernel": "double"})";  // the double profile's band
    const std::string json = R"({"volume": {"source": {"field": "cells", "dims": [)" + std::to_string(nx) + ", " +
                             std::to_string(ny) + ", " + std::to_string(nz) + R"(], "values": [)" + number_list(values) + "]}" +
                             (shell ? R"(, "bounds": )" + bounds : std::string()) +
                             (shading.empty() ? std::string() : R"(, "shading": )" + shading) +
                             R"(, "transfer": {"color": [)" + color + R"(], "opacity": [)" + opacity + R"(]}},
        "camera": {"type": "perspective", "eye": [)" + number_list({eye.x, eye.y, eye.z}) + R"(], "target": [)" +
                             number_list({c.x, c.y, c.z}) + R"(], "up": [0, 0, 1], "fov_y": 30},
        "image": {"width": 8, "height": 8},
        "render": {"projection": ")" + proj + R"(", "step": )" + number_list({0.2 + 0.4 * U(g)}) +
                             R"(, "step_units": "world", "profile": ")" + prof + "\"" + options + "}}";
    return parse_scene(json, ".", "random");
}

struct BandCheck {
    double worst_ratio = 0.0;   // max over pixels of |unit - exact| / band
    double largest_band = 0.0;  // max over pixels of the band
    double largest_hw = 0.0;    // max |h100 - exact|
};

// exact + band, the h100 rule and Monte Carlo units: every unit within the band of the exact render.
void check_band(const Scene& base, BandCheck& out, int units) {
    Scene s = base;
    s.render.profile_options.texture_band = true;
    const Image exact = render_scene(s, {1, false});
    const std::size_t err = channel(exact, "error");
    ASSERT_EQ(exact.channels.size(), 5u);
    s.render.profile_options.texture_band = false;
    for (int u = 0; u <= units; ++u) {
        s.render.profile_options.texture_unit = u == 0 ? TU::H100 : TU::Admissible;
        s.render.profile_options.texture_seed = 1000u + unsigned(u);
        const Image other = render_scene(s, {1, false});
        ASSERT_EQ(other.channels.size(), 4u);
        for (int y = 0; y < exact.height; ++y)
            for (int x = 0; x < exact.width; ++x) {
                const double band = exact.at(x, y, err);
                out.largest_band = std::max(out.largest_band, band);
                for (std::size_t c = 0; c < 4; ++c) {
                    const double d = std::fabs(other.at(x, y, c) - exact.at(x, y, c));
                    if (u == 0) out.largest_hw = std::max(out.largest_hw, d);
                    if (band > 1e-9) out.worst_ratio = std::max(out.worst_ratio, d / band);
                    ASSERT_LE(d, band) << "unit " << u << " pixel (" << x << ", " << y << ") channel " << c;
                }
            }
    }
}

void random_band_cases(ProfileId profile, Projection projection, const std::string& bounds, int cases, std::uint64_t seed,
                       const std::string& shading = "") {
    std::mt19937_64 g(seed);
    BandCheck b;
    for (int k = 0; k < cases; ++k) {
        SCOPED_TRACE("case " + std::to_string(k));
        check_band(random_scene(g, profile, projection, bounds, shading), b, 4);
        if (testing::Test::HasFatalFailure()) return;
    }
    // The simulation is not idle (the h100 rule moved some pixel) and the band is not vacuous.
    EXPECT_GT(b.largest_hw, 1e-6);
    // shaded: the normal's error grows as 1 / |grad f| on these random 3-6 voxel volumes (up to 0.9 seen)
    EXPECT_LT(b.largest_band, shading.empty() ? 0.5 : 1.0);
    std::printf("band: largest %.3g, largest |h100 - exact| %.3g, worst |unit - exact| / band %.3f\n",
                b.largest_band, b.largest_hw, b.worst_ratio);
}

const std::string kCylinder = R"({"type": "cylindrical", "center": [0, 0, 0], "radius": [0, 1], "angle": [0, 360], "height": [0, 1]})";
const std::string kSphere = R"({"type": "spherical", "center": [0, 0, 0.5], "radius": [0.2, 1], "longitude": [0, 270], "latitude": [-60, 60]})";

}  // namespace

TEST(TextureUnitProfiles, BandHoldsRandomVtkGpuComposite) { random_band_cases(ProfileId::VtkGpu, Projection::Composite, "", 6, 1); }
TEST(TextureUnitProfiles, BandHoldsRandomVtkGpuMip) { random_band_cases(ProfileId::VtkGpu, Projection::Mip, "", 4, 2); }
TEST(TextureUnitProfiles, BandHoldsRandomVtkGpuAverage) { random_band_cases(ProfileId::VtkGpu, Projection::Average, "", 4, 3); }
TEST(TextureUnitProfiles, BandHoldsRandomGlslBasicComposite) { random_band_cases(ProfileId::GlslBasic, Projection::Composite, "", 6, 4); }
TEST(TextureUnitProfiles, BandHoldsRandomCudaCartesianComposite) { random_band_cases(ProfileId::CudaCurvilinear, Projection::Composite, "", 4, 5); }
TEST(TextureUnitProfiles, BandHoldsRandomCudaCylinderComposite) { random_band_cases(ProfileId::CudaCurvilinear, Projection::Composite, kCylinder, 4, 6); }
TEST(TextureUnitProfiles, BandHoldsRandomCudaSphereComposite) { random_band_cases(ProfileId::CudaCurvilinear, Projection::Composite, kSphere, 4, 7); }
TEST(TextureUnitProfiles, BandHoldsRandomCudaCylinderXray) { random_band_cases(ProfileId::CudaCurvilinear, Projection::Xray, kCylinder, 4, 8); }
TEST(TextureUnitProfiles, BandHoldsRandomCudaMip) { random_band_cases(ProfileId::CudaCurvilinear, Projection::Mip, kSphere, 4, 9); }
// Shaded (issue 27: the band through the gradient's fetches and the lighting): blinn-phong one-sided,
// phong two-sided, vtk-gpu (clamped, gradient along -grad f) and glsl-basic (its colour is the value).
const std::string kBlinn = R"({"model": "blinn-phong", "ka": 0.2, "kd": 0.6, "ks": 0.4, "n": 12})";
const std::string kPhong = R"({"model": "phong", "ka": 0.1, "kd": 0.8, "ks": 0.5, "n": 5, "two_sided": true})";
TEST(TextureUnitProfiles, BandHoldsRandomVtkGpuShaded) { random_band_cases(ProfileId::VtkGpu, Projection::Composite, "", 4, 21, kBlinn); }
TEST(TextureUnitProfiles, BandHoldsRandomVtkGpuShadedPhong) { random_band_cases(ProfileId::VtkGpu, Projection::Composite, "", 4, 22, kPhong); }
TEST(TextureUnitProfiles, BandHoldsRandomGlslBasicShaded) { random_band_cases(ProfileId::GlslBasic, Projection::Composite, "", 4, 23, kBlinn); }
TEST(TextureUnitProfiles, BandHoldsRandomGlslBasicShadedPhong) { random_band_cases(ProfileId::GlslBasic, Projection::Composite, "", 4, 24, kPhong); }

// "exact" is the default: the same image bit for bit as no option at all.
TEST(TextureUnitProfiles, ExactIsTheDefault) {
    std::mt19937_64 g(11);
    const Scene s = random_scene(g, ProfileId::VtkGpu, Projection::Composite, "");
    Scene e = s;
    e.render.profile_options.texture_unit = TU::Exact;
    EXPECT_EQ(render_scene(s, {1, false}).pixels, render_scene(e, {1, false}).pixels);
}

// The loader: one-line errors naming the key.
TEST(TextureUnitProfiles, LoaderErrorsNameTheKey) {
    auto error_of = [](const std::string& render, const std::string& volume_extra = "") {
        const std::string json = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [3, 3, 3]})" + volume_extra +
                                 R"(}, "render": )" + render + "}";
        try {
            render_scene(parse_scene(json, ".", "t"), {1, false});
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    std::string m = error_of(R"({"profile": "vtk-gpu", "profile_options": {"texture_unit": "fast"}})");
    EXPECT_NE(m.find("texture_unit"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    m = error_of(R"({"profile": "glsl-basic", "profile_options": {"texture_band": "yes"}})");
    EXPECT_NE(m.find("texture_band"), std::string::npos) << m;
    m = error_of(R"({"profile": "vtk-gpu", "profile_options": {"density": 2}})");
    EXPECT_NE(m.find("density"), std::string::npos) << m;
    m = error_of(R"({"profile": "ospray", "profile_options": {"texture_unit": "hardware"}})");
    EXPECT_NE(m.find("profile_options"), std::string::npos) << m;
    m = error_of(R"({"profile": "vtk-gpu", "profile_options": {"texture_unit": "hardware"}})", R"(, "interpolation": "nearest")");
    EXPECT_NE(m.find("render.profile_options.texture_unit"), std::string::npos) << m;
    // issue 27: the band goes through shading; "hardware" is a deprecated alias of "h100"
    EXPECT_EQ(error_of(R"({"profile": "vtk-gpu", "profile_options": {"texture_band": true}})", R"(, "shading": {})"), "");
    EXPECT_EQ(error_of(R"({"profile": "cuda-curvilinear", "profile_options": {"texture_unit": "hardware", "texture_band": true}})"), "");
    EXPECT_EQ(error_of(R"({"profile": "glsl-basic", "profile_options": {"texture_unit": "h100", "texture_band": true}})"), "");
    const std::string json = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [3, 3, 3]}},
        "render": {"profile": "vtk-gpu", "profile_options": {"texture_unit": "hardware"}}})";
    EXPECT_EQ(parse_scene(json, ".", "t").render.profile_options.texture_unit, TU::H100);
}
