// Pre-integrated segments (transfer/PreIntegration.h; render.profile_options.preintegration on the fast
// profile; conventions section 9b). The segment integrals against closed forms and a brute-force
// compositing of 200 000 sub-slabs; the table's bilinear reads against the exact integrals; renders
// of a linear field (where the ramp between a segment's ends is the field itself, so the method is
// exact up to its table) against the reference at a fine step; the scene keys and refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/grid/Volume.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneWriter.h"
#include "transfer/PreIntegration.h"
#include "transfer/TransferFunction.h"

using namespace volref;
using namespace volref::test;

namespace {

// A transfer function over data values (the volume only sets the default window, unused here).
TransferFunction make_tf(std::vector<std::array<double, 4>> color, std::vector<std::array<double, 2>> opacity, double l) {
    TransferSpec spec;
    spec.color = std::move(color);
    spec.opacity = std::move(opacity);
    spec.opacity_unit_distance = l;
    static Volume v = [] {
        Volume x;
        x.dims = {2, 1, 1};
        x.type = ScalarType::F64;
        x.values = {0.0, 1.0};
        return x;
    }();
    return TransferFunction(spec, v);
}

// The segment by brute force: m sub-slabs at their midpoints, each composited exactly as a constant
// slab (alpha = 1 - exp(-sigma d / m), C += T alpha c, T *= 1 - alpha).
SegmentIntegral brute_force(const TransferFunction& tf, double xf, double xb, double d, int m = 200000) {
    SegmentIntegral s;
    double T = 1.0, tau = 0.0;
    for (int k = 0; k < m; ++k) {
        const double x = xf + (xb - xf) * (k + 0.5) / m;
        const double a = std::min(tf.opacity(x), kPreIntegrationMaxOpacity);
        const double sigma = -std::log1p(-a) / tf.unit_distance();
        const double alpha = -std::expm1(-sigma * d / m);
        s.colour += T * alpha * tf.color(x);
        T *= 1.0 - alpha;
        tau += sigma / m;
    }
    s.sigma_bar = tau;
    s.alpha = 1.0 - T;
    return s;
}

double F(double a) { return (1.0 - a) * std::log1p(-a) + a; }

}  // namespace

// Constant opacity and colour: sigma_bar = -log(1 - a) / l, alpha = 1 - exp(-sigma d), C = c alpha.
TEST(PreIntegration, ConstantClosedForm) {
    const TransferFunction tf = make_tf({{0, 0.2, 0.5, 0.9}}, {{0, 0.3}}, 2.0);
    const double sigma = -std::log(0.7) / 2.0;
    for (double d : {0.1, 1.0, 7.0})
        for (auto [xf, xb] : {std::pair{0.2, 0.8}, std::pair{0.9, 0.1}, std::pair{0.4, 0.4}}) {
            const SegmentIntegral s = segment_integral(tf, xf, xb, d);
            EXPECT_NEAR(s.sigma_bar, sigma, 1e-15);
            EXPECT_NEAR(s.alpha, 1.0 - std::exp(-sigma * d), 1e-15);
            EXPECT_NEAR(s.colour.r, 0.2 * s.alpha, 1e-14);
            EXPECT_NEAR(s.colour.b, 0.9 * s.alpha, 1e-14);
        }
}

// An opacity ramp a(x) = 0.8 x and a constant colour: sigma_bar l = (F(a_b) - F(a_f)) / (a_b - a_f),
// F(a) = (1 - a) log(1 - a) + a, whatever the direction; the colour is c alpha (C = c (1 - T_end)).
TEST(PreIntegration, OpacityRampClosedForm) {
    const TransferFunction tf = make_tf({{0, 1.0, 0.5, 0.25}}, {{0, 0}, {1, 0.8}}, 1.5);
    for (auto [xf, xb] : {std::pair{0.1, 0.9}, std::pair{0.95, 0.2}, std::pair{0.0, 1.0}}) {
        const double af = 0.8 * xf, ab = 0.8 * xb;
        const double sigma_bar = (F(ab) - F(af)) / (ab - af) / 1.5;
        const SegmentIntegral s = segment_integral(tf, xf, xb, 3.0);
        EXPECT_NEAR(s.sigma_bar, sigma_bar, 1e-14 * sigma_bar);
        EXPECT_NEAR(s.alpha, -std::expm1(-3.0 * sigma_bar), 1e-14);
        EXPECT_NEAR(s.colour.g, 0.5 * s.alpha, 1e-12);
    }
}

