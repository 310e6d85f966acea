// mip, minip, average, xray and first-hit against closed forms (conventions section 6).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "TestScenes.h"
#include "core/camera/Camera.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneLoader.h"

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
namespace {

// The radial field |x| on [-1.2, 1.2]^3 (65^3 voxels, h = 2.4 / 64), first hit at iso R = 0.8, seen by a
// size x size perspective camera.
constexpr double kSphereH = 2.4 / 64.0, kSphereR = 0.8;
Scene sphere_scene(int size) {
    FieldSpec radial;
    radial.kind = FieldSpec::Kind::Radial;
    radial.dims = {65, 65, 65};
    radial.center = {0.0, 0.0, 0.0};
    Scene s = field_scene(radial, glm::dvec3(-1.2), glm::dvec3(kSphereH));
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {0.3, 0.2, 4.0};
    s.camera.target = {0.0, 0.0, 0.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.fov_y = 30.0;
    s.image.width = s.image.height = size;
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = kSphereR;
    s.render.step = 0.25;
    return s;
}

}  // namespace

TEST(Projections, FirstHitOnARadialFieldIsTheSphere) {
    const double h = kSphereH, R = kSphereR;
    const Scene s = sphere_scene(32);
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

// Issue 18, case 5: the bound that holds on every pixel, silhouette included. Trilinear interpolation
// moves the field by at most eps = (h^2 / 8) max(f_xx + f_yy + f_zz) = h^2 / (4 r_min) (f = |x|: the
// Laplacian is 2 / r) over the cells the hit can lie in, r_min = R - sqrt(3) h. So the interpolated
// iso-surface lies between the spheres of radius R - eps and R + eps, and the exact first crossing of
// the interpolated field along a ray (first_crossing_exact) lies between where the ray enters the
// sphere R + eps and where it enters the sphere R - eps (or leaves R + eps, if it misses R - eps). The
// first-order h^2 / (4 R cos theta) is this interval's width for small eps; near the silhouette the
// sphere's curvature widens it (the reference scene's silhouette exceeded the first-order form 1.26x).
// A ray whose chord through R + eps is shorter than a step may miss (two crossings in one step).
TEST(Projections, FirstHitLiesBetweenTheSpheresRPlusMinusEpsilon) {
    for (const bool reference_scene : {false, true}) {
        Scene s;
        double h, R;
        glm::dvec3 centre;
        if (reference_scene) {  // reference_scenes/sphere-first-hit.json at 96 x 96
            s = load_scene(std::string(VOLREF_SOURCE_DIR) + "/reference_scenes/sphere-first-hit.json",
                           {"image.width=96", "image.height=96"});
            h = 1.0;
            R = 20.0;
            centre = glm::dvec3(32.0);
        } else {
            s = sphere_scene(64);
            h = kSphereH;
            R = kSphereR;
            centre = glm::dvec3(0.0);
        }
        const Image im = render_scene(s, {.threads = 2});
        const PreparedScene prepared(s, {});
        const double eps = h * h / (4.0 * (R - std::sqrt(3.0) * h));
        const double step = s.render.step * (s.render.step_units == StepUnits::Voxel ? h : 1.0);
        int hits = 0, silhouette = 0;
        for (int y = 0; y < s.image.height; ++y)
            for (int x = 0; x < s.image.width; ++x) {
                const Ray ray = prepared.pixel_ray(x, y);
                const glm::dvec3 o = ray.origin - centre;
                const double b = glm::dot(o, ray.direction), oo = glm::dot(o, o);
                auto chord = [&](double rho, double& t0, double& t1) {  // the ray's chord through sphere rho
                    const double disc = b * b - (oo - rho * rho);
                    if (disc < 0.0) return false;
                    t0 = -b - std::sqrt(disc);
                    t1 = -b + std::sqrt(disc);
                    return true;
                };
                double outer0, outer1, inner0, inner1;
                const bool outer = chord(R + eps, outer0, outer1), inner = chord(R - eps, inner0, inner1);
                const double z = im.at(x, y, 4);
                if (!outer) {
                    EXPECT_TRUE(std::isinf(z)) << x << "," << y;
                    continue;
                }
                if (std::isinf(z)) {  // allowed only where the chord is shorter than a step
                    EXPECT_LT(inner ? inner1 - inner0 : 0.0, 2.0 * step) << x << "," << y;
                    continue;
                }
                const double slack = 1e-9 * (outer1 - outer0) + 1e-12 * std::fabs(z);
                EXPECT_GE(z, outer0 - slack) << x << "," << y;
                EXPECT_LE(z, (inner ? inner0 : outer1) + slack) << x << "," << y;
                ++hits;
                double t0, t1;
                if (chord(R, t0, t1) && std::fabs(glm::dot(glm::normalize(ray.at(t0) - centre), ray.direction)) < 0.3)
                    ++silhouette;
            }
        EXPECT_GT(hits, 500);
        EXPECT_GT(silhouette, 20);  // the silhouette (cos theta < 0.3) is checked too
    }
}
