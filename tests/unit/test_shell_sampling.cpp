// Beam-space sampling (issue 5, items 3, 4, 6 and 7), against closed forms: shell coordinates and grid
// placement (geometry/ShellCoordinates.h), reconstruction on shells with periodic axes
// (core/sample/ShellSampler.h), Cartesian <-> shell resampling (core/sample/Resample.h), the NRRD writer
// (core/io/NrrdWriter.h) and the `volref resample` command.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/sample/Resample.h"
#include "core/io/NrrdWriter.h"
#include "core/io/VolumeReader.h"
#include "core/scene/SceneLoader.h"
#include "core/sample/ShellSampler.h"
#include "core/sample/VolumeSampler.h"
#include "geometry/ShellCoordinates.h"

namespace {

namespace fs = std::filesystem;
using namespace volref;
using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// A volume (origin 0, spacing 1) with f(i, j, k) at each sample.
Volume make_volume(const std::array<std::int64_t, 3>& dims,
                   const std::function<double(std::int64_t, std::int64_t, std::int64_t)>& f) {
    Volume v;
    v.dims = dims;
    v.values.resize(std::size_t(dims[0] * dims[1] * dims[2]));
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j)
            for (std::int64_t i = 0; i < dims[0]; ++i) v.values[v.index(i, j, k)] = f(i, j, k);
    return v;
}

