// cuda-curvilinear's float32 kernel (issue 28; core/integrate/profiles/CudaCurvilinearKernel.h): seed 001's kernel
// as it runs on the GPU. By hand: one chord through the host's 64-sided cylinder; against the H100: a ray
// the real program never finished (tests/gpu/h100/seed001, its guard's mark); the fault channel through
// render, trace and compare; the band against the exact unit on random cylinders; the loader's errors.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/explain/PixelTrace.h"
#include "core/film/ImageWriter.h"
#include "core/integrate/profiles/CudaCurvilinearKernel.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;

namespace {

// A full cylinder (R = 1, 360 degrees, height 1; dims (4, 8, 2): radius, angle, height), data = the
// radial index i; one orthographic ray along -z at x = 0.05, y = 0.5 from z = 5.
std::string chord_scene(const std::string& projection, const std::string& options) {
    std::string values;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 4; ++i) values += (values.empty() ? "" : ", ") + std::to_string(i);
    return R"({"volume": {"source": {"field": "cells", "dims": [4, 8, 2], "values": [)" + values + R"(]},
               "bounds": {"type": "cylindrical", "center": [0, 0, 0], "radius": [0, 1], "angle": [0, 360], "height": [0, 1]},
               "transfer": {"color": [[0, 1, 0, 0], [3, 0, 0, 1]], "opacity": [[0, 0.5], [3, 1]]}},
              "camera": {"type": "orthographic", "eye": [0.05, 0.5, 5], "target": [0.05, 0.5, 0], "up": [0, 1, 0], "height": 0.01},
              "image": {"width": 1, "height": 1},
              "render": {"projection": ")" + projection + R"(", "step": 0.25, "step_units": "world", "profile": "cuda-curvilinear",
                         "profile_options": {)" + options + "}}}";
}

// The error a scene's render throws ("" when it renders).
std::string error_of(const std::string& json) {
    try {
        render_scene(parse_scene(json, ".", "t"), {1, false});
    } catch (const Error& e) {
        return std::string(e.what());
    }
    return std::string();
}

glm::dvec4 render_json(const std::string& json) { return rgba(render_scene(parse_scene(json, ".", "test"), {1, false}), 0, 0); }

// The chord by hand. The host's triangles: 64 segments per turn, vertices at angles 5.625 k degrees
// (x = cos, z = -sin); the ray x = 0.05 enters through the side between 270 and 275.625 degrees at
// z = 1 - 0.05 tan(2.8125 deg) = 0.997544 and leaves through its mirror image at z = -0.997544:
// inAbs = 5 - 0.997544, outAbs = 5 + 0.997544. From outAbs, s -= 0.25: 8 samples at z = -0.997544 + 0.25 k,
// k = 0 .. 7 (k = 8 is in front of inAbs). interpolateCyl: x_r = r / (1/4), x_angle = angle / 45 deg, x_h =
// 0.5 / (1/2) = 1 = n - 1 (in range); outVal (0) when x_r > 3 (r > 0.75) or x_angle > 7: angle =
// atan2(-z, 0.05) + 360 deg for z > 0, above 315 deg for 0 < z < 0.05. Otherwise the unsigned shorts
// i 65535 / 3 read at clamp(x_r - 0.5, 0, 3), exact weights: s = clamp(4 r - 0.5, 0, 3) / 3.
double chord_sample(int k) {
    const double z = -(1.0 - 0.05 * std::tan(2.8125 * 3.14159265358979323846 / 180.0)) + 0.25 * k;
    const double r = std::hypot(0.05, z);
    double angle = std::atan2(-z, 0.05) * 180.0 / 3.14159265358979323846;
    if (angle < 0.0) angle += 360.0;
    if (4.0 * r > 3.0 || angle / 45.0 > 7.0) return 0.0;
    return std::clamp(4.0 * r - 0.5, 0.0, 3.0) / 3.0;
}

