// First hit exact to rounding (issue 6 item 3): the first root of the cell cubics (Marmitt et al.
// 2004), against closed-form surfaces, the test's own evaluation of the trilinear field, and the
// stepped crossing.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "TestScenes.h"
#include "core/camera/Camera.h"
#include "core/render/PreparedScene.h"

using namespace volref;
using namespace volref::test;

namespace {

Scene first_hit_scene(FieldSpec f, glm::dvec3 origin, glm::dvec3 spacing, double iso, IntegrationMethod m) {
    Scene s = field_scene(std::move(f), origin, spacing);
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = iso;
    s.render.integrator = m;
    return s;
}

}  // namespace

// A linear field's isosurface is a plane, and trilinear interpolation reproduces linear fields: the
// hit is t* = (iso - a.o) / (a.d) to rounding, on oblique rays, adaptive and fixed alike.
TEST(FirstHitExact, LinearFieldPlane) {
    for (IntegrationMethod m : {IntegrationMethod::Adaptive, IntegrationMethod::Fixed}) {
        Scene s = first_hit_scene(linear_field({0.3, 0.2, 0.5, 0.1}, {6, 6, 6}), glm::dvec3(0.0), glm::dvec3(1.0), 1.7, m);
        s.camera.type = CameraSpec::Type::Perspective;
        s.camera.eye = {-3.0, 9.0, 11.0};
        s.camera.target = {2.5, 2.5, 2.5};
        s.camera.up = {0, 1, 0};
        s.camera.fov_y = 25.0;
        s.image.width = s.image.height = 8;
        s.render.step = 0.7;
        const PreparedScene p(s, {1, false});
        int hits = 0;
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const Ray ray = p.pixel_ray(x, y);
                const PixelValue v = p.render_pixel(x, y);
                const double ao = 0.3 * ray.origin.x + 0.2 * ray.origin.y + 0.5 * ray.origin.z + 0.1;
                const double ad = 0.3 * ray.direction.x + 0.2 * ray.direction.y + 0.5 * ray.direction.z;
                const double t = (1.7 - ao) / ad;
                const glm::dvec3 q = ray.at(t);
                const bool inside = q.x >= 0 && q.y >= 0 && q.z >= 0 && q.x <= 5 && q.y <= 5 && q.z <= 5;
                if (!inside) continue;
                ++hits;
                EXPECT_NEAR(v.depth, t, 1e-13 * t) << x << "," << y;
            }
        EXPECT_GT(hits, 20);
    }
}

// A radial field: the hit is a root of the trilinear interpolant of |x - c| to rounding (the test
// evaluates the interpolant itself: Levoy's weights on the voxel values |x_ijk - c|): the field
// changes sign between t (1 - 1e-12) and t (1 + 1e-12); and it is the sphere up to the interpolation
// error h^2 / (4 R cos theta) (tests/unit/test_projections.cpp). The stepped crossing (fixed, step 0.25
// voxel) finds the same root to 1e-12 wherever it finds one.
TEST(FirstHitExact, RadialFieldSphere) {
    FieldSpec radial;
    radial.kind = FieldSpec::Kind::Radial;
    radial.dims = {33, 33, 33};
    const double h = 2.4 / 32.0, R = 0.8;
    Scene s = first_hit_scene(radial, glm::dvec3(-1.2), glm::dvec3(h), R, IntegrationMethod::Adaptive);
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {0.3, 0.2, 4.0};
    s.camera.target = {0.0, 0.0, 0.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.fov_y = 30.0;
    s.image.width = s.image.height = 16;
    s.render.step = 0.25;
    const Image exact = render_scene(s, {1, false});
    s.render.integrator = IntegrationMethod::Fixed;
    const Image stepped = render_scene(s, {1, false});
    const Camera camera(s.camera, 16, 16, glm::dvec3(-1.2), glm::dvec3(1.2));
    // The test's own trilinear interpolant of the radial field.
    auto f = [&](const glm::dvec3& x) {
        const glm::dvec3 u = (x + 1.2) / h;
        const glm::dvec3 i = glm::min(glm::floor(u), glm::dvec3(31.0));
        const glm::dvec3 p = u - i;
        double sum = 0.0;
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 o((c & 1) ? 1 : 0, (c & 2) ? 1 : 0, (c & 4) ? 1 : 0);
            const double w = (o.x ? p.x : 1 - p.x) * (o.y ? p.y : 1 - p.y) * (o.z ? p.z : 1 - p.z);
            sum += w * glm::length(-1.2 + (i + o) * h);
        }
        return sum;
    };
    int checked = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const double t = exact.at(x, y, 4);
            if (std::isinf(t)) continue;
            const Ray ray = camera.pixel_ray(x, y);
            EXPECT_GT(f(ray.at(t * (1 - 1e-12))), R) << x << "," << y;  // outside before the hit
            EXPECT_LT(f(ray.at(t * (1 + 1e-12))), R) << x << "," << y;  // inside after
            const double b = glm::dot(ray.origin, ray.direction), c = glm::dot(ray.origin, ray.origin) - R * R;
            if (b * b - c > 0.0) {
                const double ts = -b - std::sqrt(b * b - c);
                const double cos_theta = std::fabs(glm::dot(glm::normalize(ray.at(ts)), ray.direction));
                if (cos_theta > 0.5) EXPECT_NEAR(t, ts, h * h / (4.0 * R * 0.5));
            }
            if (!std::isinf(stepped.at(x, y, 4))) EXPECT_NEAR(stepped.at(x, y, 4), t, 1e-12 * t);
            ++checked;
        }
    EXPECT_GT(checked, 60);
}