// Distance between two angles in degrees, modulo 360.
double angle_distance(double a, double b) {
    const double d = std::fmod(std::abs(a - b), 360.0);
    return std::min(d, 360.0 - d);
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

// ---------------------------------------------------------------------------------------------
// Shell coordinates

TEST(ShellCoordinates, CylindricalClosedForms) {
    const glm::dvec3 c(1.0, -2.0, 0.5);
    // theta = atan2(-z, x): +x is 0, -z is 90, -x is 180, +z is 270; exact on the axes.
    const CylindricalCoordinates a = to_cylindrical(c + glm::dvec3(2.0, 3.0, 0.0), c);
    EXPECT_EQ(a.r, 2.0);
    EXPECT_EQ(a.theta, 0.0);
    EXPECT_EQ(a.h, 3.0);
    EXPECT_EQ(to_cylindrical(c + glm::dvec3(0.0, 0.0, -2.0), c).theta, 90.0);
    EXPECT_EQ(to_cylindrical(c + glm::dvec3(-2.0, 0.0, 0.0), c).theta, 180.0);
    EXPECT_EQ(to_cylindrical(c + glm::dvec3(0.0, 0.0, 2.0), c).theta, 270.0);
    EXPECT_NEAR(to_cylindrical(c + glm::dvec3(1.0, 0.0, -1.0), c).theta, 45.0, 1e-13);
    EXPECT_EQ(from_cylindrical({2.0, 90.0, 3.0}, c), c + glm::dvec3(0.0, 3.0, -2.0));
    EXPECT_EQ(from_cylindrical({2.0, 180.0, 3.0}, c), c + glm::dvec3(-2.0, 3.0, 0.0));
    EXPECT_EQ(from_cylindrical({2.0, 630.0, 3.0}, c), c + glm::dvec3(0.0, 3.0, 2.0));  // 630 = 270 + 360
    EXPECT_EQ(from_cylindrical({2.0, -90.0, 3.0}, c), c + glm::dvec3(0.0, 3.0, 2.0));
    // The axis: r = 0, theta = 0 by convention.
    const CylindricalCoordinates axis = to_cylindrical(c + glm::dvec3(0.0, 7.0, 0.0), c);
    EXPECT_EQ(axis.r, 0.0);
    EXPECT_EQ(axis.theta, 0.0);
    EXPECT_EQ(axis.h, 7.0);
    // Just either side of the seam (+x axis): theta tiny, or just below 360 but never 360.
    EXPECT_NEAR(to_cylindrical(c + glm::dvec3(1.0, 0.0, -1e-12), c).theta, 1e-12 / kDeg, 1e-14);  // z - c.z rounds
    const double below = to_cylindrical(c + glm::dvec3(1.0, 0.0, 1e-12), c).theta;
    EXPECT_LT(below, 360.0);
    EXPECT_NEAR(below, 360.0 - 1e-12 / kDeg, 1e-12);
    EXPECT_LT(to_cylindrical(c + glm::dvec3(1.0, 0.0, 1e-300), c).theta, 360.0);
}

TEST(ShellCoordinates, CylindricalRoundTrip) {
    const glm::dvec3 c(1.0, -2.0, 0.5);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    std::vector<glm::dvec3> points;
    for (int n = 0; n < 2000; ++n) points.push_back(c + glm::dvec3(u(rng), u(rng), u(rng)));
    for (double y : {-1.0, 0.0, 2.5}) {
        points.push_back(c + glm::dvec3(0.0, y, 0.0));       // on the axis
        points.push_back(c + glm::dvec3(1.5, y, 1e-15));     // the seam, from below
        points.push_back(c + glm::dvec3(1.5, y, -1e-15));    // the seam, from above
        points.push_back(c + glm::dvec3(1.5, y, 0.0));       // on the seam
        points.push_back(c + glm::dvec3(-1.5, y, 0.0));      // theta = 180
        points.push_back(c + glm::dvec3(1e-300, y, 1e-300)); // next to the axis
    }
    for (const glm::dvec3& p : points) {
        const CylindricalCoordinates s = to_cylindrical(p, c);
        ASSERT_GE(s.theta, 0.0);
        ASSERT_LT(s.theta, 360.0);
        ASSERT_GE(s.r, 0.0);
        const glm::dvec3 q = from_cylindrical(s, c);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(q[a], p[a], 1e-14 * (1.0 + std::abs(p[a]) + s.r)) << a;
    }
    // Shell -> world -> shell, including the seam and theta beyond [0, 360).
    for (double theta : {0.0, 1e-9, 45.0, 90.0, 179.999, 270.0, 359.9999999, 360.0 - 1e-12, 400.0, -30.0})
        for (double r : {0.1, 1.0, 5.0}) {
            const CylindricalCoordinates s = to_cylindrical(from_cylindrical({r, theta, 0.25}, c), c);
            EXPECT_NEAR(s.r, r, 1e-14 * r * 4);
            EXPECT_LT(angle_distance(s.theta, theta), 1e-11) << theta;
            EXPECT_NEAR(s.h, 0.25, 1e-15);
        }
}

TEST(ShellCoordinates, SphericalClosedFormsAndRoundTrip) {
    const glm::dvec3 c(-0.5, 0.25, 2.0);
    // x = R cos(lat) cos(lon), y = R sin(lat), z = -R cos(lat) sin(lon).
    EXPECT_EQ(from_spherical({2.0, 0.0, 0.0}, c), c + glm::dvec3(2.0, 0.0, 0.0));
    EXPECT_EQ(from_spherical({2.0, 90.0, 0.0}, c), c + glm::dvec3(0.0, 0.0, -2.0));
    EXPECT_EQ(from_spherical({2.0, 123.0, 90.0}, c), c + glm::dvec3(0.0, 2.0, 0.0));
    EXPECT_EQ(from_spherical({2.0, 0.0, -90.0}, c), c + glm::dvec3(0.0, -2.0, 0.0));
    const glm::dvec3 p = from_spherical({3.0, 30.0, 60.0}, c) - c;
    EXPECT_NEAR(p.x, 3.0 * 0.5 * std::sqrt(3.0) / 2.0, 1e-15);
    EXPECT_NEAR(p.y, 3.0 * std::sqrt(3.0) / 2.0, 1e-15);
    EXPECT_NEAR(p.z, -3.0 * 0.5 * 0.5, 1e-15);
    // The poles: lat +-90 exactly, lon 0 by convention; the centre: everything 0.
    const SphericalCoordinates north = to_spherical(c + glm::dvec3(0.0, 1.5, 0.0), c);
    EXPECT_EQ(north.radius, 1.5);
    EXPECT_EQ(north.lat, 90.0);
    EXPECT_EQ(north.lon, 0.0);
    EXPECT_EQ(to_spherical(c + glm::dvec3(0.0, -1.5, 0.0), c).lat, -90.0);
    const SphericalCoordinates centre = to_spherical(c, c);
    EXPECT_EQ(centre.radius, 0.0);
    EXPECT_EQ(centre.lat, 0.0);
    EXPECT_EQ(centre.lon, 0.0);

    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    std::vector<glm::dvec3> points;
    for (int n = 0; n < 2000; ++n) points.push_back(c + glm::dvec3(u(rng), u(rng), u(rng)));
    for (double y : {-2.0, 2.0}) {
        points.push_back(c + glm::dvec3(0.0, y, 0.0));     // poles
        points.push_back(c + glm::dvec3(1e-12, y, 0.0));   // next to a pole
        points.push_back(c + glm::dvec3(1.0, y, 1e-15));   // the seam
        points.push_back(c + glm::dvec3(1.0, y, -1e-15));
    }
    points.push_back(c);
    for (const glm::dvec3& q : points) {
        const SphericalCoordinates s = to_spherical(q, c);
        ASSERT_GE(s.lon, 0.0);
        ASSERT_LT(s.lon, 360.0);
        ASSERT_GE(s.lat, -90.0);
        ASSERT_LE(s.lat, 90.0);
        const glm::dvec3 back = from_spherical(s, c);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(back[a], q[a], 2e-14 * (1.0 + std::abs(q[a]) + s.radius)) << a;
    }
    for (double lon : {0.0, 1e-9, 90.0, 359.9999999, 400.0})
        for (double lat : {-89.0, -30.0, 0.0, 45.0, 89.999}) {
            const SphericalCoordinates s = to_spherical(from_spherical({2.0, lon, lat}, c), c);
            EXPECT_NEAR(s.radius, 2.0, 1e-14);
            EXPECT_NEAR(s.lat, lat, 1e-12);
            EXPECT_LT(angle_distance(s.lon, lon), 1e-9) << lon << " " << lat;  // lon is ill-conditioned near the poles
        }
}

TEST(ShellCoordinates, BoundingBoxes) {
    CylindricalShell cyl;
    cyl.center = glm::dvec3(1.0, 2.0, 3.0);
    cyl.r0 = 0.5, cyl.r1 = 2.0, cyl.a0 = 0.0, cyl.a1 = 90.0, cyl.h0 = -1.0, cyl.h1 = 1.0;
    auto box = bounding_box(cyl);  // quarter annulus in +x, -z
    EXPECT_EQ(box[0], cyl.center + glm::dvec3(0.0, -1.0, -2.0));
    EXPECT_EQ(box[1], cyl.center + glm::dvec3(2.0, 1.0, 0.0));
    cyl.a0 = 300.0, cyl.a1 = 660.0;  // a full turn
    box = bounding_box(cyl);
    EXPECT_EQ(box[0], cyl.center + glm::dvec3(-2.0, -1.0, -2.0));
    EXPECT_EQ(box[1], cyl.center + glm::dvec3(2.0, 1.0, 2.0));
    SphericalShell sph;
    sph.r0 = 1.0, sph.r1 = 2.0, sph.lat0 = 30.0, sph.lat1 = 90.0;  // a polar cap
    box = bounding_box(sph);
    EXPECT_NEAR(box[0].y, 0.5, 1e-15);  // r0 sin 30
    EXPECT_EQ(box[1].y, 2.0);
    EXPECT_NEAR(box[1].x, 2.0 * std::sqrt(3.0) / 2.0, 1e-15);  // r1 cos 30
}

TEST(ShellCoordinates, InvalidShellsAreErrors) {
    CylindricalShell c;
    c.r0 = 1.0, c.r1 = 1.0;
    EXPECT_THAT(error_of([&] { check_shell(c); }), HasSubstr("radius"));
    c.r1 = 2.0, c.a0 = 0.0, c.a1 = 361.0;
    EXPECT_THAT(error_of([&] { check_shell(c); }), HasSubstr("angle"));
    c.a1 = 360.0, c.h0 = 1.0, c.h1 = 1.0;
    EXPECT_THAT(error_of([&] { check_shell(c); }), HasSubstr("height"));
    SphericalShell s;
    s.lat1 = 91.0;
    EXPECT_THAT(error_of([&] { check_shell(s); }), HasSubstr("latitude"));
    s.lat1 = 90.0, s.axes = {0, 0, 2};
    EXPECT_THAT(error_of([&] { check_shell(s); }), HasSubstr("axes"));
    s.axes = {2, 0, 1};
    EXPECT_EQ(error_of([&] { check_shell(s); }), "(no error)");
    EXPECT_THAT(error_of([&] { static_cast<void>(ShellGrid(s, {4, 0, 4})); }), HasSubstr("dims"));
}

// ---------------------------------------------------------------------------------------------
// Grid placement

TEST(ShellGrid, NonPeriodicAndPeriodicPlacement) {
    CylindricalShell s;
    s.r0 = 1.0, s.r1 = 3.0, s.a0 = 30.0, s.a1 = 120.0, s.h0 = 0.0, s.h1 = 2.0;
    const ShellGrid wedge(s, {5, 4, 3});  // r 1, 1.5, .. 3; theta 30, 60, 90, 120; h 0, 1, 2
    EXPECT_FALSE(wedge.axis(1).periodic);
    for (std::int64_t j = 0; j < 4; ++j) {
        const CylindricalCoordinates c = to_cylindrical(wedge.sample_position(2, j, 1), s.center);
        EXPECT_NEAR(c.r, 2.0, 1e-15);
        EXPECT_NEAR(c.theta, 30.0 + 30.0 * double(j), 1e-12);
        EXPECT_NEAR(c.h, 1.0, 1e-15);
        const glm::dvec3 u = wedge.continuous_index(wedge.sample_position(2, j, 1));
        EXPECT_NEAR(u.x, 2.0, 1e-13);
        EXPECT_NEAR(u.y, double(j), 1e-12);
        EXPECT_NEAR(u.z, 1.0, 1e-15);
    }
    // u = (c - lo) (n - 1) / (hi - lo).
    EXPECT_NEAR(wedge.continuous_index(from_cylindrical({2.25, 75.0, 0.5}, s.center)).y, 1.5, 1e-12);
    EXPECT_NEAR(wedge.continuous_index(from_cylindrical({2.25, 75.0, 0.5}, s.center)).x, 2.5, 1e-13);

    // A full turn that starts at 300: sample j at 300 + 10 j, u = ((theta - 300) mod 360) n / 360.
    s.a0 = 300.0, s.a1 = 660.0;
    const ShellGrid turn(s, {5, 36, 3});
    EXPECT_TRUE(turn.axis(1).periodic);
    EXPECT_NEAR(turn.continuous_index(from_cylindrical({2.0, 295.0, 0.5}, s.center)).y, 35.5, 1e-11);
    EXPECT_NEAR(turn.continuous_index(from_cylindrical({2.0, 5.0, 0.5}, s.center)).y, 6.5, 1e-11);
    EXPECT_NEAR(turn.continuous_index(from_cylindrical({2.0, 300.0, 0.5}, s.center)).y, 0.0, 1e-11);
    for (std::int64_t j = 0; j < 36; ++j) {
        EXPECT_LT(angle_distance(to_cylindrical(turn.sample_position(0, j, 0), s.center).theta, 300.0 + 10.0 * double(j)),
                  1e-12);
        const double u = turn.continuous_index(turn.sample_position(3, j, 1)).y;
        EXPECT_GE(u, 0.0);
        EXPECT_LT(u, 36.0);
        EXPECT_LT(std::min(std::abs(u - double(j)), std::abs(u - double(j) - 36.0)), 1e-11) << j;
    }

    // A wedge over the seam, [300, 420] with 5 samples (30 degrees apart): 10 degrees is 370.
    s.a0 = 300.0, s.a1 = 420.0;
    const ShellGrid seam(s, {5, 5, 3});
    EXPECT_NEAR(seam.continuous_index(from_cylindrical({2.0, 10.0, 0.5}, s.center)).y, 70.0 / 30.0, 1e-12);
    EXPECT_NEAR(seam.continuous_index(from_cylindrical({2.0, 330.0, 0.5}, s.center)).y, 1.0, 1e-12);
    // In the gap (60, 300): to the nearer edge (index < 0 near 300, > 4 near 60).
    EXPECT_LT(seam.continuous_index(from_cylindrical({2.0, 200.0, 0.5}, s.center)).y, 0.0);
    EXPECT_GT(seam.continuous_index(from_cylindrical({2.0, 100.0, 0.5}, s.center)).y, 4.0);
    EXPECT_TRUE(seam.contains(from_cylindrical({2.0, 10.0, 0.5}, s.center)));
    EXPECT_TRUE(seam.contains(from_cylindrical({2.0, 59.0, 0.5}, s.center)));
    EXPECT_FALSE(seam.contains(from_cylindrical({2.0, 61.0, 0.5}, s.center)));
    EXPECT_FALSE(seam.contains(from_cylindrical({2.0, 200.0, 0.5}, s.center)));
    EXPECT_FALSE(seam.contains(from_cylindrical({0.5, 10.0, 0.5}, s.center)));  // r < r0
    EXPECT_FALSE(seam.contains(from_cylindrical({2.0, 10.0, 2.5}, s.center)));  // h > h1
}

// Where an angle is undefined (the axis, the poles, the centre) a point is in every range of it.
TEST(ShellGrid, TheAxisAndThePolesAreInEveryAngleRange) {
    CylindricalShell c;
    c.r0 = 0.0, c.r1 = 1.0, c.a0 = 30.0, c.a1 = 120.0;
    const ShellGrid wedge(c, {3, 4, 2});
    EXPECT_TRUE(wedge.contains(glm::dvec3(0.0, 0.5, 0.0)));                   // the axis, theta "0"
    EXPECT_FALSE(wedge.contains(glm::dvec3(1e-9, 0.5, 0.0)));                 // theta 0, off the axis
    EXPECT_FALSE(wedge.contains(glm::dvec3(0.0, 1.5, 0.0)));                  // above h1
    SphericalShell s;
    s.r0 = 0.0, s.r1 = 1.0, s.lon0 = 30.0, s.lon1 = 120.0, s.lat0 = 10.0, s.lat1 = 90.0;
    const ShellGrid cap(s, {4, 3, 2});
    EXPECT_TRUE(cap.contains(glm::dvec3(0.0, 0.5, 0.0)));                     // the north pole
    EXPECT_TRUE(cap.contains(glm::dvec3(0.0)));                               // the centre
    EXPECT_FALSE(cap.contains(glm::dvec3(0.0, -0.5, 0.0)));                   // the south pole: lat -90
    EXPECT_FALSE(cap.contains(from_spherical({0.5, 0.0, 45.0}, glm::dvec3(0.0))));  // lon 0
}

TEST(ShellGrid, SphericalAxesPermutation) {
    SphericalShell s;
    s.center = glm::dvec3(0.5, 0.0, -1.0);
    s.r0 = 1.0, s.r1 = 2.0, s.lon0 = 0.0, s.lon1 = 90.0, s.lat0 = -45.0, s.lat1 = 45.0;
    s.axes = {2, 0, 1};  // grid (radius, longitude, latitude)
    const ShellGrid g(s, {3, 4, 7});  // R 1, 1.5, 2; lon 0, 30, 60, 90; lat -45, -30, .., 45
    const glm::dvec3 u = g.continuous_index(from_spherical({1.75, 45.0, 7.5}, s.center));
    EXPECT_NEAR(u.x, 1.5, 1e-13);
    EXPECT_NEAR(u.y, 1.5, 1e-12);
    EXPECT_NEAR(u.z, 3.5, 1e-12);
    const SphericalCoordinates p = to_spherical(g.sample_position(2, 1, 6), s.center);
    EXPECT_NEAR(p.radius, 2.0, 1e-15);
    EXPECT_NEAR(p.lon, 30.0, 1e-12);
    EXPECT_NEAR(p.lat, 45.0, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Reconstruction

// A field linear in the grid index, f = i + 10 j + 100 k, is reproduced by trilinear at any shell
// point: f(x) = u0 + 10 u1 + 100 u2 with u the point's continuous index computed by hand.
TEST(ShellSampler, TrilinearReproducesAFieldLinearInTheIndex) {
    auto linear = [](std::int64_t i, std::int64_t j, std::int64_t k) { return double(i) + 10.0 * double(j) + 100.0 * double(k); };
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> t(0.0, 1.0);

    CylindricalShell c;
    c.center = glm::dvec3(0.3, -0.2, 0.1);
    c.r0 = 0.5, c.r1 = 2.0, c.a0 = 30.0, c.a1 = 120.0, c.h0 = -1.0, c.h1 = 1.0;
    const Volume vc = make_volume({5, 7, 4}, linear);
    const ShellSampler sc(vc, c, Interpolation::Trilinear);
    for (int n = 0; n < 500; ++n) {
        const double r = c.r0 + t(rng) * (c.r1 - c.r0), th = c.a0 + t(rng) * (c.a1 - c.a0), h = c.h0 + t(rng) * 2.0;
        const double expected = (r - 0.5) * 4.0 / 1.5 + 10.0 * (th - 30.0) * 6.0 / 90.0 + 100.0 * (h + 1.0) * 3.0 / 2.0;
        ASSERT_NEAR(sc.value(from_cylindrical({r, th, h}, c.center)), expected, 1e-11) << r << " " << th << " " << h;
    }

    // A spherical wedge over the longitude seam ([300, 420]) with permuted axes (radius, longitude, latitude).
    SphericalShell s;
    s.center = glm::dvec3(1.0, 2.0, 3.0);
    s.r0 = 1.0, s.r1 = 3.0, s.lon0 = 300.0, s.lon1 = 420.0, s.lat0 = -30.0, s.lat1 = 60.0;
    s.axes = {2, 0, 1};
    const Volume vs = make_volume({6, 5, 4}, linear);
    const ShellSampler ss(vs, s, Interpolation::Trilinear);
    for (int n = 0; n < 500; ++n) {
        const double R = 1.0 + 2.0 * t(rng), lon = 300.0 + 120.0 * t(rng), lat = -30.0 + 90.0 * t(rng);
        const double expected = (R - 1.0) * 5.0 / 2.0 + 10.0 * (lon - 300.0) * 4.0 / 120.0 + 100.0 * (lat + 30.0) * 3.0 / 90.0;
        ASSERT_NEAR(ss.value(from_spherical({R, lon, lat}, s.center)), expected, 1e-10) << R << " " << lon << " " << lat;
    }
}

// On a grid without periodic axes, the reconstruction at a continuous index is VolumeSampler's at
// the same index, bit for bit, for every interpolation.
TEST(ShellSampler, NonPeriodicGridMatchesVolumeSamplerBitForBit) {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> noise(-1.0, 1.0);
    const Volume v = make_volume({6, 5, 4}, [&](std::int64_t, std::int64_t, std::int64_t) { return noise(rng); });
    CylindricalShell c;
    c.r0 = 0.0, c.r1 = 1.0, c.a0 = 10.0, c.a1 = 200.0;
    std::uniform_real_distribution<double> u(-0.5, 6.0);
    for (Interpolation in : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                             Interpolation::TricubicCatmullRom}) {
        const ShellSampler shell(v, c, in);
        const VolumeSampler box(v, in);
        for (int n = 0; n < 300; ++n) {
            const glm::dvec3 p(u(rng), u(rng), u(rng));
            ASSERT_EQ(shell.index_value(p), box.value(p)) << int(in);
        }
    }
}

// A periodic axis is a clamped one over the wrapped samples (core/sample/IndexSpace.h): the shell
// sampler at index u on a full turn of n angles equals VolumeSampler, the Cartesian sampler, at u + 2
// on the same volume padded with two wrapped layers each side (n + 4 angles: j - 2 mod n). Every tap
// of the cubic (i - 1 .. i + 2) and both corners of the seam's cell lie inside the padding, so nothing
// clamps there; only the fraction's rounding differs (u - floor(u) against (u + 2) - floor(u + 2)).
// An error in the wrap (a tap taken as i - 1 + m without mod n, a seam corner clamped) is a difference
// of the size of the data's (noise in [-1, 1]).
TEST(ShellSampler, APeriodicAxisIsTheCartesianSamplerOnTheWrappedSamples) {
    std::mt19937_64 rng(29);
    std::uniform_real_distribution<double> noise(-1.0, 1.0);
    constexpr std::int64_t n = 12;
    const Volume v = make_volume({4, n, 3}, [&](std::int64_t, std::int64_t, std::int64_t) { return noise(rng); });
    const Volume padded = make_volume({4, n + 4, 3}, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        return v.at(i, ((j - 2) % n + n) % n, k);
    });
    CylindricalShell c;
    c.r0 = 0.5, c.r1 = 1.0, c.a0 = 0.0, c.a1 = 360.0, c.h0 = 0.0, c.h1 = 1.0;
    std::uniform_real_distribution<double> radial(-0.5, 3.5), angle(0.0, double(n)), height(-0.5, 2.5);
    for (Interpolation in : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                             Interpolation::TricubicCatmullRom}) {
        const ShellSampler shell(v, c, in);
        ASSERT_TRUE(shell.grid().axis(1).periodic);
        const VolumeSampler box(padded, in);
        double worst = 0.0;
        for (int m = 0; m < 2000; ++m) {
            // Every tenth point within 1e-9 of the seam (u = 0 from either side, and the last cell).
            const double a = m % 10 == 0 ? (m % 20 == 0 ? 1e-9 : double(n) - 1e-9) : angle(rng);
            const glm::dvec3 u(radial(rng), a, height(rng));
            worst = std::max(worst, std::abs(shell.index_value(u) - box.value(u + glm::dvec3(0.0, 2.0, 0.0))));
        }
        EXPECT_LE(worst, 1e-14) << int(in);
    }
}

