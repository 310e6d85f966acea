// Cameras: pixel centres, perspective and orthographic rays, and OpenGL matrices giving the same rays.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>

#include "core/camera/Camera.h"

using namespace volref;

namespace {
CameraSpec perspective() {
    CameraSpec c;
    c.type = CameraSpec::Type::Perspective;
    c.eye = {1, 2, 10};
    c.target = {1, 2, 0};
    c.up = {0, 1, 0};
    c.fov_y = 60;
    return c;
}
// Every pixel of a 6 x 4 image gets the same ray from both cameras.
void expect_same_rays(const CameraSpec& a_spec, const CameraSpec& b_spec) {
    const Camera a(a_spec, 6, 4, glm::dvec3(0), glm::dvec3(1)), b(b_spec, 6, 4, glm::dvec3(0), glm::dvec3(1));
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 6; ++x) {
            const Ray ra = a.pixel_ray(x, y), rb = b.pixel_ray(x, y);
            EXPECT_NEAR(glm::length(ra.direction - rb.direction), 0.0, 1e-12);
            EXPECT_NEAR(glm::length(ra.origin - rb.origin), 0.0, 1e-9);
        }
}
}  // namespace

TEST(Camera, PerspectiveCornersAndCentre) {
    const Camera cam(perspective(), 4, 2, glm::dvec3(0), glm::dvec3(1));
    // The image centre (2, 1) looks at the target.
    const Ray c = cam.ray(2.0, 1.0);
    EXPECT_NEAR(c.direction.z, -1.0, 1e-15);
    // Pixel (3, 0)'s centre is at nx = 0.75, ny = 0.5; tan(30 deg) = 1/sqrt(3); aspect 2.
    const Ray r = cam.pixel_ray(3, 0);
    const double t = 1.0 / std::sqrt(3.0);
    const glm::dvec3 expected = glm::normalize(glm::dvec3(0.75 * t * 2.0, 0.5 * t, -1.0));
    EXPECT_NEAR(r.direction.x, expected.x, 1e-15);
    EXPECT_NEAR(r.direction.y, expected.y, 1e-15);
    EXPECT_NEAR(r.direction.z, expected.z, 1e-15);
    EXPECT_EQ(r.origin, glm::dvec3(1, 2, 10));
}

TEST(Camera, OrthographicOrigins) {
    CameraSpec c = perspective();
    c.type = CameraSpec::Type::Orthographic;
    c.height = 4.0;
    const Camera cam(c, 4, 4, glm::dvec3(0), glm::dvec3(1));
    const Ray r = cam.pixel_ray(0, 0);  // top left: x = 1 - 1.5, y = 2 + 1.5
    EXPECT_NEAR(r.origin.x, -0.5, 1e-15);
    EXPECT_NEAR(r.origin.y, 3.5, 1e-15);
    EXPECT_EQ(r.origin.z, 10.0);
    EXPECT_EQ(r.direction, glm::dvec3(0, 0, -1));
}

// A GPU program's view and projection matrices (glm::lookAt / glm::perspective / glm::ortho, as
// OpenGL programs build them) give the same rays as the equivalent camera.
TEST(Camera, MatricesMatchPerspectiveAndOrthographic) {
    const CameraSpec p = perspective();
    CameraSpec m;
    m.type = CameraSpec::Type::Matrices;
    m.view = glm::lookAt(p.eye, p.target, p.up);
    m.projection = glm::perspective(p.fov_y * std::numbers::pi / 180.0, 3.0 / 2.0, 0.1, 100.0);
    expect_same_rays(p, m);
    CameraSpec o = p;
    o.type = CameraSpec::Type::Orthographic;
    o.height = 4.0;
    m.projection = glm::ortho(-3.0, 3.0, -2.0, 2.0, 0.1, 100.0);
    expect_same_rays(o, m);
}