// Two crossings inside one cell: along the diagonal of the cell whose corners (1,0,0), (0,1,0),
// (0,0,1) are 1 (others 0), f = 3 s (1 - s)^2 (s = t / sqrt(3) from the corner (0,0,0)) rises to 4/9 at
// s = 1/3 and falls back to 0. At iso 0.4 the first root s1 solves 3 s^3 - 6 s^2 + 3 s - 0.4 = 0 on
// [0, 1/3] (found here by bisection of that polynomial). The adaptive first hit finds it; a fixed
// step of a whole diagonal sees f = 0 at both ends and misses; a small fixed step finds it exactly.
TEST(FirstHitExact, TwoCrossingsInOneCell) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Cells;
    f.dims = {2, 2, 2};
    f.values = {0, 1, 1, 0, 1, 0, 0, 0};
    double lo = 0.0, hi = 1.0 / 3.0;
    for (int it = 0; it < 200; ++it) {
        const double m = 0.5 * (lo + hi);
        (3 * m * m * m - 6 * m * m + 3 * m - 0.4 < 0 ? lo : hi) = m;
    }
    const double s1 = 0.5 * (lo + hi);
    Scene s = first_hit_scene(f, glm::dvec3(0.0), glm::dvec3(1.0), 0.4, IntegrationMethod::Adaptive);
    s.camera.type = CameraSpec::Type::Orthographic;
    s.camera.eye = {-5.0, -5.0, -5.0};
    s.camera.target = {0.5, 0.5, 0.5};
    s.camera.up = {0, 1, 0};
    s.camera.height = 1e-6;
    s.image.width = s.image.height = 1;
    const PreparedScene p(s, {1, false});
    const Ray ray = p.pixel_ray(0, 0);
    const double t_corner = glm::dot(glm::dvec3(0.0) - ray.origin, ray.direction);  // t at (0,0,0)
    const double want = t_corner + s1 * std::sqrt(3.0);
    EXPECT_NEAR(p.render_pixel(0, 0).depth, want, 1e-12 * want);
    s.render.integrator = IntegrationMethod::Fixed;
    s.render.step = 2.0;
    s.render.step_units = StepUnits::World;
    EXPECT_TRUE(std::isinf(PreparedScene(s, {1, false}).render_pixel(0, 0).depth));
    s.render.step = 0.05;
    EXPECT_NEAR(PreparedScene(s, {1, false}).render_pixel(0, 0).depth, want, 1e-12 * want);
}

// A ray exactly along a cell face (x = 2 in a linear field f = z + 0.1 x): no plane crossing on that
// axis, the hit is still z = iso - 0.2.
TEST(FirstHitExact, RayAlongACellFace) {
    Scene s = first_hit_scene(linear_field({0.1, 0.0, 1.0, 0.0}, {5, 5, 5}), glm::dvec3(0.0), glm::dvec3(1.0), 2.45,
                              IntegrationMethod::Adaptive);
    s.camera = ortho_down_z(2.0, 3.0, 10.0, 1.0);  // the ray x = 2, y = 3: along an edge of four cells
    s.image.width = s.image.height = 1;
    const PixelValue v = PreparedScene(s, {1, false}).render_pixel(0, 0);
    EXPECT_NEAR(v.depth, 10.0 - 2.25, 1e-13);
}

namespace {

// Issue 18, case 2: a 2 x 2 x 4 grid whose values depend on k alone: 0.2, 1.0, NaN, 0.3. The cell
// k in [0, 1] is finite (f = 0.2 + 0.8 z); the cells above it have a NaN corner. An orthographic ray
// down -z from z = 10 reaches the finite cell through the plane z = 1, where the sampler reads the
// cell above (with the NaN). The finite cell must be integrated in full: its maximum 1.0 is at z = 1,
// and f = 0.9 at z = 0.875 (t = 9.125).
Scene nan_above_a_finite_cell(Projection projection, IntegrationMethod method) {
    FieldSpec cells;
    cells.kind = FieldSpec::Kind::Cells;
    cells.dims = {2, 2, 4};
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (double v : {0.2, 1.0, nan, 0.3})
        for (int n = 0; n < 4; ++n) cells.values.push_back(v);
    Scene s = field_scene(cells);
    s.volume().transfer.color = {{0.0, 1.0, 1.0, 1.0}};
    s.volume().transfer.opacity = {{0.0, 0.0}, {1.0, 1.0}};  // a = f
    s.camera = ortho_down_z(0.5, 0.5, 10.0, 0.5);
    s.image.width = s.image.height = 1;
    s.render.projection = projection;
    s.render.integrator = method;
    s.render.step = 0.5;
    if (projection == Projection::FirstHit) s.render.isovalue = 0.9;
    return s;
}

}  // namespace

TEST(FirstHitExact, NanCellsDoNotHideTheFiniteCellBesideThem) {
    for (IntegrationMethod m : {IntegrationMethod::Fixed, IntegrationMethod::Adaptive}) {
        const Image hit = render_scene(nan_above_a_finite_cell(Projection::FirstHit, m), {.threads = 1});
        EXPECT_NEAR(hit.at(0, 0, 4), 9.125, 1e-12) << "first hit, method " << int(m);
    }
    // The adaptive MIP finds the cell's maximum on its face: a = 1, the pixel (1, 1, 1, 1).
    const Image mip = render_scene(nan_above_a_finite_cell(Projection::Mip, IntegrationMethod::Adaptive), {.threads = 1});
    for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(mip.at(0, 0, c), 1.0, 1e-12) << "mip channel " << c;
}