// The angle field f = cos(theta) on a full-turn grid of 36 angles (10 degrees apart), with the
// grid's seam at 0 and at 300 degrees.
class SeamTest : public ::testing::TestWithParam<double> {
protected:
    void SetUp() override {
        shell_.r0 = 0.5, shell_.r1 = 1.0, shell_.a0 = GetParam(), shell_.a1 = GetParam() + 360.0;
        volume_ = make_volume({3, 36, 2}, [&](std::int64_t, std::int64_t j, std::int64_t) {
            return std::cos((shell_.a0 + 10.0 * double(j)) * kDeg);
        });
    }
    glm::dvec3 at(double theta) const { return from_cylindrical({0.75, theta, 0.5}, shell_.center); }
    double sample(std::int64_t j) const { return volume_.at(0, j, 0); }
    CylindricalShell shell_;
    Volume volume_;
};

TEST_P(SeamTest, TrilinearIsContinuousAcrossTheSeam) {
    const ShellSampler s(volume_, shell_, Interpolation::Trilinear);
    const double a0 = shell_.a0;
    // Either side of the grid's seam and of the world's 0/360 seam: equal up to the slope times the
    // distance (1e-9 degrees), not a jump from clamping.
    for (double seam : {a0, 0.0, 360.0}) {
        const double below = s.value(at(seam - 1e-9)), above = s.value(at(seam + 1e-9));
        EXPECT_NEAR(below, above, 1e-10) << seam;
        EXPECT_NEAR(below, std::cos(seam * kDeg), 0.02) << seam;
    }
    // Between the last sample (a0 + 350) and the first (a0 + 360): the linear mix of those two.
    const double last = sample(35), first = sample(0);
    EXPECT_NEAR(s.value(at(a0 - 5.0)), 0.5 * last + 0.5 * first, 1e-15);
    EXPECT_NEAR(s.value(at(a0 - 2.5)), 0.25 * last + 0.75 * first, 1e-12);
    EXPECT_NEAR(s.value(at(a0 - 7.5)), 0.75 * last + 0.25 * first, 1e-12);
    // Everywhere, and in the seam's cell in particular, within the linear interpolation error
    // dtheta^2 / 8 max|f''| (dtheta = 10 degrees in radians).
    const double bound = std::pow(10.0 * kDeg, 2) / 8.0 + 1e-12;
    double worst = 0.0, worst_seam = 0.0;
    for (int n = 0; n < 3600; ++n) {
        const double theta = 0.1 * n + 0.05;
        const double err = std::abs(s.value(at(theta)) - std::cos(theta * kDeg));
        worst = std::max(worst, err);
        if (angle_distance(theta, a0 - 5.0) <= 5.0) worst_seam = std::max(worst_seam, err);
    }
    EXPECT_LE(worst, bound);
    EXPECT_LE(worst_seam, bound);
    EXPECT_GT(worst, 0.9 * bound);  // the bound is tight (attained at cell centres where |cos| ~ 1)
}