// A colour ramp c(x) = x in constant opacity: the attenuation inside the segment weights its front,
//   C = x_f (1 - e^-k) + (x_b - x_f) ((1 - e^-k) / k - e^-k),  k = d sigma.
TEST(PreIntegration, ColourWeightedByAttenuationClosedForm) {
    const TransferFunction tf = make_tf({{0, 0, 0, 0}, {1, 1, 1, 1}}, {{0, 0.6}}, 1.0);
    const double sigma = -std::log(0.4);
    for (double d : {0.5, 2.0, 6.0}) {
        const double xf = 0.2, xb = 0.9, k = d * sigma;
        const double C = xf * (1 - std::exp(-k)) + (xb - xf) * ((1 - std::exp(-k)) / k - std::exp(-k));
        const SegmentIntegral s = segment_integral(tf, xf, xb, d);
        EXPECT_NEAR(s.colour.r, C, 1e-13) << d;
        // The naive average colour (x_f + x_b) / 2 is what attenuation moves away from.
        EXPECT_GT(std::fabs(s.colour.r / s.alpha - 0.55), 0.01 * (d > 1.0));
    }
}

// A tent of opacity with a colour ramp (rows inside the segment, pieces, both directions) against
// brute-force compositing: the closed-form depth and K15 colour agree to the brute force's own error.
TEST(PreIntegration, TentAgainstBruteForce) {
    const TransferFunction tf = make_tf({{0.0, 0.1, 0.2, 0.6}, {0.45, 0.25, 0.5, 0.95}, {0.5, 1.0, 0.85, 0.4}, {1.0, 0.9, 0.1, 0.05}},
                                        {{0.0, 0.0}, {0.44, 0.0}, {0.5, 0.5}, {0.56, 0.0}, {1.0, 1.0}}, 4.0);
    for (auto [xf, xb, d] : {std::tuple{0.3, 0.7, 4.0}, std::tuple{0.52, 0.41, 1.0}, std::tuple{0.47, 0.47, 2.0}}) {
        const SegmentIntegral s = segment_integral(tf, xf, xb, d), b = brute_force(tf, xf, xb, d);
        EXPECT_NEAR(s.sigma_bar, b.sigma_bar, 1e-8) << xf << " " << xb;
        EXPECT_NEAR(s.alpha, b.alpha, 1e-8);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.colour[c], b.colour[c], 1e-8);
    }
    // Up to x = 1, where the opacity reaches 1: clamped at kPreIntegrationMaxOpacity from
    // x* = 0.56 + 0.44 a_max on. By hand: the tent's two pieces give F(0.5) 0.06 / 0.5 each, the last
    // F(a_max) 0.44 + (-log(1 - a_max)) (1 - x*); over l (x_b - x_f) = 4 x 0.9. The brute force's
    // midpoints meet sigma's logarithmic peak there, so it is only good to about 1e-6.
    const double am = kPreIntegrationMaxOpacity, xs = 0.56 + 0.44 * am;
    const double by_hand = (2 * F(0.5) * 0.06 / 0.5 + F(am) * 0.44 - std::log1p(-am) * (1 - xs)) / (4 * 0.9);
    const SegmentIntegral s = segment_integral(tf, 0.1, 1.0, 8.0), b = brute_force(tf, 0.1, 1.0, 8.0);
    EXPECT_NEAR(s.sigma_bar, by_hand, 1e-15);
    EXPECT_NEAR(s.sigma_bar, b.sigma_bar, 2e-6);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.colour[c], b.colour[c], 2e-6);
}

