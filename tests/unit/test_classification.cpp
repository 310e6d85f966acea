// Levoy's classification against closed forms (conventions section 7).
#include <gtest/gtest.h>

#include <cmath>

#include "TestScenes.h"
#include "transfer/BoundaryClassifier.h"
#include "transfer/IsovalueClassifier.h"
#include "transfer/TransferFunction.h"

using namespace volref;
using namespace volref::test;

namespace {

// The integral of ln(1 - a(x)) over an interval of length `len` where a goes linearly from a0 to a1:
// with G(u) = u ln u - u, it is len (G(1 - a0) - G(1 - a1)) / (a1 - a0)  (len ln(1 - a0) if a0 = a1).
double integral_log_transparency(double a0, double a1, double len) {
    if (a0 == a1) return len * std::log1p(-a0);
    auto G = [](double u) { return u * std::log(u) - u; };
    return len * (G(1.0 - a0) - G(1.0 - a1)) / (a1 - a0);
}

// f = x on [0, 10] (|grad f| = 1), looked at along +x through the middle of the y-z square.
Scene along_x(FieldSpec field, double step) {
    Scene s = field_scene(field, glm::dvec3(0.0), glm::dvec3(1.0));
    s.camera.type = CameraSpec::Type::Orthographic;
    s.camera.eye = {-10.0, 1.0, 1.0};
    s.camera.target = {0.0, 1.0, 1.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.height = 0.5;
    s.image.width = s.image.height = 1;
    s.render.step = step;
    s.render.step_units = StepUnits::World;
    return s;
}

}  // namespace

TEST(IsovalueClassifier, LevoyFormula) {
    const IsovalueContour c{5.0, 0.8, 2.0, {1, 0, 0}};
    EXPECT_DOUBLE_EQ(IsovalueClassifier::contour_opacity(c, 5.0, 3.0), 0.8);
    EXPECT_DOUBLE_EQ(IsovalueClassifier::contour_opacity(c, 6.5, 1.0), 0.8 * (1.0 - 1.5 / 2.0));
    EXPECT_DOUBLE_EQ(IsovalueClassifier::contour_opacity(c, 8.0, 1.0), 0.0);  // beyond r |grad f|
    EXPECT_DOUBLE_EQ(IsovalueClassifier::contour_opacity(c, 5.0, 0.0), 0.8);  // flat, on the isovalue
    EXPECT_DOUBLE_EQ(IsovalueClassifier::contour_opacity(c, 5.1, 0.0), 0.0);  // flat, off it
    // Two contours: 1 - (1 - a1)(1 - a2), colour weighted by the a_n.
    const IsovalueClassifier two({{5.0, 0.8, 2.0, {1, 0, 0}}, {6.0, 0.5, 2.0, {0, 0, 1}}}, 1.0);
    const Classified k = two.classify(5.5, 1.0);
    const double a1 = 0.8 * (1 - 0.5 / 2), a2 = 0.5 * (1 - 0.5 / 2);
    EXPECT_DOUBLE_EQ(k.opacity, 1 - (1 - a1) * (1 - a2));
    EXPECT_DOUBLE_EQ(k.color.r, a1 / (a1 + a2));
    EXPECT_DOUBLE_EQ(k.color.b, a2 / (a1 + a2));
}

TEST(BoundaryClassifier, LevoyFormula) {
    const BoundaryClassifier b({{0.0, 0.2, {1, 0, 0}}, {10.0, 0.6, {0, 1, 0}}, {20.0, 0.0, {0, 0, 1}}}, 1.0);
    // f = 2.5 in [0, 10]: w = 0.25; a = |g| (0.6 * 0.25 + 0.2 * 0.75) = 0.3 |g|.
    Classified k = b.classify(2.5, 2.0);
    EXPECT_DOUBLE_EQ(k.opacity, 2.0 * (0.6 * 0.25 + 0.2 * 0.75));
    EXPECT_DOUBLE_EQ(k.color.r, 0.2 * 0.75 / (0.6 * 0.25 + 0.2 * 0.75));
    // f = 15: w = 0.5 between 0.6 and 0.0: a = |g| 0.3; only region 2's colour has weight.
    k = b.classify(15.0, 1.0);
    EXPECT_DOUBLE_EQ(k.opacity, 0.3);
    EXPECT_EQ(k.color, glm::dvec3(0, 1, 0));
    EXPECT_EQ(b.classify(-1.0, 5.0).opacity, 0.0);  // outside the regions
    EXPECT_EQ(b.classify(25.0, 5.0).opacity, 0.0);
    EXPECT_EQ(b.classify(5.0, 10.0).opacity, 1.0);  // clamped
}

TEST(TransferFunction, GradientOpacityModulates) {
    TransferSpec spec;
    spec.opacity = {{0, 0.5}};
    spec.gradient_opacity = {{0, 0}, {10, 1}, {20, 3}};
    Volume v;
    v.dims = {1, 1, 1};
    v.type = ScalarType::F32;
    v.values = {0};
    const TransferFunction tf(spec, v);
    EXPECT_TRUE(tf.needs_gradient());
    EXPECT_DOUBLE_EQ(tf.classify(0, 5).opacity, 0.25);
    EXPECT_DOUBLE_EQ(tf.classify(0, 12.5).opacity, 0.75);
    EXPECT_DOUBLE_EQ(tf.classify(0, 20).opacity, 1.0);  // 1.5 clamped to 1
}

// f = x seen along x: the contour's opacity is a tent of half-width r around fv, so
// alpha = 1 - exp((1 / l) * 2 * integral_{0}^{r} ln(1 - a) dx) with a going linearly from 0 to av.
// The render integrates with the midpoint rule (error <= L h^2 max|(ln(1 - a))''| / 24 / l, about
// 2e-5 here); the closed form is exact.
TEST(Classification, IsovalueTentAlongTheGradient) {
    ClassificationSpec c;
    c.type = ClassificationSpec::Type::Isovalue;
    c.isovalues = {{5.0, 0.8, 2.0, {0.2, 0.4, 0.9}}};
    c.opacity_unit_distance = 1.5;
    Scene s = along_x(linear_field({1, 0, 0, 0}, {11, 3, 3}), 0.01);
    s.volume().classification = c;
    const glm::dvec4 p = rgba(render_scene(s, {1, false}), 0, 0);
    const double alpha = -std::expm1(2.0 * integral_log_transparency(0.0, 0.8, 2.0) / 1.5);
    EXPECT_NEAR(p.a, alpha, 5e-5);
    std::printf("tent alpha %.12f closed form %.12f\n", p.a, alpha);
    EXPECT_NEAR(p.r, 0.2 * p.a, 1e-12);  // one colour: C = c alpha
    EXPECT_NEAR(p.b, 0.9 * p.a, 1e-12);
}

// Region boundaries on f = 2x (|grad f| = 2): a = 2 (linear mix of the regions' opacities), linear in
// x on each region's interval, so the same closed form applies piece by piece.
TEST(Classification, RegionBoundariesOnALinearField) {
    ClassificationSpec c;
    c.type = ClassificationSpec::Type::Boundary;
    c.regions = {{4.0, 0.05, {1, 1, 1}}, {10.0, 0.3, {1, 1, 1}}, {16.0, 0.1, {1, 1, 1}}};
    Scene s = along_x(linear_field({2, 0, 0, 0}, {11, 3, 3}), 0.01);
    s.volume().classification = c;
    const glm::dvec4 p = rgba(render_scene(s, {1, false}), 0, 0);
    // x in [2, 5]: a from 0.1 to 0.6; x in [5, 8]: a from 0.6 to 0.2; 0 elsewhere.
    const double tau = -(integral_log_transparency(0.1, 0.6, 3.0) + integral_log_transparency(0.6, 0.2, 3.0));
    EXPECT_NEAR(p.a, -std::expm1(-tau), 5e-5);
    EXPECT_NEAR(p.g, p.a, 1e-12);
}

// Pre-classification interpolates a c and a; it equals post-classification when both are affine in
// the value (constant colour, linear opacity), and differs when the opacity has a kink in a cell.
TEST(Classification, PreAndPostAgreeOnlyForLinearTransferFunctions) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {9, 9, 9};
    g.center = {4.0, 4.0, 4.0};
    g.sigma = 2.0;
    Scene s = field_scene(g);
    s.image.width = s.image.height = 12;
    s.volume().transfer.color = {{0, 0.3, 0.6, 0.9}};
    s.volume().transfer.opacity = {{0, 0.0}, {1, 0.8}};
    const Image post = render_scene(s, {1, false});
    s.volume().classify = VolumeSpec::Classify::Pre;
    const Image pre = render_scene(s, {1, false});
    double max_alpha = 0.0;
    for (std::size_t i = 0; i < post.pixels.size(); ++i) {
        EXPECT_NEAR(pre.pixels[i], post.pixels[i], 1e-13);
        max_alpha = std::max(max_alpha, post.pixels[i]);
    }
    EXPECT_GT(max_alpha, 0.2);
    // A kinked opacity (0 below 0.5, then a ramp): pre and post differ.
    s.volume().transfer.opacity = {{0, 0.0}, {0.5, 0.0}, {1, 0.8}};
    const Image pre2 = render_scene(s, {1, false});
    s.volume().classify = VolumeSpec::Classify::Post;
    const Image post2 = render_scene(s, {1, false});
    double max_diff = 0.0;
    for (std::size_t i = 0; i < post2.pixels.size(); ++i)
        max_diff = std::max(max_diff, std::fabs(pre2.pixels[i] - post2.pixels[i]));
    EXPECT_GT(max_diff, 1e-3);
}