TEST_P(SeamTest, NearestPicksTheNearestSampleAcrossTheSeam) {
    const ShellSampler s(volume_, shell_, Interpolation::Nearest);
    const double a0 = shell_.a0;
    for (std::int64_t j = 0; j < 36; ++j) {
        EXPECT_EQ(s.value(at(a0 + 10.0 * double(j) + 4.9)), sample(j)) << j;
        EXPECT_EQ(s.value(at(a0 + 10.0 * double(j) + 5.1)), sample((j + 1) % 36)) << j;
        EXPECT_EQ(s.value(at(a0 + 10.0 * double(j) - 4.9)), sample(j)) << j;
    }
    EXPECT_EQ(s.value(at(a0 - 4.9)), sample(0));
    EXPECT_EQ(s.value(at(a0 - 5.1)), sample(35));
}

// Tricubic wraps: the cubic's 4 taps run over the seam, so the error is as small there as anywhere
// (clamped taps would make the seam's cells constant: errors up to |cos(a0 - 10) - cos(a0)| ~ 0.17).
// With w = 10 degrees in radians per sample:
// B-spline approximates (blurs by the kernel's variance 1/3): at the samples it gives
// cos (2 + cos w) / 3, an error (1 - cos w) / 3 < w^2 / 6; asserted <= w^2 / 6 everywhere
// (measured max 5.064e-3 against w^2 / 6 = 5.077e-3).
// Catmull-Rom interpolates and is third order; asserted <= w^3 / 32 = 1.7e-4 (measured max 8.6e-5).
TEST_P(SeamTest, TricubicWrapsWithASmallBoundedError) {
    const double w = 10.0 * kDeg;
    for (auto [in, bound] : {std::pair{Interpolation::TricubicBSpline, w * w / 6.0},
                             std::pair{Interpolation::TricubicCatmullRom, w * w * w / 32.0}}) {
        const ShellSampler s(volume_, shell_, in);
        double worst = 0.0, worst_seam = 0.0;
        for (int n = 0; n < 3600; ++n) {
            const double theta = 0.1 * n + 0.05;
            const double err = std::abs(s.value(at(theta)) - std::cos(theta * kDeg));
            worst = std::max(worst, err);
            if (angle_distance(theta, shell_.a0) <= 20.0) worst_seam = std::max(worst_seam, err);
        }
        EXPECT_LE(worst, bound) << int(in);
        EXPECT_LE(worst_seam, bound) << int(in);
        RecordProperty(in == Interpolation::TricubicBSpline ? "bspline_max_error" : "catmull_rom_max_error",
                       std::to_string(worst));
        // Catmull-Rom interpolates: exact at the samples, including the last and first.
        if (in == Interpolation::TricubicCatmullRom) {
            EXPECT_NEAR(s.value(at(shell_.a0)), sample(0), 1e-12);
            EXPECT_NEAR(s.value(at(shell_.a0 + 350.0)), sample(35), 1e-12);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(GridSeams, SeamTest, ::testing::Values(0.0, 300.0, -90.0));

// Gradient of f = r in a cylindrical shell: the unit radial vector (cos theta, 0, -sin theta).
// The step h is the smallest grid spacing at r1 (here the radial one, 0.05). f = r is linear in the
// radial index, so trilinear reconstructs it exactly; the error is that of central differences of
// |(x, z)|: h^2 / 6 |f'''| <= h^2 / (5 r^2) per component; asserted |g - e_r| <= (h / (r - h))^2 / 4.
// One-sided differences (a neighbour outside the shell) are first order: asserted <= h / r.
TEST(ShellSampler, GradientOfRadiusIsTheRadialUnitVector) {
    CylindricalShell s;
    s.center = glm::dvec3(0.5, 1.0, -0.5);
    s.r0 = 0.25, s.r1 = 1.0, s.a0 = 0.0, s.a1 = 360.0, s.h0 = 0.0, s.h1 = 1.0;
    const Volume v = make_volume({16, 64, 8}, [](std::int64_t i, std::int64_t, std::int64_t) { return 0.25 + 0.05 * double(i); });
    const ShellSampler sampler(v, s, Interpolation::Trilinear);
    const double h = sampler.gradient_step();
    EXPECT_NEAR(h, 0.05, 1e-15);  // min(0.75 / 15, 1 * 2 pi / 64, 1 / 7)
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> t(0.0, 1.0);
    for (int n = 0; n < 500; ++n) {
        const double r = 0.35 + 0.55 * t(rng), theta = 360.0 * t(rng), y = 0.1 + 0.8 * t(rng);
        const glm::dvec3 g = sampler.gradient(from_cylindrical({r, theta, y}, s.center));
        const glm::dvec3 e(std::cos(theta * kDeg), 0.0, -std::sin(theta * kDeg));
        ASSERT_LE(glm::length(g - e), 0.25 * std::pow(h / (r - h), 2) + 1e-12) << r << " " << theta;
        ASSERT_NEAR(g.y, 0.0, 1e-12);
    }
    // Next to the outer surface: one-sided where the neighbour leaves the shell.
    for (double theta : {0.0, 30.0, 135.0, 359.0}) {
        const glm::dvec3 g = sampler.gradient(from_cylindrical({0.99, theta, 0.5}, s.center));
        const glm::dvec3 e(std::cos(theta * kDeg), 0.0, -std::sin(theta * kDeg));
        EXPECT_LE(glm::length(g - e), h / 0.99) << theta;
    }
    // Next to the top (h1 = 1): backward difference in y, still 0 (f does not depend on y).
    EXPECT_NEAR(sampler.gradient(from_cylindrical({0.5, 10.0, 0.99}, s.center)).y, 0.0, 1e-12);
}

TEST(ShellSampler, GradientOfRadiusInASphericalShell) {
    SphericalShell s;
    s.r0 = 0.5, s.r1 = 2.0;
    const Volume v = make_volume({72, 37, 16}, [](std::int64_t, std::int64_t, std::int64_t k) { return 0.5 + 0.1 * double(k); });
    const ShellSampler sampler(v, s, Interpolation::Trilinear);
    const double h = sampler.gradient_step();
    EXPECT_NEAR(h, 0.1, 1e-15);  // min(1.5 / 15, 2 * 5 deg, 2 * 5 deg)
    for (double lon : {0.0, 45.0, 200.0, 359.5})
        for (double lat : {-60.0, 0.0, 30.0}) {
            const double R = 1.2;
            const glm::dvec3 g = sampler.gradient(from_spherical({R, lon, lat}, s.center));
            const glm::dvec3 e = from_spherical({1.0, lon, lat}, glm::dvec3(0.0));
            // |p| in 3-D: h^2 / 6 |f'''| with |f'''| <= 3 / (2 R^2)-ish; asserted (h / (R - h))^2 / 2.
            EXPECT_LE(glm::length(g - e), 0.5 * std::pow(h / (R - h), 2)) << lon << " " << lat;
        }
}

// ---------------------------------------------------------------------------------------------
// Resampling

// A Cartesian field linear in world space, f = a x + b y + c z + d, on [-1.5, 1.5]^3.
constexpr double kA = 2.0, kB = -3.0, kC = 0.5, kD = 1.0;
double linear_world(const glm::dvec3& p) { return kA * p.x + kB * p.y + kC * p.z + kD; }
Volume linear_cartesian() {
    Volume v = make_volume({31, 31, 31}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        return linear_world(glm::dvec3(-1.5) + 0.1 * glm::dvec3(double(i), double(j), double(k)));
    });
    v.origin = glm::dvec3(-1.5);
    v.spacing = glm::dvec3(0.1);
    return v;
}

// Cartesian -> cylindrical -> Cartesian. Step 1 is exact (trilinear reproduces a linear field). In
// step 2, f = r g(theta) + b h + const with g = a cos theta - c sin theta; trilinear in index space is
// exact in r and h, so the error is r (g - linear interpolant of g) <= r1 |(a, c)| dtheta^2 / 8.
TEST(Resample, CartesianToCylindricalAndBackWithinTheTrilinearError) {
    const Volume cart = linear_cartesian();
    CylindricalShell s;
    s.r0 = 0.0, s.r1 = 1.2, s.h0 = -1.0, s.h1 = 1.0;
    const std::array<std::int64_t, 3> dims{25, 72, 21};  // dtheta = 5 degrees
    const Volume beam = resample_to_cylindrical(cart, Interpolation::Trilinear, s, dims, -7.0);
    EXPECT_EQ(beam.dims, dims);
    const ShellGrid grid(s, dims);
    for (std::int64_t k = 0; k < dims[2]; k += 4)
        for (std::int64_t j = 0; j < dims[1]; j += 5)
            for (std::int64_t i = 0; i < dims[0]; i += 3)
                ASSERT_NEAR(beam.at(i, j, k), linear_world(grid.sample_position(i, j, k)), 1e-12);

    const double fill = -7.0;
    const Volume back = resample_to_cartesian(beam, s, Interpolation::Trilinear, cart.origin, cart.spacing, cart.dims, fill);
    const double bound = s.r1 * std::hypot(kA, kC) * std::pow(5.0 * kDeg, 2) / 8.0 + 1e-12;
    double worst = 0.0;
    int inside = 0, outside = 0;
    for (std::int64_t k = 0; k < 31; ++k)
        for (std::int64_t j = 0; j < 31; ++j)
            for (std::int64_t i = 0; i < 31; ++i) {
                const glm::dvec3 p = back.voxel_position(i, j, k);
                if (grid.contains(p, kResampleShellTolerance)) {
                    worst = std::max(worst, std::abs(back.at(i, j, k) - cart.at(i, j, k)));
                    ++inside;
                } else {
                    ASSERT_EQ(back.at(i, j, k), fill);
                    ++outside;
                }
            }
    EXPECT_GT(inside, 5000);
    EXPECT_GT(outside, 5000);
    EXPECT_LE(worst, bound);
    EXPECT_GT(worst, 0.5 * bound);  // measured 2.0e-3 against 2.35e-3
}

// Cartesian -> spherical -> Cartesian: f = R G(lon, lat) + d; trilinear is exact in R; the bilinear
// error in (lon, lat) is <= R1 (dlon^2 |G_lonlon| + dlat^2 |G_latlat|) / 8 <= R1 |(a, b, c)| (dlon^2 + dlat^2) / 8.
TEST(Resample, CartesianToSphericalAndBackWithinTheTrilinearError) {
    const Volume cart = linear_cartesian();
    SphericalShell s;
    s.center = glm::dvec3(0.1, -0.1, 0.05);
    s.r0 = 0.2, s.r1 = 1.3;
    const std::array<std::int64_t, 3> dims{72, 37, 12};  // 5 degrees in both angles
    const Volume beam = resample_to_spherical(cart, Interpolation::Trilinear, s, dims);
    const ShellGrid grid(s, dims);
    for (std::int64_t k = 0; k < dims[2]; k += 3)
        for (std::int64_t j = 0; j < dims[1]; j += 4)
            for (std::int64_t i = 0; i < dims[0]; i += 7)
                ASSERT_NEAR(beam.at(i, j, k), linear_world(grid.sample_position(i, j, k)), 1e-12);
    const Volume back = resample_to_cartesian(beam, s, Interpolation::Trilinear, cart.origin, cart.spacing, cart.dims);
    const double d = 5.0 * kDeg;
    const double bound = s.r1 * std::sqrt(kA * kA + kB * kB + kC * kC) * 2.0 * d * d / 8.0 + 1e-12;
    double worst = 0.0;
    for (std::int64_t k = 0; k < 31; ++k)
        for (std::int64_t j = 0; j < 31; ++j)
            for (std::int64_t i = 0; i < 31; ++i) {
                const glm::dvec3 p = back.voxel_position(i, j, k);
                if (grid.contains(p, kResampleShellTolerance))
                    worst = std::max(worst, std::abs(back.at(i, j, k) - cart.at(i, j, k)));
                else
                    ASSERT_EQ(back.at(i, j, k), 0.0);
            }
    EXPECT_LE(worst, bound);
    EXPECT_GT(worst, 0.3 * bound);  // measured 5.9e-3 against 9.0e-3
}

TEST(Resample, SamplesOutsideTheCartesianDomainGetTheFill) {
    const Volume cart = linear_cartesian();
    CylindricalShell s;
    s.r0 = 1.0, s.r1 = 2.0, s.h0 = 0.0, s.h1 = 1.0;  // sticks out of [-1.5, 1.5] in x and z
    const Volume beam = resample_to_cylindrical(cart, Interpolation::Trilinear, s, {3, 8, 2}, 42.0);
    const ShellGrid grid(s, {3, 8, 2});
    EXPECT_EQ(beam.at(2, 0, 0), 42.0);                                       // r = 2 at theta 0: x = 2
    EXPECT_NEAR(beam.at(0, 0, 0), linear_world(grid.sample_position(0, 0, 0)), 1e-12);  // r = 1: inside
    EXPECT_NEAR(beam.at(2, 1, 1), linear_world(grid.sample_position(2, 1, 1)), 1e-12);  // 45 degrees: (1.41, 1, -1.41)
}

// ---------------------------------------------------------------------------------------------
// NRRD writing

class NrrdWriterTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("volref-shell-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    bool no_temporaries() const {
        for (const auto& e : fs::directory_iterator(dir_))
            if (e.path().filename().string().find(".volref-tmp") != std::string::npos) return false;
        return true;
    }
    fs::path dir_;
};

Volume test_volume() {
    Volume v = make_volume({3, 4, 5}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        return std::sin(double(i) * 1.3 + double(j) * 0.7) * std::pow(10.0, double(k) - 2.0) + 1e-3 * double(k);
    });
    v.values[7] = std::numeric_limits<double>::quiet_NaN();
    v.values[8] = -std::numeric_limits<double>::infinity();
    v.values[9] = 0.1;  // not a float
    v.origin = glm::dvec3(-1.25, 0.1, 3.0);
    v.spacing = glm::dvec3(0.3, 1e-3, 7.0);
    return v;
}