// The table read bilinearly: at its nodes it is segment_integral's value (float rounding); between
// nodes its error against the exact integral falls about 4 times when the node count doubles (second
// order) where the transfer function is smooth (one row segment), and about 2 times (first order)
// where rows put kinks in it (the benchmark's tent).
namespace {
void table_convergence(const TransferFunction& tf, double ratio, double finest) {
    const double h = 2.0;
    double err[3] = {};
    const int ns[3] = {16, 32, 64};
    for (int q = 0; q < 3; ++q) {
        const PreIntegrationTable t = build_preintegration_table(tf, 0.0, 1.0, h, ns[q]);
        double e[4];
        lookup_preintegration(t, 3 * t.dx, 7 * t.dx, e);  // a node
        const SegmentIntegral at = segment_integral(tf, 3 * t.dx, 7 * t.dx, h);
        EXPECT_NEAR(e[0], at.sigma_bar, 1e-6 * at.sigma_bar);
        EXPECT_NEAR(e[1], at.colour.r / at.alpha, 1e-6);
        for (int k = 0; k < 200; ++k) {  // between nodes
            const double xf = std::fmod(0.137 + 0.618034 * k, 1.0), xb = std::fmod(0.291 + 0.414214 * k * k, 1.0);
            lookup_preintegration(t, xf, xb, e);
            const SegmentIntegral x = segment_integral(tf, xf, xb, h);
            err[q] = std::max({err[q], std::fabs(e[0] - x.sigma_bar), std::fabs(e[1] - x.colour.r / x.alpha)});
        }
    }
    std::printf("table error at 16, 32, 64 intervals: %.3g %.3g %.3g\n", err[0], err[1], err[2]);
    EXPECT_LT(err[1], ratio * err[0]);
    EXPECT_LT(err[2], ratio * err[1]);
    EXPECT_LT(err[2], finest);
}
}  // namespace

TEST(PreIntegration, TableReadsAgainstExactIntegrals) {
    table_convergence(make_tf({{0, 0.2, 0.4, 0.9}, {1, 0.9, 0.6, 0.1}}, {{0, 0.05}, {1, 0.6}}, 1.0), 0.35, 1e-4);
    table_convergence(make_tf({{0, 0.2, 0.4, 0.9}, {1, 0.9, 0.6, 0.1}}, {{0, 0.05}, {0.5, 0.4}, {1, 0.1}}, 1.0), 0.6, 3e-3);
}

namespace {

// A linear field f = (x + 0.3 y + 0.2 z) / 31 on 32^3 with the benchmark's tent (opacity unit distance
// 4), seen obliquely: trilinear reconstruction of a linear field is the field itself, so along every
// segment the value is exactly linear and pre-integration is exact up to its table and float rounding.
Scene linear_tent_scene() {
    Scene s = field_scene(linear_field({1.0 / 31, 0.3 / 31, 0.2 / 31, 0.0}, {32, 32, 32}));
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.6}, {0.45, 0.25, 0.5, 0.95}, {0.5, 1.0, 0.85, 0.4}, {0.55, 1.0, 0.45, 0.15}, {1.5, 0.9, 0.1, 0.05}};
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.44, 0.0}, {0.5, 0.5}, {0.56, 0.0}, {1.5, 0.0}};
    s.volume().transfer.opacity_unit_distance = 4.0;
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {80, -30, 60};
    s.camera.target = {15.5, 15.5, 15.5};
    s.camera.up = {0, 0, 1};
    s.camera.fov_y = 40;
    s.image.width = s.image.height = 48;
    s.render.step_units = StepUnits::Voxel;
    return s;
}