// A random cylinder (`dims` cells of uniform values, 300 degrees, 24 segments) seen from a random
// perspective eye, 8 x 8 pixels, composite or x-ray, through the cuda-curvilinear profile with `options`.
Scene random_cylinder_scene(std::mt19937_64& g, std::array<int, 3> dims, bool xray, const std::string& options) {
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::string values;
    for (int k = 0; k < dims[0] * dims[1] * dims[2]; ++k) values += (values.empty() ? "" : ", ") + std::to_string(U(g));
    const double th = 6.283185307179586 * U(g), ph = 0.4 + 0.8 * U(g);
    char eye[128], dim[64];
    std::snprintf(eye, sizeof eye, "[%.17g, %.17g, %.17g]", 4.0 * std::cos(th) * std::sin(ph), 0.5 + 4.0 * std::cos(ph),
                  4.0 * std::sin(th) * std::sin(ph));
    std::snprintf(dim, sizeof dim, "[%d, %d, %d]", dims[0], dims[1], dims[2]);
    const std::string json = R"({"volume": {"source": {"field": "cells", "dims": )" + std::string(dim) + R"(, "values": [)" + values + R"(]},
           "bounds": {"type": "cylindrical", "center": [0, 0, 0], "radius": [0, 1], "angle": [0, 300], "height": [0, 1], "tessellate": 24},
           "transfer": {"color": [[0, 1, 0.2, 0], [1, 0, 0.5, 1]], "opacity": [[0, 0.05], [0.5, 0.4], [1, 0.9]]}},
          "camera": {"type": "perspective", "eye": )" + std::string(eye) + R"(, "target": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 40},
          "image": {"width": 8, "height": 8},
          "render": {"projection": ")" + std::string(xray ? "xray" : "composite") + R"(", "step": 0.05, "step_units": "world",
                     "profile": "cuda-curvilinear", "profile_options": {"iso_threshold": 0.1, "density": 0.7)" + options + "}}}";
    return parse_scene(json, ".", "t");
}

}  // namespace

// Composite: the 9-entry table over [0, 3] holds colour (1 - j/8, 0, j/8) and opacity 0.5 + 0.5 j/8, read
// at pos = clamp(9 s - 0.5, 0, 8) (exact unit); sum = lerp(sum, col, col.a) from k = 0 (the back). X-ray:
// the largest s (k = 1: r = 0.749214, s = 0.832286). float32 arithmetic: within 2e-6 of the double values.
TEST(CudaCurvilinearKernel, ChordThroughTheHostsTrianglesByHand) {
    EXPECT_EQ(chord_sample(0), 0.0);  // r = 0.9988: outVal
    EXPECT_EQ(chord_sample(4), 0.0);  // z = 0.0025: angle 357.2 degrees, x_angle = 7.94: outVal
    EXPECT_EQ(chord_sample(7), 0.0);  // r = 0.7541
    glm::dvec4 sum(0.0);
    double best = 0.0;
    for (int k = 0; k <= 7; ++k) {
        const double s = chord_sample(k);
        const double pos = std::clamp(9.0 * s - 0.5, 0.0, 8.0);
        const glm::dvec4 col(1.0 - pos / 8.0, 0.0, pos / 8.0, 0.5 + 0.5 * pos / 8.0);
        sum += (col - sum) * col.a;
        best = std::max(best, s);
    }
    const glm::dvec4 p = render_json(chord_scene("composite", ""));
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(p[c], sum[c], 2e-6) << c;
    EXPECT_NEAR(best, (4.0 * std::hypot(0.05, 0.25 - 0.997544) - 0.5) / 3.0, 1e-6);
    const glm::dvec4 x = render_json(chord_scene("xray", R"("brightness": 0.8)"));
    EXPECT_NEAR(x.r, 0.8 * best, 2e-6);
    EXPECT_EQ(x.a, 1.0);
    // The double profile on the exact circle differs: it enters at z = sqrt(1 - 0.05^2) = 0.998749.
    const glm::dvec4 d = render_json(chord_scene("composite", R"("kernel": "double")"));
    EXPECT_GT(std::fabs(d.r - p.r) + std::fabs(d.a - p.a), 1e-4);
}