TEST_F(NrrdWriterTest, RoundTripsThroughReadVolume) {
    const Volume v = test_volume();
    for (ScalarType type : {ScalarType::F64, ScalarType::F32})
        for (auto encoding : {NrrdWriteOptions::Encoding::Raw, NrrdWriteOptions::Encoding::Gzip}) {
            SCOPED_TRACE(std::string(scalar_type_name(type)) + (encoding == NrrdWriteOptions::Encoding::Gzip ? " gzip" : " raw"));
            NrrdWriteOptions o;
            o.type = type;
            o.encoding = encoding;
            o.comments = {"a comment", "with a\nnewline"};
            o.key_values = {{"volref_bounds", R"({"type":"cylindrical"})"}, {"two", "line\nvalue \\ back"}};
            const fs::path p = dir_ / "v.nrrd";
            write_nrrd(v, p, o);
            const Volume r = read_volume(p);
            EXPECT_EQ(r.dims, v.dims);
            EXPECT_EQ(r.origin, v.origin);  // exactly: shortest round-trip numbers
            EXPECT_EQ(r.spacing, v.spacing);
            EXPECT_EQ(r.type, type);
            ASSERT_EQ(r.values.size(), v.values.size());
            for (std::size_t n = 0; n < v.values.size(); ++n) {
                const double expected = type == ScalarType::F32 ? double(float(v.values[n])) : v.values[n];
                if (std::isnan(expected)) EXPECT_TRUE(std::isnan(r.values[n])) << n;
                else EXPECT_EQ(r.values[n], expected) << n;
            }
            std::ifstream in(p, std::ios::binary);
            std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            EXPECT_EQ(text.rfind("NRRD0004\n", 0), 0u);
            EXPECT_THAT(text, HasSubstr("\nvolref_bounds:={\"type\":\"cylindrical\"}\n"));
            EXPECT_THAT(text, HasSubstr("\ntwo:=line\\nvalue \\\\ back\n"));
            EXPECT_THAT(text, HasSubstr("\n# with a newline\n"));
            EXPECT_TRUE(no_temporaries());
        }
}