double max_diff(const Image& a, const Image& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) m = std::max(m, std::fabs(a.pixels[i] - b.pixels[i]));
    return m;
}

}  // namespace

TEST(PreIntegration, LinearFieldRendersExactlyAtLongSteps) {
    Scene s = linear_tent_scene();
    s.render.step = 1.0 / 32;
    const Image ref = render_scene(s, {.threads = 2});
    double alpha_max = 0.0;
    for (std::size_t i = 3; i < ref.pixels.size(); i += 4) alpha_max = std::max(alpha_max, ref.pixels[i]);
    ASSERT_GT(alpha_max, 0.3);
    s.render.profile = ProfileId::Fast;
    for (double step : {1.0, 4.0}) {
        s.render.step = step;
        s.render.profile_options.preintegration = 0;
        const double point = max_diff(render_scene(s, {.threads = 2}), ref);
        s.render.profile_options.preintegration = 1024;
        const double pre = max_diff(render_scene(s, {.threads = 2}), ref);
        std::printf("step %g: max |fast - reference at 1/32| = %.3g (midpoints), %.3g (pre-integrated, 1024)\n", step, point, pre);
        // The bound of conventions 9b for a linear field: the table's error (about 1e-4 here), the
        // colour of the shorter last segment of each interval read at d = h, float rounding.
        EXPECT_LT(pre, step > 1.0 ? 3e-3 : 5e-4);
        if (step > 1.0) EXPECT_GT(point, 10 * pre);  // what the midpoints miss at this step
    }
}

// Skipping passes over a segment only where both of its ends lie in empty macrocells: the image with
// skipping is the image without it, up to the table's reads of ramps whose exact integral is 0.
TEST(PreIntegration, SkippingKeepsTheImage) {
    Scene s = linear_tent_scene();
    s.render.profile = ProfileId::Fast;
    s.render.profile_options.preintegration = 256;
    for (double step : {0.5, 3.0, 20.0}) {
        s.render.step = step;
        const Image a = render_scene(s, {.threads = 1}), b = render_scene(s, {.threads = 2, .empty_space_skipping = false});
        EXPECT_LT(max_diff(a, b), 1e-6) << step;
    }
}

TEST(PreIntegration, SceneKeysAndRefusals) {
    auto scene = [](const std::string& render) {
        return R"({"volume": {"source": {"field": "linear", "dims": [8, 8, 8], "coefficients": [0.1, 0, 0, 0]}},
                  "render": )" + render + "}";
    };
    const Scene s = parse_scene(scene(R"({"profile": "fast", "profile_options": {"preintegration": 64}})"), ".", "test.json");
    EXPECT_EQ(s.render.profile_options.preintegration, 64);
    // Written and read again.
    const Scene again = parse_scene(scene_json(s).dump(), ".", "again.json");
    EXPECT_EQ(again.render.profile_options.preintegration, 64);
    auto error = [&](const std::string& render) {
        try {
            render_scene(parse_scene(scene(render), ".", "test.json"), {.threads = 1});
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(error(R"({"profile": "fast", "profile_options": {"preintegration": 1}})").find("preintegration"), std::string::npos);
    EXPECT_NE(error(R"({"profile": "fast", "profile_options": {"preintegration": 4096}})").find("preintegration"), std::string::npos);
    EXPECT_NE(error(R"({"profile": "reference", "profile_options": {"preintegration": 64}})").find("profile_options"), std::string::npos);
    EXPECT_NE(error(R"({"profile": "fast", "projection": "mip", "profile_options": {"preintegration": 64}})")
                  .find("render.profile_options.preintegration: pre-integrated segments composite"),
              std::string::npos);
    Scene shaded = s;
    shaded.volume().shading = ShadingSpec{};
    try {
        render_scene(shaded, {.threads = 1});
        ADD_FAILURE() << "a shaded pre-integrated scene rendered";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("do not shade"), std::string::npos) << e.what();
    }
}