// sphere-composite on the H100 (tests/gpu/h100/seed001): the program's guard marked pixel (70, 52) as
// (-1, outAbs, inAbs, -1) with outAbs = 3550161.25, inAbs = 3.2778039: its float32 intersection accepted a
// nearly parallel triangle 3.5e6 away, where s -= 0.01 leaves s unchanged. The kernel finds the same
// triangle, the same outAbs and inAbs bit for bit, and faults: NaN, fault channel 1, the reason traced.
TEST(CudaCurvilinearKernel, TheRayTheH100NeverFinished) {
    const std::string dir = std::string(VOLREF_SOURCE_DIR) + "/tests/gpu/h100/seed001/";
    auto in = OIIO::ImageInput::open(dir + "sphere-composite.h100.exr");
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<float> gpu(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, gpu.data()));
    in->close();
    const float* g = &gpu[(std::size_t(52) * std::size_t(spec.width) + 70) * std::size_t(spec.nchannels)];
    ASSERT_EQ(g[0], -1.0f);
    ASSERT_EQ(g[3], -1.0f);
    const Scene scene = load_scene(dir + "sphere-composite.json", {});
    const PreparedScene prepared(scene, RenderOptions{});
    const explain::PixelTrace t = explain::trace_pixel(prepared, 70, 52);
    EXPECT_TRUE(t.pixel.fault);
    EXPECT_TRUE(std::isnan(t.pixel.rgba.r));
    char out_abs[64], in_abs[64];
    std::snprintf(out_abs, sizeof out_abs, "outAbs = %.9g", double(g[1]));
    std::snprintf(in_abs, sizeof in_abs, "(inAbs %.9g)", double(g[2]));
    EXPECT_NE(t.fault.find(out_abs), std::string::npos) << t.fault << " / " << out_abs;
    EXPECT_NE(t.fault.find(in_abs), std::string::npos) << t.fault << " / " << in_abs;
    EXPECT_NE(t.fault.find("leaves s unchanged"), std::string::npos) << t.fault;
    // its neighbour finishes
    EXPECT_FALSE(prepared.render_pixel(69, 52).fault);
}

// The fault channel through the image and `volref compare`: a pixel with fault = 1 in either image is
// reported apart and left out of the metrics and the tolerance test.
TEST(CudaCurvilinearKernel, CompareLeavesFaultsOut) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "seed001-fault";
    std::filesystem::create_directories(dir);
    Image a(2, 1, {"R", "G", "B", "A", "fault"}), b(2, 1, {"R", "G", "B", "A"});
    for (std::size_t c = 0; c < 4; ++c) {
        a.at(0, 0, c) = std::numeric_limits<double>::quiet_NaN();
        b.at(0, 0, c) = -1.0;  // the guard's mark
        a.at(1, 0, c) = b.at(1, 0, c) = 0.25;
    }
    a.at(0, 0, 4) = 1.0;
    write_image(a, dir / "a.exr", glm::dvec4(0.0));
    write_image(b, dir / "b.exr", glm::dvec4(0.0));
    const std::string cmd = std::string(VOLREF_CLI) + " compare " + (dir / "a.exr").string() + " " + (dir / "b.exr").string() + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_TRUE(p);
    std::string text;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) text += buf;
    EXPECT_EQ(pclose(p), 0) << text;
    EXPECT_NE(text.find("1 pixels where the mirrored program does not finish"), std::string::npos) << text;
    EXPECT_NE(text.find("within tolerance"), std::string::npos) << text;
}