// Every storage type (issue 18): integers 0 .. 59 (and -5 for the signed types) written as each of
// the eight NRRD types read back exactly, in that type, with that many bytes per voxel after the header.
TEST_F(NrrdWriterTest, EveryTypeRoundTrips) {
    for (ScalarType t : {ScalarType::U8, ScalarType::I8, ScalarType::U16, ScalarType::I16, ScalarType::U32,
                         ScalarType::I32, ScalarType::F32, ScalarType::F64}) {
        Volume v = make_volume({3, 4, 5}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
            return double(i + 3 * j + 12 * k);
        });
        if (t == ScalarType::I8 || t == ScalarType::I16 || t == ScalarType::I32 || !scalar_type_is_integer(t))
            v.values[5] = -5.0;
        NrrdWriteOptions o;
        o.type = t;
        const fs::path p = dir_ / (std::string("t-") + scalar_type_name(t) + ".nrrd");
        write_nrrd(v, p, o);
        const Volume back = read_volume(p);
        EXPECT_EQ(back.type, t) << scalar_type_name(t);
        for (std::size_t n = 0; n < v.values.size(); ++n) EXPECT_EQ(back.values[n], v.values[n]) << scalar_type_name(t);
        std::ifstream in(p, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::size_t data = bytes.size() - (bytes.find("\n\n") + 2);
        EXPECT_EQ(data, 60 * scalar_type_size(t)) << scalar_type_name(t);
    }
}

