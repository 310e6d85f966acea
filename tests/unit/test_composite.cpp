// Compositing against closed forms (conventions sections 3 to 5).
#include <gtest/gtest.h>

#include <cmath>

#include "TestScenes.h"

using namespace volref;
using namespace volref::test;

// A constant field in a box seen orthographically: along a chord of length L the segments' opacities
// multiply to (1 - a)^(L / l) whatever the steps, so alpha = 1 - (1 - a)^(L / l) and the colour is
// c * alpha. L is set with the box bounds; steps that do not divide L included.
TEST(Composite, ConstantFieldClosedForm) {
    for (double L : {0.3, 1.0, 2.0, 3.7})
        for (double l : {0.5, 1.0, 2.5})
            for (double h : {0.1, 0.25, 0.3, 0.7, 5.0})
                for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
                    Scene s = field_scene(constant_field(2.0, {5, 5, 5}));  // domain [0, 4]^3
                    s.volume().bounds.min = glm::dvec3(0.0, 0.0, 0.2);
                    s.volume().bounds.max = glm::dvec3(4.0, 4.0, 0.2 + L);
                    const double a = 0.35;
                    s.volume().transfer.opacity = {{0.0, a}};
                    s.volume().transfer.color = {{0.0, 0.2, 0.6, 0.9}};
                    s.volume().transfer.opacity_unit_distance = l;
                    s.camera = ortho_down_z(2.0, 2.0, 10.0, 1.0);
                    s.image.width = s.image.height = 1;
                    s.render.step = h;
                    s.render.step_units = StepUnits::World;
                    s.render.order = order;
                    const Image im = render_scene(s, {1, false});
                    const double alpha = 1.0 - std::pow(1.0 - a, L / l);
                    const glm::dvec4 p = rgba(im, 0, 0);
                    EXPECT_NEAR(p.a, alpha, 1e-14) << "L=" << L << " l=" << l << " h=" << h;
                    EXPECT_NEAR(p.r, 0.2 * alpha, 1e-14);
                    EXPECT_NEAR(p.g, 0.6 * alpha, 1e-14);
                    EXPECT_NEAR(p.b, 0.9 * alpha, 1e-14);
                }
}

// Opacity 1 is opaque: the pixel is the colour of the first segment, alpha exactly 1.
TEST(Composite, OpaqueSegment) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {3, 3, 5}));  // f = z on [0, 4]
    s.volume().transfer.opacity = {{0.0, 0.0}, {3.0, 0.0}, {3.0, 1.0}};  // opaque where f >= 3
    s.volume().transfer.color = {{0.0, 0, 0, 0}, {4.0, 1, 1, 1}};
    s.camera = ortho_down_z(1.0, 1.0, 10.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
        s.render.order = order;
        const glm::dvec4 p = rgba(render_scene(s, {1, false}), 0, 0);
        // The first midpoint is z = 3.75 (f = 3.75, colour 3.75 / 4).
        EXPECT_EQ(p.a, 1.0);
        EXPECT_NEAR(p.r, 3.75 / 4.0, 1e-15);
    }
}

namespace {
// A smooth scene: a Gaussian blob, smooth ramps, perspective camera.
Scene smooth_scene(double step) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {65, 65, 65};  // spacing 0.25 over [0, 16]^3: small kinks at cell faces
    g.center = {8.0, 8.0, 8.0};
    g.sigma = 4.0;
    g.amplitude = 1.0;
    Scene s = field_scene(g, glm::dvec3(0.0), glm::dvec3(0.25));
    s.volume().transfer.opacity = {{0.0, 0.0}, {1.0, 0.6}};
    s.volume().transfer.color = {{0.0, 0.2, 0.3, 1.0}, {1.0, 1.0, 0.8, 0.1}};
    s.volume().transfer.opacity_unit_distance = 4.0;
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {8.0, 3.0, 40.0};
    s.camera.target = {8.0, 8.0, 8.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.fov_y = 30.0;
    s.image.width = s.image.height = 24;
    s.render.step = step;
    s.render.step_units = StepUnits::World;
    return s;
}

double rmse(const Image& a, const Image& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) sum += (a.pixels[i] - b.pixels[i]) * (a.pixels[i] - b.pixels[i]);
    return std::sqrt(sum / double(a.pixels.size()));
}
}  // namespace

// Front to back and back to front agree to rounding on a non-trivial scene.
TEST(Composite, FrontToBackEqualsBackToFront) {
    Scene s = smooth_scene(0.37);
    const Image ftb = render_scene(s, {1, false});
    s.render.order = CompositeOrder::BackToFront;
    const Image btf = render_scene(s, {1, false});
    double max_alpha = 0.0;
    for (std::size_t i = 0; i < ftb.pixels.size(); ++i) {
        EXPECT_NEAR(ftb.pixels[i], btf.pixels[i], 1e-13);
        max_alpha = std::max(max_alpha, ftb.pixels[i]);
    }
    EXPECT_GT(max_alpha, 0.3);  // the scene is not empty
}

// Midpoint sampling converges with order 2: the RMSE over the image against a fine-step reference
// falls by 4 each time the step halves; the order is the least-squares slope of log(RMSE) vs log(h).
TEST(Composite, ConvergesWithOrderTwo) {
    const Image reference = render_scene(smooth_scene(1.0 / 256.0), {0, false});
    std::vector<double> lh, le;
    for (double h : {0.613, 0.317, 0.161, 0.0787}) {
        const double e = rmse(render_scene(smooth_scene(h), {0, false}), reference);
        std::printf("h %g rmse %.6e\n", h, e);
        lh.push_back(std::log(h));
        le.push_back(std::log(e));
    }
    const double n = double(lh.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < lh.size(); ++i) {
        sx += lh[i];
        sy += le[i];
        sxx += lh[i] * lh[i];
        sxy += lh[i] * le[i];
    }
    const double order = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    EXPECT_GE(order, 1.8) << "measured order " << order;
    EXPECT_LE(order, 2.3) << "measured order " << order;
}

// Early termination stops once alpha exceeds the threshold (front to back).
TEST(Composite, EarlyTermination) {
    Scene s = field_scene(constant_field(1.0, {3, 3, 11}));  // z in [0, 10]
    s.volume().transfer.opacity = {{0.0, 0.5}};
    s.camera = ortho_down_z(1.0, 1.0, 20.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 1.0;
    s.render.step_units = StepUnits::World;
    s.render.early_termination = 0.9;
    // After k unit segments alpha = 1 - 0.5^k: 0.875 (k = 3), 0.9375 (k = 4): stops after 4.
    EXPECT_NEAR(render_scene(s, {1, false}).at(0, 0, 3), 0.9375, 1e-15);
}