// The loader and the kernel's refusals name the key.
TEST(CudaCurvilinearKernel, ErrorsNameTheKey) {
    std::string m = error_of(chord_scene("composite", R"("kernel": "fast")"));
    EXPECT_NE(m.find("render.profile_options.kernel"), std::string::npos) << m;
    // a shell the seed cannot describe (radius from 0.2): the float32 kernel refuses, "double" renders it
    std::string j = chord_scene("composite", "");
    j.replace(j.find("\"radius\": [0, 1]"), 16, "\"radius\": [0.2, 1]");
    m = error_of(j);
    EXPECT_NE(m.find("render.profile_options.kernel"), std::string::npos) << m;
    EXPECT_NE(m.find("double"), std::string::npos) << m;
    j.replace(j.find("\"profile_options\": {"), 20, "\"profile_options\": {\"kernel\": \"double\"");
    EXPECT_EQ(error_of(j), "");
}

// The band of the float32 kernel (texture_band) holds the kernel through the exact unit as well as the
// h100 one, on random cylinders and perspective views (8 x 8 pixels), composite and x-ray.
TEST(CudaCurvilinearKernel, BandHoldsTheOtherUnit) {
    std::mt19937_64 g(28);
    double used = 0.0;
    for (int trial = 0; trial < 6; ++trial) {
        Scene s = random_cylinder_scene(g, {4, 6, 3}, trial % 2 == 1, "");
        s.render.profile_options.texture_unit = ProfileOptions::TextureUnit::H100;
        s.render.profile_options.texture_band = true;
        const Image h = render_scene(s, {1, false});
        ASSERT_EQ(h.channels.size(), 6u);  // R G B A error fault
        s.render.profile_options.texture_unit = ProfileOptions::TextureUnit::Exact;
        s.render.profile_options.texture_band = false;
        const Image e = render_scene(s, {1, false});
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const double band = h.at(x, y, 4);
                for (std::size_t c = 0; c < 4; ++c) {
                    const double d = std::fabs(h.at(x, y, c) - e.at(x, y, c));
                    EXPECT_LE(d, band) << "trial " << trial << " pixel " << x << ", " << y << " channel " << c;
                    if (std::isfinite(band) && band > 1e-7) used = std::max(used, d / band);
                }
            }
    }
    EXPECT_GT(used, 0.01);  // the two units differ somewhere by a visible part of the band
}

// ---- seed 001's tri-cubic option (render.profile_options.tricubic; CudaCurvilinearKernel.h, seed001_cubic) ----

namespace {

// The seed's cubic along one axis of linear data by hand: the linear read of texels f_j = j is
// F(m) = clamp(m - 0.5, 0, n - 1); at t = i + a the mixture reads m0 = i + a (1 - a), m1 = i + 1 - a (1 - a)
// with weight a, so inside (1 <= t < n - 1) (1 - a)(m0 - 0.5) + a (m1 - 0.5) = t - 0.5 + a (1 - a)(1 - 2a):
// Keys' cubic with parameter -1 does not reproduce a linear function (up to 0.096 off, at a = 0.211).
double cubic_of_index(double t, double n) {
    const double i = std::floor(t), a = t - i;
    auto F = [&](double m) { return std::clamp(m - 0.5, 0.0, n - 1.0); };
    return (1.0 - a) * F(i + a * (1.0 - a)) + a * F(i + 1.0 - a * (1.0 - a));
}

Seed001Frame ramp_frame(bool tricubic) {
    Seed001Frame f;
    f.dims = {8, 8, 8};
    f.data.resize(512);
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) f.data[std::size_t(i + 8 * (j + 8 * k))] = std::uint16_t(std::lround(65535.0 * i / 7.0));
    f.geom_size = {1.0f, 1.0f, 1.0f};
    f.tricubic = tricubic;
    return f;
}

}  // namespace