TEST_F(NrrdWriterTest, ErrorsLeaveNoFile) {
    Volume big = test_volume();
    big.values[3] = 1e300;
    NrrdWriteOptions f32;
    f32.type = ScalarType::F32;
    const fs::path p = dir_ / "big.nrrd";
    EXPECT_THAT(error_of([&] { write_nrrd(big, p, f32); }), HasSubstr("is not in the range of f32 (write f64)"));
    EXPECT_THAT(error_of([&] { write_nrrd(big, p, f32); }), HasSubstr("voxel (0, 1, 0)"));
    EXPECT_FALSE(fs::exists(p));
    EXPECT_THAT(error_of([&] { write_nrrd(test_volume(), dir_ / "v.raw"); }), HasSubstr(".nrrd"));
    EXPECT_THAT(error_of([&] { write_nrrd(test_volume(), dir_ / "nope" / "v.nrrd"); }), HasSubstr("does not exist"));
    NrrdWriteOptions u8;
    u8.type = ScalarType::U8;  // the test volume holds non-integers
    EXPECT_THAT(error_of([&] { write_nrrd(test_volume(), p, u8); }), HasSubstr("is not an integer in the range of u8"));
    NrrdWriteOptions key;
    key.key_values = {{"a:=b", "c"}};
    EXPECT_THAT(error_of([&] { write_nrrd(test_volume(), p, key); }), HasSubstr("invalid NRRD key"));
    Volume wrong = test_volume();
    wrong.values.pop_back();
    EXPECT_THAT(error_of([&] { write_nrrd(wrong, p); }), HasSubstr("59 values"));
    EXPECT_FALSE(fs::exists(p));
    EXPECT_TRUE(no_temporaries());
}

// ---------------------------------------------------------------------------------------------
// volref resample

class ResampleCommand : public NrrdWriterTest {
protected:
    struct Result {
        int status;
        std::string err;
    };
    Result run(const std::string& args) const {
        const fs::path err = dir_ / "stderr.txt";
        const std::string cmd = std::string(VOLREF_CLI) + " " + args + " > /dev/null 2> " + err.string();
        const int raw = std::system(cmd.c_str());
        std::ifstream in(err);
        std::stringstream ss;
        ss << in.rdbuf();
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, ss.str()};
    }
    // Fails with status 1 and one line naming `needle`, and writes no output (nor a temporary).
    void expect_error(const std::string& args, const std::string& needle, const fs::path& out) const {
        const Result r = run(args);
        EXPECT_EQ(r.status, 1) << args << "\n" << r.err;
        EXPECT_THAT(r.err, HasSubstr(needle)) << args;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_EQ(r.err.rfind("volref: error: ", 0), 0u) << r.err;
        EXPECT_FALSE(fs::exists(out)) << out;
        EXPECT_TRUE(no_temporaries());
    }
    fs::path write_cartesian() const {
        const fs::path p = dir_ / "cart.nrrd";
        write_nrrd(linear_cartesian(), p);
        return p;
    }
    static constexpr const char* kCylinder =
        R"({"type": "cylindrical", "center": [0, 0, 0], "radius": [0.25, 1.2], "angle": [300, 660], "height": [-1, 1]})";
};

TEST_F(ResampleCommand, CylindricalAndBackMatchTheLibrary) {
    const fs::path in = write_cartesian(), beam = dir_ / "beam.nrrd", back = dir_ / "back.nrrd";
    Result r = run("resample " + in.string() + " " + beam.string() + " --to cylindrical --dims 9,24,5 --shell '" +
                   kCylinder + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    CylindricalShell s;
    s.r0 = 0.25, s.r1 = 1.2, s.a0 = 300.0, s.a1 = 660.0, s.h0 = -1.0, s.h1 = 1.0;
    const Volume cart = read_volume(in);
    const Volume expected = resample_to_cylindrical(cart, Interpolation::Trilinear, s, {9, 24, 5});
    const Volume got = read_volume(beam);
    EXPECT_EQ(got.dims, expected.dims);
    EXPECT_EQ(got.values, expected.values);  // f64: bit for bit
    std::ifstream hin(beam, std::ios::binary);
    std::string header, line;
    while (std::getline(hin, line) && !line.empty()) header += line + "\n";
    EXPECT_THAT(header, HasSubstr("volref_bounds:={\"type\":\"cylindrical\",\"center\":[0.0,0.0,0.0],"
                                  "\"radius\":[0.25,1.2],\"angle\":[300.0,660.0],\"height\":[-1.0,1.0]}"));

    // Back, the shell read from the beam file's header; tricubic; gzip f32 output.
    r = run("resample " + beam.string() + " " + back.string() +
            " --to cartesian --dims 31,31,31 --origin=-1.5,-1.5,-1.5 --spacing 0.1,0.1,0.1 --interpolation "
            "tricubic-catmull-rom --type f32 --encoding gzip --fill -1");
    ASSERT_EQ(r.status, 0) << r.err;
    const Volume expected_back = resample_to_cartesian(got, s, Interpolation::TricubicCatmullRom, glm::dvec3(-1.5),
                                                       glm::dvec3(0.1), {31, 31, 31}, -1.0);
    const Volume got_back = read_volume(back);
    EXPECT_EQ(got_back.type, ScalarType::F32);
    EXPECT_EQ(got_back.origin, glm::dvec3(-1.5));
    ASSERT_EQ(got_back.values.size(), expected_back.values.size());
    for (std::size_t n = 0; n < got_back.values.size(); ++n)
        ASSERT_EQ(got_back.values[n], double(float(expected_back.values[n]))) << n;
}

TEST_F(ResampleCommand, SphericalFromAShellFileWithDefaultCartesianGrid) {
    const fs::path in = write_cartesian(), beam = dir_ / "beam.nrrd", back = dir_ / "back.nrrd";
    const fs::path shell = dir_ / "shell.json";
    std::ofstream(shell) << R"({"type": "spherical", "radius": [0.5, 1.4], "longitude": [0, 360],
        "latitude": [-60, 60], "axes": ["radius", "longitude", "latitude"]})";
    Result r = run("resample " + in.string() + " " + beam.string() + " --to spherical --dims 10,36,13 --shell " +
                   shell.string() + " --interpolation nearest");
    ASSERT_EQ(r.status, 0) << r.err;
    SphericalShell s;
    s.r0 = 0.5, s.r1 = 1.4, s.lat0 = -60.0, s.lat1 = 60.0, s.axes = {2, 0, 1};
    EXPECT_EQ(read_volume(beam).values,
              resample_to_spherical(read_volume(in), Interpolation::Nearest, s, {10, 36, 13}).values);
    // No --origin/--spacing: the shell's bounding box, [-1.4, 1.4] x [-1.4 sin 60, 1.4 sin 60] x [-1.4, 1.4].
    r = run("resample " + beam.string() + " " + back.string() + " --to cartesian --dims 15,11,15");
    ASSERT_EQ(r.status, 0) << r.err;
    const Volume b = read_volume(back);
    const auto box = bounding_box(s);
    EXPECT_EQ(b.origin, box[0]);
    EXPECT_NEAR(b.domain_max().x, 1.4, 1e-14);
    EXPECT_NEAR(b.domain_max().y, 1.4 * std::sqrt(3.0) / 2.0, 1e-14);
}