// The default camera looks along -z at the bounds' centre from d = R / sin(15 deg).
TEST(Camera, DefaultFitsTheBoundingSphere) {
    CameraSpec c;  // Type::Default
    const Camera cam(c, 8, 8, glm::dvec3(0, 0, 0), glm::dvec3(2, 2, 2));
    const Ray r = cam.ray(4.0, 4.0);
    const double d = std::sqrt(3.0) / std::sin(15.0 * std::numbers::pi / 180.0);
    EXPECT_NEAR(r.origin.x, 1.0, 1e-15);
    EXPECT_NEAR(r.origin.y, 1.0, 1e-15);
    EXPECT_NEAR(r.origin.z, 1.0 + d, 1e-13);
    EXPECT_NEAR(r.direction.z, -1.0, 1e-15);
}

// Camera::pixel_rays (SIMD lanes for the perspective and orthographic cameras, CameraRays.cpp) gives
// each pixel the ray of Camera::pixel_ray, and both give the rays of the formula of conventions section
// 10 evaluated here with glm, as the camera did before its lane template (the second method: glm's
// normalize is v * (1 / sqrt(dot(v, v)))), bit for bit; for batches of every length up to 40 and an
// oblique camera (no zero component), including the matrices camera (one by one).
TEST(Camera, PixelRaysAreTheFormulaBitForBit) {
    CameraSpec p;
    p.type = CameraSpec::Type::Perspective;
    p.eye = {7.25, -3.5, 11.0};
    p.target = {0.3, 0.2, -0.1};
    p.up = {0.1, 0.2, 1.0};
    p.fov_y = 37;
    CameraSpec o = p;
    o.type = CameraSpec::Type::Orthographic;
    o.height = 9.5;
    CameraSpec m;
    m.type = CameraSpec::Type::Matrices;
    m.view = glm::lookAt(p.eye, p.target, p.up);
    m.projection = glm::perspective(p.fov_y * std::numbers::pi / 180.0, 13.0 / 7.0, 0.1, 100.0);
    const int W = 13, H = 7;
    for (const CameraSpec& spec : {p, o, m}) {
        const Camera cam(spec, W, H, glm::dvec3(0), glm::dvec3(1));
        // The formula with glm.
        const glm::dvec3 f = glm::normalize(spec.target - spec.eye), r = glm::normalize(glm::cross(f, spec.up)),
                         u = glm::cross(r, f);
        const double aspect = double(W) / double(H), tan_half = std::tan(spec.fov_y * std::numbers::pi / 180.0 / 2.0);
        std::vector<int> xs, ys;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) xs.push_back(x), ys.push_back(y);
        for (int first = 0; first + 40 <= int(xs.size()); first += 17)
            for (int count = 1; count <= 40; ++count) {
                std::vector<Ray> rays(static_cast<std::size_t>(count));
                cam.pixel_rays(xs.data() + first, ys.data() + first, count, rays.data());
                for (int i = 0; i < count; ++i) {
                    const int x = xs[std::size_t(first + i)], y = ys[std::size_t(first + i)];
                    const Ray one = cam.pixel_ray(x, y);
                    EXPECT_EQ(rays[std::size_t(i)].origin, one.origin);
                    EXPECT_EQ(rays[std::size_t(i)].direction, one.direction);
                    if (spec.type == CameraSpec::Type::Matrices) continue;
                    const double nx = 2.0 * (x + 0.5) / double(W) - 1.0, ny = 1.0 - 2.0 * (y + 0.5) / double(H);
                    if (spec.type == CameraSpec::Type::Perspective) {
                        EXPECT_EQ(one.origin, spec.eye);
                        EXPECT_EQ(one.direction, glm::normalize(f + (nx * tan_half * aspect) * r + (ny * tan_half) * u));
                    } else {
                        EXPECT_EQ(one.origin, spec.eye + (nx * (spec.height / 2.0) * aspect) * r + (ny * (spec.height / 2.0)) * u);
                        EXPECT_EQ(one.direction, f);
                    }
                }
            }
    }
}