TEST(CudaCurvilinearKernel, CubicClosedFormOnARamp) {
    // the formula in double against the closed form, and against the expansion with the weights as written
    for (double t : {1.0, 1.25, 1.5, 2.1, 3.75, 5.999}) {
        const double a = t - std::floor(t);
        const double v = seed001_cubic({t, 2.5, 4.0}, [](const std::array<double, 3>& m) { return std::clamp(m[0] - 0.5, 0.0, 7.0); });
        EXPECT_NEAR(v, t - 0.5 + a * (1.0 - a) * (1.0 - 2.0 * a), 1e-14) << t;
        EXPECT_NEAR(v, cubic_of_index(t, 8.0), 1e-14) << t;
        const double w0 = -a * a * a + 2 * a * a - a, w1 = a * a * a - 2 * a * a + 1;
        if (a > 0.0) {
            const double w2 = -a * a * a + a * a + a, w3 = a * a * a - a * a;
            // (w0 and w0 + w1 cancel near a = 1 in double too: 5e-14 at a = 0.999)
            EXPECT_NEAR(std::floor(t) - w0 / (w0 + w1), std::floor(t) + a * (1.0 - a), 1e-12);
            EXPECT_NEAR(std::floor(t) + 1 + w3 / (w2 + w3), std::floor(t) + 1.0 - a * (1.0 - a), 1e-12);
        }
    }
    EXPECT_NEAR(cubic_of_index(2.25, 8.0), 1.84375, 1e-15);  // 2.25 - 0.5 + 0.25 * 0.75 * 0.5
    // The float32 kernel (exact unit) on unsigned shorts round(65535 i / 7): within their rounding, also
    // where a = 0 (w2 + w3 = 0: a NaN coordinate read with weight 0) and next to the edges (clamped reads).
    const CudaCurvilinearKernel k(ramp_frame(true), false, false);
    for (float t : {1.0f, 1.25f, 2.5f, 3.0f, 4.8f, 6.0f, 0.3f, 6.7f, 0.0f, 7.0f}) {
        const float v = k.cubic({t, 3.3f, 5.0f});
        ASSERT_TRUE(std::isfinite(v)) << t;
        EXPECT_NEAR(double(v), cubic_of_index(double(t), 8.0) / 7.0, 1e-5) << t;
        // the H100 rule: 8-bit weights, within kL1Max / 2 of the three texels' range (2 / 7)
        const CudaCurvilinearKernel h(ramp_frame(true), true, false);
        EXPECT_NEAR(double(h.cubic({t, 3.3f, 5.0f})), cubic_of_index(double(t), 8.0) / 7.0, 0.0295867919921875 / 2 * 2.0 / 7.0 + 1e-5) << t;
    }
    // without the option the same point is one linear read: (t - 0.5) / 7 (the shorts 9362 and 18724 read
    // with weights 1/4, 3/4: 16383.5 / 65535, within 0.5 / 65535)
    const CudaCurvilinearKernel lin(ramp_frame(false), false, false);
    EXPECT_NEAR(double(lin.fetch({2.25f, 3.3f, 5.0f})), 16383.5 / 65535.0, 1e-7);
    EXPECT_NEAR(double(lin.fetch({2.25f, 3.3f, 5.0f})), 1.75 / 7.0, 0.5 / 65535.0);
}