TEST_F(ResampleCommand, BadInputIsOneLineAndNoOutput) {
    const fs::path in = write_cartesian(), out = dir_ / "out.nrrd";
    const std::string base = "resample " + in.string() + " " + out.string();
    const std::string shell = std::string(" --shell '") + kCylinder + "'";
    expect_error("resample " + (dir_ / "missing.nrrd").string() + " " + out.string() + " --to cylindrical --dims 4,4,4" + shell,
                 "missing.nrrd: cannot read file", out);
    expect_error(base + " --to polar --dims 4,4,4" + shell, "--to: expected cylindrical, spherical or cartesian", out);
    expect_error(base + " --to cylindrical --dims 4,4" + shell, "--dims: expected 3 integers", out);
    expect_error(base + " --to cylindrical --dims 0,4,4" + shell, "--dims", out);
    expect_error(base + " --to cylindrical --dims 4,4,4", "needs --shell", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --shell '{\"type\": \"cylindrical\", \"radius\": [1, 2]'",
                 "--shell: line 1", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --shell '{\"type\": \"cylindrical\", \"radius\": [2, 1], "
                        "\"height\": [0, 1]}'",
                 "--shell: radius: expected [lo, hi] with lo < hi, got [2,1]", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --shell '{\"type\": \"cylindrical\", \"radius\": [1, 2], "
                        "\"height\": [0, 1], \"longitude\": [0, 90]}'",
                 "longitude", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --shell '{\"type\": \"spherical\", \"radius\": [1, 2]}'",
                 "expected \"cylindrical\" for --to cylindrical", out);
    expect_error(base + " --to spherical --dims 4,4,4 --shell '{\"type\": \"spherical\", \"radius\": [1, 2], "
                        "\"axes\": [\"radius\", \"radius\", \"latitude\"]}'",
                 "--shell: axes[1]: \"radius\" is given twice", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --shell " + (dir_ / "none.json").string(), "none.json: cannot read file",
                 out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --interpolation cubic" + shell, "--interpolation", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --type f16" + shell, "--type", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --encoding bz2" + shell, "--encoding", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --fill x" + shell, "--fill", out);
    expect_error(base + " --to cylindrical --dims 4,4,4 --origin 0,0,0 --spacing 1,1,1" + shell, "only to --to cartesian", out);
    expect_error(base + " --to cartesian --dims 4,4,4 --origin 0,0,0" + shell, "both --origin and --spacing", out);
    expect_error(base + " --to cartesian --dims 4,4,4 --origin 0,0,0 --spacing 1,0,1" + shell, "--spacing: expected 3 numbers > 0",
                 out);
    // A Cartesian input has no volref_bounds to place beam-space samples.
    expect_error(base + " --to cartesian --dims 4,4,4", "no 'volref_bounds' key", out);
    const fs::path raw = dir_ / "out.raw";
    expect_error("resample " + in.string() + " " + raw.string() + " --to cylindrical --dims 4,4,4" + shell,
                 "must be a .nrrd file", raw);
    const fs::path nodir = dir_ / "nope" / "out.nrrd";
    expect_error("resample " + in.string() + " " + nodir.string() + " --to cylindrical --dims 4,4,4" + shell,
                 "does not exist", nodir);
    // The input is not overwritten by a failing run onto itself.
    const auto before = fs::file_size(in);
    const Result r = run("resample " + in.string() + " " + in.string() + " --to cylindrical --dims 4,4,4 --type f16" + shell);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(fs::file_size(in), before);
}

// --shell is read by the scene loader's shell reader (parse_shell): a bad shell fails as in a scene, with
// the same problem after the path, and the radius (and a cylinder's height) is required in both.
TEST_F(ResampleCommand, ShellErrorsAreTheScenesErrors) {
    const fs::path in = write_cartesian(), out = dir_ / "out.nrrd";
    const std::string base = "resample " + in.string() + " " + out.string();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"cylindrical", R"({"type": "cylindrical", "radius": [0, 1]})"},
        {"cylindrical", R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "tessellate": 1})"},
        {"cylindrical", R"({"type": "cylindrical", "radius": [0, 1], "height": [0, 1], "colour": 1})"},
        {"spherical", R"({"type": "spherical", "radius": [0, 1], "latitude": [-100, 0]})"},
        {"spherical", R"({"type": "spherical", "radius": [0, 1], "axes": ["radius", "longitude", "up"]})"},
    };
    for (const auto& c : cases) {
        const std::string& to = c.first;
        const std::string& shell = c.second;  // (clang 14 cannot capture a structured binding)
        const std::string alone = error_of([&] { parse_shell(shell, "--shell"); });
        const std::string in_scene = error_of([&] {
            parse_scene(R"({"volume": {"source": "v.nrrd", "bounds": )" + shell + "}}", dir_, "scene.json");
        });
        const std::string scene_prefix = "scene.json: volume.bounds.";
        ASSERT_EQ(in_scene.rfind(scene_prefix, 0), 0u) << in_scene;
        EXPECT_EQ(alone, "--shell: " + in_scene.substr(scene_prefix.size()));
        const Result r = run(base + " --to " + to + " --dims 4,4,4 --shell '" + shell + "'");
        EXPECT_EQ(r.status, 1) << shell;
        EXPECT_EQ(r.err, "volref: error: " + alone + "\n") << shell;
        EXPECT_FALSE(fs::exists(out));
    }
}

}  // namespace
