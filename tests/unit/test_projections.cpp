// mip, minip, average, xray and first-hit against closed forms (conventions section 6).
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "TestScenes.h"
#include "core/camera/Camera.h"

using namespace volref;
using namespace volref::test;

namespace {

// f = x + 2y + 3z + 1 on [0, 4]^3, 4 x 4 orthographic pixels covering the domain from above:
// pixel (px, py) looks along -z at x = 0.5 + px, y = 3.5 - py; the ray enters at z = 4 (t = 6).
Scene linear_scene(Projection projection, double step) {
    Scene s = field_scene(linear_field({1, 2, 3, 1}, {5, 5, 5}));
    s.volume().transfer.color = {{0, 0, 0, 0}, {100, 1, 1, 1}};  // c = v / 100
    s.volume().transfer.opacity = {{0, 0}, {100, 1}};          // a = v / 100
    s.camera = ortho_down_z(2.0, 2.0, 10.0, 4.0);
    s.image.width = s.image.height = 4;
    s.render.projection = projection;
    s.render.step = step;
    s.render.step_units = StepUnits::World;
    return s;
}

double f_linear(double x, double y, double z) { return x + 2 * y + 3 * z + 1; }

}  // namespace

// With h = 0.3 the chord of 4 has 14 segments: 13 of 0.3 and a last one of 0.1. The first midpoint
// is at depth 0.15 (z = 3.85), the last at depth 3.95 (z = 0.05).
TEST(Projections, MipAndMinipOfLinearField) {
    for (auto [proj, z] : {std::pair{Projection::Mip, 3.85}, std::pair{Projection::Minip, 0.05}}) {
        const Image im = render_scene(linear_scene(proj, 0.3), {1, false});
        for (int py = 0; py < 4; ++py)
            for (int px = 0; px < 4; ++px) {
                const double v = f_linear(0.5 + px, 3.5 - py, z);
                const glm::dvec4 p = rgba(im, px, py);
                EXPECT_NEAR(p.a, v / 100.0, 1e-13);
                EXPECT_NEAR(p.r, (v / 100.0) * (v / 100.0), 1e-13);
            }
    }
}

// The length-weighted mean of a linear field along a chord is its value at the chord's midpoint
// (z = 2), and the midpoint rule is exact for it; x-ray is gain * L * that value.
TEST(Projections, AverageAndXrayOfLinearField) {
    const Image avg = render_scene(linear_scene(Projection::Average, 0.3), {1, false});
    Scene xs = linear_scene(Projection::Xray, 0.3);
    xs.render.gain = 0.5;
    const Image xray = render_scene(xs, {1, false});
    for (int py = 0; py < 4; ++py)
        for (int px = 0; px < 4; ++px) {
            const double mean = f_linear(0.5 + px, 3.5 - py, 2.0);
            EXPECT_NEAR(avg.at(px, py, 0), mean, 1e-12);
            EXPECT_EQ(avg.at(px, py, 3), 1.0);
            EXPECT_NEAR(xray.at(px, py, 1), 0.5 * 4.0 * mean, 1e-12);
        }
}

// First hit on f = z at iso 2.7: the plane z = 2.7 is met at t = 10 - 2.7 = 7.3 by every ray.
TEST(Projections, FirstHitOnAPlane) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {5, 5, 5}));
    s.volume().transfer.color = {{0, 0, 0, 0}, {4, 1, 0.5, 0.25}};
    s.camera = ortho_down_z(2.0, 2.0, 10.0, 4.0);
    s.image.width = s.image.height = 4;
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = 2.7;
    s.render.step = 0.3;
    s.render.step_units = StepUnits::World;
    const Image im = render_scene(s, {1, false});
    ASSERT_EQ(im.channels.size(), 5u);
    EXPECT_EQ(im.channels[4], "Z");
    for (int py = 0; py < 4; ++py)
        for (int px = 0; px < 4; ++px) {
            EXPECT_NEAR(im.at(px, py, 4), 7.3, 4.0 * 1e-9 + 1e-12);  // 1e-9 of the chord (4)
            EXPECT_NEAR(im.at(px, py, 0), 2.7 / 4.0, 1e-8);
            EXPECT_EQ(im.at(px, py, 3), 1.0);
        }
}

// First hit on a radial field at iso R is the sphere |x - c| = R, up to the trilinear interpolation
// error of the distance function. That error is at most (h^2 / 8) * trace(Hessian) = h^2 / (4 r)
// (Hessian of |x| is (I - n n^T) / r), and |grad f| = 1, so along a ray meeting the sphere at angle
// theta to the normal the hit moves by at most h^2 / (4 R cos theta). Pixels with cos theta < 0.5
// (near the silhouette) are skipped; rays that miss the sphere by a margin must miss.
TEST(Projections, FirstHitOnARadialFieldIsTheSphere) {
    FieldSpec radial;
    radial.kind = FieldSpec::Kind::Radial;
    radial.dims = {65, 65, 65};
    radial.center = {0.0, 0.0, 0.0};
    const double h = 2.4 / 64.0, R = 0.8;
    Scene s = field_scene(radial, glm::dvec3(-1.2), glm::dvec3(h));
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {0.3, 0.2, 4.0};
    s.camera.target = {0.0, 0.0, 0.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.fov_y = 30.0;
    s.image.width = s.image.height = 32;
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = R;
    s.render.step = 0.25;
    const Image im = render_scene(s, {0, false});
    const Camera camera(s.camera, 32, 32, glm::dvec3(-1.2), glm::dvec3(1.2));
    const double bound = h * h / (4.0 * R * 0.5);
    int checked = 0, missed = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            const Ray ray = camera.pixel_ray(x, y);
            const double b = glm::dot(ray.origin, ray.direction);
            const double c = glm::dot(ray.origin, ray.origin) - R * R;
            const double disc = b * b - c;
            if (disc > 0.0) {
                const double t = -b - std::sqrt(disc);
                const double cos_theta = std::fabs(glm::dot(glm::normalize(ray.at(t)), ray.direction));
                if (cos_theta < 0.5) continue;
                EXPECT_NEAR(im.at(x, y, 4), t, bound) << x << "," << y;
                ++checked;
            } else if (b * b - (glm::dot(ray.origin, ray.origin) - 0.85 * 0.85) < 0.0) {
                EXPECT_TRUE(std::isinf(im.at(x, y, 4)));
                EXPECT_EQ(im.at(x, y, 3), 0.0);
                ++missed;
            }
        }
    EXPECT_GT(checked, 100);
    EXPECT_GT(missed, 100);
}

// A ray that misses the volume is transparent black in every projection.
TEST(Projections, MissesAreEmpty) {
    for (auto proj : {Projection::Composite, Projection::Mip, Projection::Minip, Projection::Average, Projection::Xray}) {
        Scene s = linear_scene(proj, 0.5);
        s.camera = ortho_down_z(50.0, 50.0, 10.0, 4.0);
        const Image im = render_scene(s, {1, false});
        for (double v : im.pixels) EXPECT_EQ(v, 0.0);
    }
}