// The chord of ChordThroughTheHostsTrianglesByHand with tricubic: the data is the radial index, constant
// along angle and height, so each sample is the radial cubic of x_r = 4 r (over the range [0, 3]:
// cubic_of_index / 3), outVal where x_r > 3 or x_angle > 7. X-ray: the largest.
TEST(CudaCurvilinearKernel, TricubicChordByHand) {
    double best = 0.0;
    for (int k = 0; k <= 7; ++k) {
        const double z = -(1.0 - 0.05 * std::tan(2.8125 * 3.14159265358979323846 / 180.0)) + 0.25 * k;
        const double r = std::hypot(0.05, z);
        double angle = std::atan2(-z, 0.05) * 180.0 / 3.14159265358979323846;
        if (angle < 0.0) angle += 360.0;
        if (4.0 * r > 3.0 || angle / 45.0 > 7.0) continue;
        best = std::max(best, cubic_of_index(4.0 * r, 4.0) / 3.0);
    }
    const glm::dvec4 x = render_json(chord_scene("xray", R"("tricubic": true)"));
    EXPECT_NEAR(x.r, best, 2e-6);
    EXPECT_GT(std::fabs(x.r - render_json(chord_scene("xray", "")).r), 1e-3);  // the option changes the value
    // At step 0.001 both kernels (float32 on the triangles, double on the exact circle) approach the
    // supremum over the chord: the radial cubic increases (d/dt = 2 - 6a + 6a^2 >= 1/2), so it is its
    // value at x_r = 3, F(3) / 3 = 2.5 / 3; the samples' r moves by <= 0.001 (x_r by 0.004, value by 0.003).
    for (const char* opt : {R"("tricubic": true)", R"("tricubic": true, "kernel": "double")"}) {
        std::string j = chord_scene("xray", opt);
        j.replace(j.find("\"step\": 0.25"), 12, "\"step\": 0.001");
        EXPECT_NEAR(render_json(j).r, 2.5 / 3.0, 3e-3) << opt;
    }
}

// The band holds the tri-cubic kernel through the other unit (BandHoldsTheOtherUnit's scenes).
TEST(CudaCurvilinearKernel, TricubicBandHoldsTheOtherUnit) {
    std::mt19937_64 g(281);
    double used = 0.0;
    for (int trial = 0; trial < 4; ++trial) {
        Scene s = random_cylinder_scene(g, {5, 6, 4}, trial % 2 == 1, R"(, "tricubic": true)");
        s.render.profile_options.texture_unit = ProfileOptions::TextureUnit::H100;
        s.render.profile_options.texture_band = true;
        const Image h = render_scene(s, {1, false});
        ASSERT_EQ(h.channels.size(), 6u);
        s.render.profile_options.texture_unit = ProfileOptions::TextureUnit::Exact;
        s.render.profile_options.texture_band = false;
        const Image e = render_scene(s, {1, false});
        s.render.profile_options.tricubic = false;
        const Image l = render_scene(s, {1, false});
        double changed = 0.0;
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const double band = h.at(x, y, 4);
                for (std::size_t c = 0; c < 4; ++c) {
                    const double d = std::fabs(h.at(x, y, c) - e.at(x, y, c));
                    EXPECT_LE(d, band) << "trial " << trial << " pixel " << x << ", " << y << " channel " << c;
                    if (std::isfinite(band) && band > 1e-7) used = std::max(used, d / band);
                    changed = std::max(changed, std::fabs(e.at(x, y, c) - l.at(x, y, c)));
                }
            }
        EXPECT_GT(changed, 1e-3) << trial;  // tri-cubic is not the linear read
    }
    EXPECT_GT(used, 0.005);
}

TEST(CudaCurvilinearKernel, TricubicRefusalsNameTheKey) {
    // the double kernel reads exactly: the h100 unit with it is refused
    std::string m = error_of(chord_scene("composite", R"("tricubic": true, "kernel": "double", "texture_unit": "h100")"));
    EXPECT_NE(m.find("render.profile_options.tricubic"), std::string::npos) << m;
    // a Cartesian grid: seed 001 renders shells only
    std::string j = chord_scene("composite", R"("tricubic": true)");
    const auto b = j.find("\"bounds\"");
    j.erase(b, j.find('}', b) - b + 2);
    m = error_of(j);
    EXPECT_NE(m.find("tricubic"), std::string::npos) << m;
    // another profile has no such option: the loader names the key
    j = chord_scene("composite", R"("tricubic": true)");
    j.replace(j.find("cuda-curvilinear"), 16, "glsl-basic");
    m = error_of(j);
    EXPECT_NE(m.find("tricubic"), std::string::npos) << m;
}
