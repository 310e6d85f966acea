// Bounding shapes beyond boxes (issue 5): curvilinear shells (analytic, in double), closed triangle
// meshes (OBJ and PLY, watertight crossings) and tessellated shells, through BoundingGeometry (Embree)
// against chords computed here by hand.
#include <gtest/gtest.h>

#include "ErrorOf.h"
#include "TempDir.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/MeshIntervals.h"
#include "geometry/ShellIntersection.h"
#include "geometry/ShellTessellation.h"
#include "geometry/TriangleMesh.h"

namespace volref {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

Ray ray(glm::dvec3 origin, glm::dvec3 direction) { return Ray{origin, glm::normalize(direction)}; }

double total(const std::vector<Interval>& v) {
    double s = 0;
    for (const auto& i : v) s += i.length();
    return s;
}

// Finite, sorted, disjoint, t >= 0, positive lengths.
::testing::AssertionResult well_formed(const std::vector<Interval>& v) {
    for (std::size_t k = 0; k < v.size(); ++k) {
        if (!std::isfinite(v[k].t0) || !std::isfinite(v[k].t1)) return ::testing::AssertionFailure() << "not finite";
        if (!(v[k].t0 >= 0) || !(v[k].t1 > v[k].t0)) return ::testing::AssertionFailure() << "bad interval " << k;
        if (k > 0 && !(v[k].t0 > v[k - 1].t1)) return ::testing::AssertionFailure() << "not disjoint at " << k;
    }
    return ::testing::AssertionSuccess();
}

::testing::AssertionResult same(const std::vector<Interval>& got, const std::vector<Interval>& want, double tol) {
    if (got.size() != want.size()) {
        auto f = ::testing::AssertionFailure() << got.size() << " intervals, want " << want.size() << ":";
        for (const auto& i : got) f << " [" << i.t0 << ", " << i.t1 << "]";
        f << " want";
        for (const auto& i : want) f << " [" << i.t0 << ", " << i.t1 << "]";
        return f;
    }
    for (std::size_t k = 0; k < got.size(); ++k) {
        if (!(std::abs(got[k].t0 - want[k].t0) <= tol) || !(std::abs(got[k].t1 - want[k].t1) <= tol))
            return ::testing::AssertionFailure() << "interval " << k << " is [" << got[k].t0 << ", " << got[k].t1
                                                 << "], want [" << want[k].t0 << ", " << want[k].t1 << "]";
    }
    return ::testing::AssertionSuccess();
}

// Every point of `inner` lies in `outer` (both sorted and disjoint), up to `tol`.
::testing::AssertionResult covered(const std::vector<Interval>& inner, const std::vector<Interval>& outer, double tol) {
    std::vector<Interval> o;  // outer, with gaps up to 2 tol closed
    for (const auto& i : outer) {
        if (!o.empty() && i.t0 - o.back().t1 <= 2 * tol)
            o.back().t1 = i.t1;
        else
            o.push_back(i);
    }
    for (const auto& i : inner) {
        bool in = false;
        for (const auto& j : o) in = in || (j.t0 - tol <= i.t0 && i.t1 <= j.t1 + tol);
        if (!in) return ::testing::AssertionFailure() << "[" << i.t0 << ", " << i.t1 << "] is not covered";
    }
    return ::testing::AssertionSuccess();
}

template <class Shell>
std::vector<Interval> shell_query(const Shell& shell, const Ray& r) {
    BoundingGeometry g;
    int id;
    if constexpr (std::is_same_v<Shell, CylindricalShell>)
        id = g.add_cylindrical_shell(shell);
    else
        id = g.add_spherical_shell(shell);
    g.commit();
    std::vector<Interval> out;
    g.intervals(r, id, out);
    EXPECT_TRUE(well_formed(out));
    return out;
}

SphericalShell sphere(double r0, double r1, glm::dvec3 c = glm::dvec3(0.0)) {
    SphericalShell s;
    s.center = c;
    s.r0 = r0;
    s.r1 = r1;
    return s;
}

CylindricalShell cylinder(double r0, double r1, double h0, double h1, glm::dvec3 c = glm::dvec3(0.0)) {
    CylindricalShell s;
    s.center = c;
    s.r0 = r0;
    s.r1 = r1;
    s.h0 = h0;
    s.h1 = h1;
    return s;
}

// The chord of a ray at distance rho from a circle's or sphere's centre, half-length sqrt(r^2 - rho^2),
// as intervals about the closest point at t = tc, for the shell r0 <= r <= r1.
std::vector<Interval> shell_chords(double r0, double r1, double rho, double tc) {
    const double s1 = std::sqrt(r1 * r1 - rho * rho);
    if (rho >= r0) return {{tc - s1, tc + s1}};
    const double s0 = std::sqrt(r0 * r0 - rho * rho);
    return {{tc - s1, tc - s0}, {tc + s0, tc + s1}};
}

// Two unit vectors perpendicular to d and to each other.
void basis(const glm::dvec3& d, glm::dvec3& u, glm::dvec3& v) {
    const glm::dvec3 a = std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    u = glm::normalize(glm::cross(d, a));
    v = glm::cross(d, u);
}

// ------------------------------------------------------------------------------------------------
// Spherical shells

TEST(SphericalShell, FullShellChordsThroughAndOutsideTheHole) {
    const glm::dvec3 c(0.3, -0.2, 0.1);
    const double r0 = 0.5, r1 = 1.25, D = 4.0;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n01;
    for (int k = 0; k < 40; ++k) {
        const glm::dvec3 d = glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng)));
        glm::dvec3 u, v;
        basis(d, u, v);
        const double rho = r1 * (k + 0.5) / 41.0;
        const double phi = 0.37 * k;
        const glm::dvec3 origin = c + rho * (std::cos(phi) * u + std::sin(phi) * v) - D * d;
        const auto iv = shell_query(sphere(r0, r1, c), Ray{origin, d});
        EXPECT_EQ(iv.size(), rho < r0 ? 2u : 1u) << "rho " << rho;
        EXPECT_TRUE(same(iv, shell_chords(r0, r1, rho, D), 1e-12)) << "rho " << rho;
        const double want = rho < r0 ? 2 * (std::sqrt(r1 * r1 - rho * rho) - std::sqrt(r0 * r0 - rho * rho))
                                     : 2 * std::sqrt(r1 * r1 - rho * rho);
        EXPECT_NEAR(total(iv), want, 1e-12);
    }
}

TEST(SphericalShell, SolidBallAndCentre) {
    // r0 = 0: one chord, also through the centre.
    for (const double rho : {0.0, 0.3, 0.999}) {
        const auto iv = shell_query(sphere(0.0, 1.0), ray({rho, 0, 3}, {0, 0, -1}));
        EXPECT_TRUE(same(iv, {{3 - std::sqrt(1 - rho * rho), 3 + std::sqrt(1 - rho * rho)}}, 1e-14));
    }
}

TEST(SphericalShell, TangentRays) {
    const double r0 = 0.5, r1 = 1.0;
    // Tangent to the outer sphere: nothing (or a sliver of the problem's conditioning, sqrt(eps)).
    const auto outer = shell_query(sphere(r0, r1), ray({1.0, 0, 3}, {0, 0, -1}));
    EXPECT_LE(total(outer), 1e-7);
    // Tangent to the inner sphere: the chord of the outer one, the touching point not counted apart.
    const auto inner = shell_query(sphere(r0, r1), ray({0.5, 0, 3}, {0, 0, -1}));
    EXPECT_NEAR(total(inner), 2 * std::sqrt(r1 * r1 - r0 * r0), 1e-7);
    EXPECT_NEAR(inner.front().t0, 3 - std::sqrt(r1 * r1 - r0 * r0), 1e-14);
    EXPECT_NEAR(inner.back().t1, 3 + std::sqrt(r1 * r1 - r0 * r0), 1e-14);
    EXPECT_LE(inner.size(), 2u);
    // Just outside the outer sphere: nothing.
    EXPECT_TRUE(shell_query(sphere(r0, r1), ray({1.0 + 1e-12, 0, 3}, {0, 0, -1})).empty());
}

TEST(SphericalShell, RaysStartingInside) {
    // In the hole: the shell from r0 to r1.
    EXPECT_TRUE(same(shell_query(sphere(0.5, 1.0), ray({0, 0, 0}, {0.6, 0, 0.8})), {{0.5, 1.0}}, 1e-15));
    // In the material: from t = 0, then the far side.
    EXPECT_TRUE(same(shell_query(sphere(0.5, 1.0), ray({0.75, 0, 0}, {-1, 0, 0})), {{0, 0.25}, {1.25, 1.75}}, 1e-15));
    EXPECT_TRUE(same(shell_query(sphere(0.5, 1.0), ray({0.75, 0, 0}, {1, 0, 0})), {{0, 0.25}}, 1e-15));
}

TEST(SphericalShell, ThroughBothPoles) {
    SphericalShell s = sphere(0.5, 1.0);
    const Ray down = ray({0, 5, 0}, {0, -1, 0});
    EXPECT_TRUE(same(shell_query(s, down), {{4, 4.5}, {5.5, 6}}, 1e-15));
    // The axis belongs to every longitude range.
    s.lon0 = 10;
    s.lon1 = 80;
    EXPECT_TRUE(same(shell_query(s, down), {{4, 4.5}, {5.5, 6}}, 1e-15));
    // Northern cap only: latitude [30, 90].
    s.lat0 = 30;
    EXPECT_TRUE(same(shell_query(s, down), {{4, 4.5}}, 1e-15));
    // A pole-to-pole ray just off the axis, full longitude: the same chords.
    const auto off = shell_query(sphere(0.5, 1.0), ray({1e-9, 5, 0}, {0, -1, 0}));
    EXPECT_TRUE(same(off, {{4, 4.5}, {5.5, 6}}, 1e-12));
}

TEST(SphericalShell, LongitudeWedges) {
    SphericalShell s = sphere(0.0, 1.0);
    s.lon0 = 0;
    s.lon1 = 90;  // x >= 0, z <= 0
    // Along -z at x = 0.5 in y = 0: inside from z = 0 to z = -sqrt(0.75).
    EXPECT_TRUE(same(shell_query(s, ray({0.5, 0, 3}, {0, 0, -1})), {{3, 3 + std::sqrt(0.75)}}, 1e-14));
    // Along +x at y = 0.2, z = -0.3: from x = 0 to sqrt(1 - 0.04 - 0.09).
    EXPECT_TRUE(same(shell_query(s, ray({-5, 0.2, -0.3}, {1, 0, 0})), {{5, 5 + std::sqrt(0.87)}}, 1e-14));
    // A concave wedge, [0, 270] (the quadrant x > 0, z > 0 is missing): a ray crossing the missing
    // quadrant between the two arms. p(s) = (0.3, 0, 0.3) + s (1, 0, -1) / sqrt 2, |p|^2 = 0.18 + s^2.
    s.lon1 = 270;
    const glm::dvec3 d = glm::normalize(glm::dvec3(1, 0, -1));
    const double S = 3;
    const auto iv = shell_query(s, Ray{glm::dvec3(0.3, 0, 0.3) - S * d, d});
    const double h = std::sqrt(0.82), q = 0.3 * std::sqrt(2.0);
    EXPECT_TRUE(same(iv, {{S - h, S - q}, {S + q, S + h}}, 1e-14));
}

TEST(SphericalShell, SeamAtZeroDegrees) {
    // [300, 420] is [-60, 60]: one interval across the seam, as for [-60, 60].
    for (const auto& [a0, a1] : {std::pair{300.0, 420.0}, std::pair{-60.0, 60.0}}) {
        SphericalShell s = sphere(0.0, 1.0);
        s.lon0 = a0;
        s.lon1 = a1;
        // Along -z at x = 0.3 in y = 0: inside while |z| <= 0.3 tan 60.
        const double z = 0.3 * std::tan(60 * kDeg);
        EXPECT_TRUE(same(shell_query(s, ray({0.3, 0, 3}, {0, 0, -1})), {{3 - z, 3 + z}}, 1e-14)) << a0;
    }
}

TEST(SphericalShell, LatitudeSectorsAreCones) {
    SphericalShell s = sphere(0.5, 1.0);
    s.lat0 = 30;
    s.lat1 = 60;
    // Along -y at x = 0.6: lat in [30, 60] <=> y in [0.6 tan 30, 0.6 tan 60]; R <= 1 <=> y <= 0.8.
    EXPECT_TRUE(same(shell_query(s, ray({0.6, 5, 0}, {0, -1, 0})), {{5 - 0.8, 5 - 0.6 * std::tan(30 * kDeg)}}, 1e-14));
    // The southern mirror image.
    s.lat0 = -60;
    s.lat1 = -30;
    EXPECT_TRUE(same(shell_query(s, ray({0.6, 5, 0}, {0, -1, 0})), {{5 + 0.6 * std::tan(30 * kDeg), 5.8}}, 1e-14));
    // A band across the equator, [-20, 40], r0 = 0, along -z at (0.3, 0.5): lat <= 40 needs
    // sqrt(0.09 + z^2) >= 0.5 / tan 40; R <= 1 needs z^2 <= 0.66. Two pieces, one each side.
    SphericalShell band = sphere(0.0, 1.0);
    band.lat0 = -20;
    band.lat1 = 40;
    const double zmin = std::sqrt(std::pow(0.5 / std::tan(40 * kDeg), 2) - 0.09), zmax = std::sqrt(0.66);
    EXPECT_TRUE(same(shell_query(band, ray({0.3, 0.5, 3}, {0, 0, -1})), {{3 - zmax, 3 - zmin}, {3 + zmin, 3 + zmax}}, 1e-14));
    // Latitude 0 is the plane y = 0: the northern hemisphere along -y at x = 0.3.
    SphericalShell north = sphere(0.0, 1.0);
    north.lat0 = 0;
    EXPECT_TRUE(same(shell_query(north, ray({0.3, 5, 0}, {0, -1, 0})), {{5 - std::sqrt(0.91), 5}}, 1e-14));
    // A ray in that plane lies on the closed region's boundary: inside, like a box face.
    EXPECT_TRUE(same(shell_query(north, ray({0.3, 0, 3}, {0, 0, -1})), {{3 - std::sqrt(0.91), 3 + std::sqrt(0.91)}}, 1e-14));
    // Through the apex (the centre) along a generator of the 45-degree cone, lat in [45, 90]:
    // the ray y = x (z = 0) from below: only the part above the centre, where lat = 45.
    SphericalShell cap = sphere(0.0, 1.0);
    cap.lat0 = 45;
    const glm::dvec3 d = glm::normalize(glm::dvec3(1, 1, 0));
    EXPECT_TRUE(same(shell_query(cap, Ray{-2.0 * d, d}), {{2, 3}}, 1e-14));
}

TEST(SphericalShell, VeryThinShell) {
    const double r1 = 1.0, r0 = 1.0 - 1e-6;
    for (const double rho : {0.0, 0.5, 0.9999, 0.9999995}) {
        const auto iv = shell_query(sphere(r0, r1), ray({rho, 0, 3}, {0, 0, -1}));
        ASSERT_TRUE(well_formed(iv));
        // Each piece: sqrt(r1^2 - rho^2) - sqrt(r0^2 - rho^2), without cancellation.
        const double a = std::sqrt(r1 * r1 - rho * rho);
        if (rho < r0) {
            const double b = std::sqrt((r0 - rho) * (r0 + rho));
            const double piece = (r1 - r0) * (r1 + r0) / (a + b);
            ASSERT_EQ(iv.size(), 2u);
            EXPECT_NEAR(iv[0].length(), piece, 1e-9 * piece);
            EXPECT_NEAR(iv[1].length(), piece, 1e-9 * piece);
            EXPECT_NEAR(iv[0].t0, 3 - a, 1e-14);
        } else {
            ASSERT_EQ(iv.size(), 1u);
            EXPECT_NEAR(iv[0].length(), 2 * a, 1e-9 * a);
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Cylindrical shells

TEST(CylindricalShell, AnnulusChordsPerpendicularToTheAxis) {
    const glm::dvec3 c(-0.4, 0.7, 0.2);
    const double r0 = 0.5, r1 = 1.5, D = 5.0;
    for (int k = 0; k < 30; ++k) {
        const double phi = 0.41 * k;
        const glm::dvec3 d(std::cos(phi), 0.0, std::sin(phi));
        const glm::dvec3 u(-std::sin(phi), 0.0, std::cos(phi));  // perpendicular to d and the axis
        const double rho = r1 * (k + 0.5) / 31.0;
        const glm::dvec3 origin = c + rho * u + glm::dvec3(0, 0.25, 0) - D * d;
        const auto iv = shell_query(cylinder(r0, r1, -1, 1, c), Ray{origin, d});
        EXPECT_TRUE(same(iv, shell_chords(r0, r1, rho, D), 1e-12)) << "rho " << rho;
    }
}

TEST(CylindricalShell, HeightLimitsAndCaps) {
    const auto s = cylinder(0.5, 1.0, -1, 2);
    // Parallel to the axis in the material: from y = 2 down to y = -1.
    EXPECT_TRUE(same(shell_query(s, ray({0.75, 5, 0}, {0, -1, 0})), {{3, 6}}, 1e-15));
    // Along the axis, in the hole: nothing; with r0 = 0: the full height.
    EXPECT_TRUE(shell_query(s, ray({0, 5, 0}, {0, -1, 0})).empty());
    EXPECT_TRUE(same(shell_query(cylinder(0, 1, -1, 2), ray({0, 5, 0}, {0, -1, 0})), {{3, 6}}, 1e-15));
    // A slanted ray leaving through the top cap: p = (0.75, 0.5 + u, -2 + u), u = t / sqrt 2;
    // r <= 1 needs |u - 2| <= sqrt(0.4375), y <= 2 needs u <= 1.5.
    const auto iv = shell_query(s, ray({0.75, 0.5, -2}, {0, 1, 1}));
    EXPECT_TRUE(same(iv, {{std::sqrt(2.0) * (2 - std::sqrt(0.4375)), std::sqrt(2.0) * 1.5}}, 1e-14));
    // Above the top cap: nothing.
    EXPECT_TRUE(shell_query(s, ray({-3, 2.5, 0}, {1, 0, 0})).empty());
    // In the plane of the top cap: on the closed boundary, inside.
    EXPECT_TRUE(same(shell_query(s, ray({-3, 2, 0}, {1, 0, 0})), {{2, 2.5}, {3.5, 4}}, 1e-15));
}

TEST(CylindricalShell, ThroughTheAxisAndStartingInside) {
    // Perpendicular through the axis: two pieces of the annulus, one chord with r0 = 0.
    EXPECT_TRUE(same(shell_query(cylinder(0.5, 1, -1, 1), ray({3, 0, 0}, {-1, 0, 0})), {{2, 2.5}, {3.5, 4}}, 1e-15));
    EXPECT_TRUE(same(shell_query(cylinder(0, 1, -1, 1), ray({3, 0, 0}, {-1, 0, 0})), {{2, 4}}, 1e-15));
    // Starting in the material and in the hole.
    EXPECT_TRUE(same(shell_query(cylinder(0.5, 1, -1, 1), ray({0.75, 0, 0}, {1, 0, 0})), {{0, 0.25}}, 1e-15));
    EXPECT_TRUE(same(shell_query(cylinder(0.5, 1, -1, 1), ray({0, 0, 0}, {0, 0, 1})), {{0.5, 1}}, 1e-15));
    // Through the axis of a wedge [0, 90] with r0 = 0 along (-1, 0, 1): only the half with x > 0, z < 0.
    CylindricalShell w = cylinder(0, 1, -1, 1);
    w.a1 = 90;
    const glm::dvec3 d = glm::normalize(glm::dvec3(-1, 0, 1));
    EXPECT_TRUE(same(shell_query(w, Ray{-3.0 * d, d}), {{2, 3}}, 1e-14));
}

TEST(CylindricalShell, WedgesAndTheSeam) {
    CylindricalShell w = cylinder(0.2, 1, -1, 1);
    w.a0 = 0;
    w.a1 = 90;  // x >= 0, z <= 0
    EXPECT_TRUE(same(shell_query(w, ray({0.5, 0, 3}, {0, 0, -1})), {{3, 3 + std::sqrt(0.75)}}, 1e-14));
    // Concave [0, 270]: the chord of the first example crosses the missing quadrant.
    w.r0 = 0;
    w.a1 = 270;
    const glm::dvec3 d = glm::normalize(glm::dvec3(1, 0, -1));
    const auto iv = shell_query(w, Ray{glm::dvec3(0.3, 0.5, 0.3) - 3.0 * d, d});
    const double h = std::sqrt(0.82), q = 0.3 * std::sqrt(2.0);
    EXPECT_TRUE(same(iv, {{3 - h, 3 - q}, {3 + q, 3 + h}}, 1e-14));
    // [300, 420] across the seam, as [-60, 60].
    for (const auto& [a0, a1] : {std::pair{300.0, 420.0}, std::pair{-60.0, 60.0}, std::pair{660.0, 780.0}}) {
        CylindricalShell s = cylinder(0, 1, -1, 1);
        s.a0 = a0;
        s.a1 = a1;
        const double z = 0.3 * std::tan(60 * kDeg);
        EXPECT_TRUE(same(shell_query(s, ray({0.3, 0, 3}, {0, 0, -1})), {{3 - z, 3 + z}}, 1e-14)) << a0;
    }
    // A half-turn [90, 270] (both limits in one plane, x <= 0): a ray in that plane through the axis.
    CylindricalShell half = cylinder(0, 1, -1, 1);
    half.a0 = 90;
    half.a1 = 270;
    EXPECT_TRUE(same(shell_query(half, ray({0, 0, 3}, {0, 0, -1})), {{2, 4}}, 1e-15));
    EXPECT_TRUE(same(shell_query(half, ray({3, 0, 0.5}, {-1, 0, 0})), {{3, 3 + std::sqrt(0.75)}}, 1e-14));
}

TEST(CylindricalShell, TangentAndThinShells) {
    EXPECT_LE(total(shell_query(cylinder(0.5, 1, -1, 1), ray({1, 0, 3}, {0, 0, -1}))), 1e-7);
    const auto inner = shell_query(cylinder(0.5, 1, -1, 1), ray({0.5, 0, 3}, {0, 0, -1}));
    EXPECT_NEAR(total(inner), 2 * std::sqrt(0.75), 1e-7);
    const double r1 = 2.0, r0 = 2.0 - 1e-6;
    for (const double rho : {0.0, 1.0, 1.9999}) {
        const auto iv = shell_query(cylinder(r0, r1, -1, 1), ray({rho, 0.1, 3}, {0, 0, -1}));
        const double a = std::sqrt(r1 * r1 - rho * rho), b = std::sqrt((r0 - rho) * (r0 + rho));
        const double piece = (r1 - r0) * (r1 + r0) / (a + b);
        ASSERT_EQ(iv.size(), 2u);
        EXPECT_NEAR(iv[0].length(), piece, 1e-9 * piece);
        EXPECT_NEAR(iv[1].length(), piece, 1e-9 * piece);
    }
}

TEST(Shells, RandomRaysAreFiniteAndAgreeWithMembership) {
    // Any ray (from inside, outside, along axes, through the centre): well formed, and the midpoint of
    // every interval is inside, the midpoint of every gap outside.
    std::vector<CylindricalShell> cyls;
    std::vector<SphericalShell> sphs;
    {
        CylindricalShell a = cylinder(0.3, 1, -0.5, 0.7);
        a.a0 = 200;
        a.a1 = 470;
        cyls.push_back(a);
        cyls.push_back(cylinder(0, 1, 0, 1));
        SphericalShell b = sphere(0.4, 1);
        b.lon0 = -30;
        b.lon1 = 200;
        b.lat0 = -45;
        b.lat1 = 20;
        sphs.push_back(b);
        SphericalShell e = sphere(0, 1);
        e.lat0 = 0;
        e.lat1 = 90;
        e.lon1 = 45;
        sphs.push_back(e);
    }
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::normal_distribution<double> n01;
    auto check = [&](const auto& intersector, const Ray& r) {
        std::vector<Interval> iv;
        intersector.intervals(r, iv);
        ASSERT_TRUE(well_formed(iv));
        double prev = 0;
        for (const auto& i : iv) {
            if (i.t0 - prev > 1e-9) {
                EXPECT_FALSE(intersector.contains(r.at(0.5 * (prev + i.t0))));
            }
            if (i.length() > 1e-9) {
                EXPECT_TRUE(intersector.contains(r.at(0.5 * (i.t0 + i.t1))));
            }
            prev = i.t1;
        }
    };
    const glm::dvec3 axes[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}};
    for (int k = 0; k < 400; ++k) {
        const glm::dvec3 o = k % 5 == 0 ? glm::dvec3(0.0) : glm::dvec3(u(rng), u(rng), u(rng));
        const glm::dvec3 d = k % 7 == 0 ? axes[k % 4] : glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng)));
        for (const auto& s : cyls) check(CylindricalShellIntersector(s), Ray{o, d});
        for (const auto& s : sphs) check(SphericalShellIntersector(s), Ray{o, d});
    }
}

TEST(Shells, InvalidParametersAreErrors) {
    EXPECT_THROW(CylindricalShellIntersector(cylinder(1, 0.5, 0, 1)), Error);
    EXPECT_THROW(CylindricalShellIntersector(cylinder(0, 1, 1, 1)), Error);
    SphericalShell s = sphere(0, 1);
    s.lat1 = 95;
    EXPECT_THROW(SphericalShellIntersector{s}, Error);
    s = sphere(-0.1, 1);
    EXPECT_THROW(SphericalShellIntersector{s}, Error);
}

TEST(Shells, BoundsHoldTheShell) {
    CylindricalShell c = cylinder(0.5, 2, -1, 3, {1, 2, 3});
    c.a0 = 10;
    c.a1 = 100;
    glm::dvec3 lo, hi;
    shell_bounds(c, lo, hi);
    // x = r cos a over [10, 100] with r in [0.5, 2]: max 2 cos 10, min 2 cos 100; z = -r sin a: min -2
    // (at 90), max -0.5 sin 10.
    EXPECT_NEAR(hi.x, 1 + 2 * std::cos(10 * kDeg), 1e-15);
    EXPECT_NEAR(lo.x, 1 + 2 * std::cos(100 * kDeg), 1e-15);
    EXPECT_NEAR(lo.z, 3 - 2, 1e-15);
    EXPECT_NEAR(hi.z, 3 - 0.5 * std::sin(10 * kDeg), 1e-15);
    EXPECT_EQ(lo.y, 1);
    EXPECT_EQ(hi.y, 5);
    SphericalShell s = sphere(0.5, 1);
    s.lat0 = 10;
    s.lat1 = 30;
    shell_bounds(s, lo, hi);
    EXPECT_NEAR(lo.y, 0.5 * std::sin(10 * kDeg), 1e-15);
    EXPECT_NEAR(hi.y, std::sin(30 * kDeg), 1e-15);
    EXPECT_NEAR(hi.x, std::cos(10 * kDeg), 1e-15);
}

TEST(Shells, QuadraticRootsWithoutCancellation) {
    double r[2];
    // x^2 - 1e8 x + 1 = 0: roots 1e8 and 1e-8 (the naive formula loses the small one).
    ASSERT_EQ(solve_quadratic(1, -1e8, 1, r), 2);
    const double small = std::min(r[0], r[1]), large = std::max(r[0], r[1]);
    EXPECT_NEAR(small, 1e-8, 1e-22);
    EXPECT_NEAR(large, 1e8, 1e-7);
    EXPECT_EQ(solve_quadratic(1, 0, 1, r), 0);
    ASSERT_EQ(solve_quadratic(0, 2, -4, r), 1);
    EXPECT_EQ(r[0], 2);
    ASSERT_EQ(solve_quadratic(1, 0, 0, r), 1);
    EXPECT_EQ(r[0], 0);
}

// ------------------------------------------------------------------------------------------------
// Triangle meshes

struct TempDir : test::TempDir {
    TempDir() : test::TempDir("shapes_test") {}
};

std::string obj_text(const TriangleMesh& m, bool one_based = true) {
    std::string s = "# written by test_shapes\n";
    char buf[128];
    for (const auto& v : m.vertices) {
        std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", v.x, v.y, v.z);
        s += buf;
    }
    for (const auto& t : m.triangles)
        s += "f " + std::to_string(t[0] + one_based) + " " + std::to_string(t[1] + one_based) + " " +
             std::to_string(t[2] + one_based) + "\n";
    return s;
}

std::string ply_ascii(const TriangleMesh& m) {
    std::string s = "ply\nformat ascii 1.0\ncomment written by test_shapes\nelement vertex " +
                    std::to_string(m.vertices.size()) + "\nproperty float x\nproperty float y\nproperty float z\n" +
                    "element face " + std::to_string(m.triangles.size()) + "\nproperty list uchar int vertex_indices\n" +
                    "end_header\n";
    char buf[128];
    for (const auto& v : m.vertices) {
        std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", v.x, v.y, v.z);
        s += buf;
    }
    for (const auto& t : m.triangles)
        s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    return s;
}

std::string ply_binary(const TriangleMesh& m) {
    std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(m.vertices.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(m.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&](const void* p, std::size_t n) { s.append(static_cast<const char*>(p), n); };
    for (const auto& v : m.vertices) {
        const float f[3] = {float(v.x), float(v.y), float(v.z)};
        put(f, sizeof f);  // x86-64 is little-endian
    }
    for (const auto& t : m.triangles) {
        const unsigned char three = 3;
        put(&three, 1);
        const std::int32_t idx[3] = {std::int32_t(t[0]), std::int32_t(t[1]), std::int32_t(t[2])};
        put(idx, sizeof idx);
    }
    return s;
}

// The box [lo, hi] as 12 outward triangles (each face split along a diagonal).
TriangleMesh cube_mesh(glm::dvec3 lo, glm::dvec3 hi) {
    TriangleMesh m;
    for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    // Faces as quads (counter-clockwise seen from outside).
    const int q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& f : q) {
        m.triangles.push_back({std::uint32_t(f[0]), std::uint32_t(f[1]), std::uint32_t(f[2])});
        m.triangles.push_back({std::uint32_t(f[0]), std::uint32_t(f[2]), std::uint32_t(f[3])});
    }
    return m;
}

// The U prism: the polygon P0..P9 (counter-clockwise in xy) extruded over z in [0, 1]; the notch
// [1, 2] x [1, 3] is missing from [0, 3] x [0, 3]. Caps triangulated by hand, side walls as quads.
const double kU[10][2] = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
const int kUCap[8][3] = {{0, 1, 7}, {0, 7, 8}, {0, 8, 9}, {1, 2, 6}, {1, 6, 7}, {2, 3, 6}, {6, 3, 4}, {6, 4, 5}};

std::string u_obj_with_quads() {
    std::string s = "o U\n";
    for (int z = 0; z < 2; ++z)
        for (const auto& p : kU) s += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(z) + "\n";
    // OBJ indices are 1-based: bottom P_i is i + 1, top P_i is i + 11.
    for (const auto& t : kUCap) s += "f " + std::to_string(t[0] + 11) + " " + std::to_string(t[1] + 11) + " " + std::to_string(t[2] + 11) + "\n";
    for (const auto& t : kUCap) s += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[2] + 1) + " " + std::to_string(t[1] + 1) + "\n";
    for (int i = 0; i < 10; ++i) {
        const int j = (i + 1) % 10;
        s += "f " + std::to_string(i + 1) + " " + std::to_string(j + 1) + " " + std::to_string(j + 11) + " " +
             std::to_string(i + 11) + "\n";
    }
    return s;
}

// The U as three boxes, and a ray's intervals in their union by the slab test written here.
std::vector<Interval> u_chords(const Ray& r) {
    const glm::dvec3 boxes[3][2] = {{{0, 0, 0}, {1, 3, 1}}, {{1, 0, 0}, {2, 1, 1}}, {{2, 0, 0}, {3, 3, 1}}};
    std::vector<Interval> v;
    for (const auto& b : boxes) {
        double t0 = 0, t1 = INFINITY;
        for (int a = 0; a < 3; ++a) {
            if (r.direction[a] == 0) {
                if (r.origin[a] < b[0][a] || r.origin[a] > b[1][a]) t1 = -1;
                continue;
            }
            double ta = (b[0][a] - r.origin[a]) / r.direction[a], tb = (b[1][a] - r.origin[a]) / r.direction[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        if (t1 > t0) v.push_back({t0, t1});
    }
    normalize_intervals(v);
    return v;
}

std::vector<Interval> mesh_query(const TriangleMesh& m, const Ray& r, glm::dvec3 dlo = glm::dvec3(-100),
                                 glm::dvec3 dhi = glm::dvec3(100)) {
    BoundingGeometry g;
    const int id = g.add_mesh(m, dlo, dhi);
    g.commit();
    std::vector<Interval> out;
    g.intervals(r, id, out);
    EXPECT_TRUE(well_formed(out));
    return out;
}

TEST(TriangleMesh, CubeMeshEqualsTheBox) {
    TempDir dir;
    const glm::dvec3 lo(-0.5, 0.25, 1), hi(1.5, 2, 1.75);
    const TriangleMesh mesh = read_closed_mesh(dir.write("cube.obj", obj_text(cube_mesh(lo, hi))));
    EXPECT_EQ(mesh.triangles.size(), 12u);
    EXPECT_NEAR(signed_volume(mesh), 2 * 1.75 * 0.75, 1e-14);
    BoundingGeometry g;
    const int box = g.add_box(lo, hi, glm::dvec3(-100), glm::dvec3(100));
    const int cube = g.add_mesh(mesh, glm::dvec3(-100), glm::dvec3(100));
    g.commit();
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-3, 4);
    std::normal_distribution<double> n01;
    int hits = 0;
    for (int k = 0; k < 2000; ++k) {
        const glm::dvec3 o(u(rng), u(rng), u(rng));
        // Aim at a point of the box half of the time.
        const glm::dvec3 target = lo + (hi - lo) * glm::dvec3(u(rng) / 7 + 3.0 / 7, u(rng) / 7 + 3.0 / 7, u(rng) / 7 + 3.0 / 7);
        const glm::dvec3 d = k % 2 ? glm::normalize(target - o) : glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng)));
        std::vector<Interval> a, b;
        g.intervals(Ray{o, d}, box, a);
        g.intervals(Ray{o, d}, cube, b);
        EXPECT_TRUE(same(b, a, 1e-13)) << k;
        hits += !a.empty();
    }
    EXPECT_GT(hits, 800);
}

TEST(TriangleMesh, RaysThroughEdgesAndVertices) {
    const TriangleMesh cube = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    const double s2 = std::sqrt(2.0), s3 = std::sqrt(3.0);
    // In through the middle of an edge, out through the opposite edge.
    EXPECT_TRUE(same(mesh_query(cube, ray({0.5, -1, -1}, {0, 1, 1})), {{s2, 2 * s2}}, 1e-14));
    // Through the face diagonals (the edges between each face's two triangles), perpendicular to the faces.
    EXPECT_TRUE(same(mesh_query(cube, ray({0.5, 0.5, 3}, {0, 0, -1})), {{2, 3}}, 1e-15));
    EXPECT_TRUE(same(mesh_query(cube, ray({0.25, 0.25, 3}, {0, 0, -1})), {{2, 3}}, 1e-15));
    EXPECT_TRUE(same(mesh_query(cube, ray({-2, 0.75, 0.75}, {1, 0, 0})), {{2, 3}}, 1e-15));
    // In through a corner (where six triangles meet), out through the opposite corner.
    EXPECT_TRUE(same(mesh_query(cube, ray({-1, -1, -1}, {1, 1, 1})), {{s3, 2 * s3}}, 1e-14));
    // Along (1, 1, 0) at z = 0.5, from the vertical edge at (0, 0) to the vertical edge at (1, 1).
    EXPECT_TRUE(same(mesh_query(cube, ray({-1, -1, 0.5}, {1, 1, 0})), {{s2, 2 * s2}}, 1e-14));
    // Touching a corner only, or an edge only, from outside: no interval.
    EXPECT_TRUE(mesh_query(cube, ray({0, 2, 1}, {1, -1, 0})).empty());
    EXPECT_TRUE(mesh_query(cube, ray({0.5, -1, 0}, {0, 1, 1})).empty());
    // Starting on a vertex, on an edge, inside.
    EXPECT_TRUE(same(mesh_query(cube, ray({0, 0, 0}, {1, 1, 1})), {{0, s3}}, 1e-14));
    EXPECT_TRUE(same(mesh_query(cube, ray({0.5, 0.5, 0.5}, {0, 0, 1})), {{0, 0.5}}, 1e-15));
    EXPECT_TRUE(same(mesh_query(cube, ray({0.5, 0.5, 0.5}, {1, 1, 1})), {{0, std::sqrt(0.75)}}, 1e-15));
    // Along a face or an edge the ray is just inside or just outside (a fixed perturbation): either
    // the whole chord or nothing, never a piece of it.
    for (const Ray& r : {ray({0, 0.5, 3}, {0, 0, -1}), ray({1, 0.5, 3}, {0, 0, -1}), ray({0, 0, 3}, {0, 0, -1}),
                         ray({1, 1, 3}, {0, 0, -1}), ray({0.5, 1, 3}, {0, 0, -1})}) {
        const auto iv = mesh_query(cube, r);
        EXPECT_TRUE(iv.empty() || same(iv, {{2, 3}}, 1e-15));
    }
}

TEST(TriangleMesh, ConcaveUFromObjAndPly) {
    TempDir dir;
    const TriangleMesh from_obj = read_closed_mesh(dir.write("u.obj", u_obj_with_quads()));
    EXPECT_EQ(from_obj.vertices.size(), 20u);
    EXPECT_EQ(from_obj.triangles.size(), 36u);  // 2 x 8 caps + 10 quads
    EXPECT_NEAR(signed_volume(from_obj), 7.0, 1e-14);
    const TriangleMesh ascii = read_closed_mesh(dir.write("u.ply", ply_ascii(from_obj)));
    const TriangleMesh binary = read_closed_mesh(dir.write("u_binary.PLY", ply_binary(from_obj)));
    EXPECT_NEAR(signed_volume(ascii), 7.0, 1e-14);
    EXPECT_NEAR(signed_volume(binary), 7.0, 1e-14);
    const double s2 = std::sqrt(2.0);
    struct Case {
        Ray r;
        std::vector<Interval> want;
    };
    const std::vector<Case> cases{
        {ray({-1, 2, 0.5}, {1, 0, 0}), {{1, 2}, {3, 4}}},   // through both arms
        {ray({-1, 0.5, 0.5}, {1, 0, 0}), {{1, 4}}},         // through the base
        {ray({1.5, 5, 0.5}, {0, -1, 0}), {{4, 5}}},         // down the notch
        {ray({0.5, 5, 0.5}, {0, -1, 0}), {{2, 5}}},         // down the left arm
        {ray({-1, -1, 0.5}, {1, 1, 0}), {{s2, 2 * s2}, {3 * s2, 4 * s2}}},  // through the notch's corner edge
        {ray({1.5, 2, 3}, {0, 0, -1}), {}},                 // into the notch from above
        {ray({2.5, 2, 3}, {0, 0, -1}), {{2, 3}}},
    };
    for (const TriangleMesh* m : {&from_obj, &ascii, &binary}) {
        for (const auto& c : cases) {
            EXPECT_TRUE(same(mesh_query(*m, c.r), c.want, 1e-14));
            EXPECT_TRUE(same(mesh_query(*m, c.r), u_chords(c.r), 1e-14));
        }
    }
    // Along the notch's floor (y = 1): in the arms for sure; over the floor, a face of the mesh, just
    // inside or just outside.
    for (const TriangleMesh* m : {&from_obj, &ascii, &binary}) {
        const auto iv = mesh_query(*m, ray({-1, 1, 0.5}, {1, 0, 0}));
        EXPECT_TRUE(same(iv, {{1, 4}}, 1e-14) || same(iv, {{1, 2}, {3, 4}}, 1e-14));
    }
    // Random rays against the union of the three boxes, and Embree against every triangle.
    BoundingGeometry g;
    const int id = g.add_mesh(from_obj, glm::dvec3(-100), glm::dvec3(100));
    g.commit();
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1, 4);
    std::normal_distribution<double> n01;
    for (int k = 0; k < 3000; ++k) {
        const glm::dvec3 o(u(rng), u(rng), u(rng) / 2);
        const glm::dvec3 d = glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng) / 4));
        const Ray r{o, d};
        std::vector<Interval> got, brute;
        g.intervals(r, id, got);
        mesh_intervals_brute_force(r, from_obj, brute);
        normalize_intervals(brute);
        EXPECT_TRUE(same(got, u_chords(r), 1e-12)) << k;
        EXPECT_TRUE(same(got, brute, 0.0)) << k;
    }
}

TEST(TriangleMesh, ClippedToTheDomain) {
    const TriangleMesh cube = cube_mesh(glm::dvec3(0), glm::dvec3(2));
    EXPECT_TRUE(same(mesh_query(cube, ray({0.5, 0.5, 5}, {0, 0, -1}), glm::dvec3(0), glm::dvec3(1)), {{4, 5}}, 1e-15));
    EXPECT_TRUE(mesh_query(cube, ray({0.5, 0.5, 5}, {0, 0, -1}), glm::dvec3(3), glm::dvec3(4)).empty());
}

TEST(TriangleMesh, InwardOrientedMeshIsFlipped) {
    TriangleMesh m = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    EXPECT_NEAR(signed_volume(m), -1.0, 1e-15);
    check_closed(m, "inward");
    EXPECT_NEAR(signed_volume(m), 1.0, 1e-15);
    EXPECT_TRUE(same(mesh_query(m, ray({0.3, 0.4, 3}, {0, 0, -1})), {{2, 3}}, 1e-15));
}

TEST(TriangleMesh, ZeroAreaTrianglesAreHandled) {
    // The cube with its bottom face's edge (0,0,0)-(1,0,0) split at M = (0.5, 0, 0) on one side only:
    // a zero-area triangle (P0, P1, M) closes the mesh.
    TriangleMesh m = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    const std::uint32_t M = std::uint32_t(m.vertices.size());
    m.vertices.push_back({0.5, 0, 0});
    // Face y = 0 is {0, 1, 5, 4}: triangles (0, 1, 5), (0, 5, 4). Split (0, 1, 5) at M.
    for (auto& t : m.triangles)
        if (t == std::array<std::uint32_t, 3>{0, 1, 5}) t = {0, M, 5};
    m.triangles.push_back({M, 1, 5});
    m.triangles.push_back({0, 1, M});  // zero area, opposite to the bottom face's edge 1 -> 0
    check_closed(m, "split cube");
    EXPECT_EQ(m.triangles.size(), 14u);
    EXPECT_TRUE(same(mesh_query(m, ray({0.5, -1, -1}, {0, 1, 1})), {{std::sqrt(2.0), 2 * std::sqrt(2.0)}}, 1e-14));
    EXPECT_TRUE(same(mesh_query(m, ray({0.5, -1, 0.5}, {0, 1, 0})), {{1, 2}}, 1e-15));
    std::mt19937_64 rng(9);
    std::normal_distribution<double> n01;
    BoundingGeometry g;
    const int box = g.add_box(glm::dvec3(0), glm::dvec3(1), glm::dvec3(-9), glm::dvec3(9));
    const int mesh = g.add_mesh(m, glm::dvec3(-9), glm::dvec3(9));
    g.commit();
    for (int k = 0; k < 500; ++k) {
        const glm::dvec3 d = glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng)));
        const Ray r{glm::dvec3(0.5, 0, 0) + 0.3 * glm::dvec3(n01(rng), n01(rng), n01(rng)) - 3.0 * d, d};
        std::vector<Interval> a, b;
        g.intervals(r, box, a);
        g.intervals(r, mesh, b);
        EXPECT_TRUE(same(b, a, 1e-13)) << k;
    }
}

using test::error_of;

TEST(TriangleMesh, OpenAndInconsistentMeshesAreErrors) {
    TempDir dir;
    TriangleMesh open = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    open.triangles.pop_back();
    const std::string open_path = dir.write("open.obj", obj_text(open));
    std::string msg = error_of([&] { read_closed_mesh(open_path); });
    EXPECT_EQ(msg.rfind(open_path + ": the mesh is not closed (the edge between vertices (", 0), 0u) << msg;
    EXPECT_NE(msg.find("is used by 1 triangle)"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);

    TriangleMesh flipped = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
    const std::string flipped_path = dir.write("flipped.ply", ply_ascii(flipped));
    msg = error_of([&] { read_closed_mesh(flipped_path); });
    EXPECT_EQ(msg.rfind(flipped_path + ": the mesh is not consistently oriented (the edge between vertices (", 0), 0u) << msg;

    // An edge shared by three triangles (a fin).
    TriangleMesh fin = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    fin.vertices.push_back({0.5, -1, 0.5});
    fin.triangles.push_back({0, 1, 8});
    msg = error_of([&] { check_closed(fin, "fin.obj"); });
    EXPECT_NE(msg.find("fin.obj: the mesh is not closed"), std::string::npos) << msg;
    EXPECT_NE(msg.find("is used by 3 triangles)"), std::string::npos) << msg;

    // Not closed for add_mesh either.
    EXPECT_THROW(mesh_query(open, ray({0.5, 0.5, 3}, {0, 0, -1})), Error);

    // Missing files, unknown formats, bad indices, nothing at all.
    const std::string missing = (dir.path / "missing.obj").string();
    msg = error_of([&] { read_mesh(missing); });
    EXPECT_EQ(msg.rfind(missing + ": ", 0), 0u) << msg;
    const std::string missing_ply = (dir.path / "missing.ply").string();
    msg = error_of([&] { read_mesh(missing_ply); });
    EXPECT_EQ(msg.rfind(missing_ply + ": ", 0), 0u) << msg;
    const std::string stl = dir.write("x.stl", "solid x\nendsolid x\n");
    msg = error_of([&] { read_mesh(stl); });
    EXPECT_EQ(msg.rfind(stl + ": unknown mesh format", 0), 0u) << msg;
    const std::string bad = dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    msg = error_of([&] { read_mesh(bad); });
    EXPECT_EQ(msg.rfind(bad + ": ", 0), 0u) << msg;
    const std::string empty = dir.write("empty.obj", "# nothing\n");
    msg = error_of([&] { read_closed_mesh(empty); });
    EXPECT_EQ(msg, empty + ": the mesh has no triangles");
    const std::string garbage = dir.write("garbage.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\nnonsense\n");
    msg = error_of([&] { read_closed_mesh(garbage); });
    EXPECT_EQ(msg.rfind(garbage + ": ", 0), 0u) << msg;
    // A closed mesh that encloses nothing: a triangle and its reverse.
    TriangleMesh flat;
    flat.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    flat.triangles = {{0, 1, 2}, {0, 2, 1}};
    msg = error_of([&] { check_closed(flat, "flat.obj"); });
    EXPECT_EQ(msg.rfind("flat.obj: the mesh encloses no volume", 0), 0u) << msg;
}

TEST(TriangleMesh, DuplicatedVerticesAreMerged) {
    // Every triangle with its own three vertices, as STL-like exporters write: merged into a closed cube.
    TempDir dir;
    const TriangleMesh cube = cube_mesh(glm::dvec3(0), glm::dvec3(1));
    TriangleMesh soup;
    for (const auto& t : cube.triangles) {
        const std::uint32_t b = std::uint32_t(soup.vertices.size());
        for (const auto v : t) soup.vertices.push_back(cube.vertices[v]);
        soup.triangles.push_back({b, b + 1, b + 2});
    }
    const TriangleMesh m = read_closed_mesh(dir.write("soup.obj", obj_text(soup)));
    EXPECT_EQ(m.vertices.size(), 8u);
    EXPECT_TRUE(same(mesh_query(m, ray({0.5, 0.5, 3}, {0, 0, -1})), {{2, 3}}, 1e-15));
}

TEST(TriangleMesh, ExactCrossSign) {
    // (2^27 + 1)(2^27 - 1) - 2^27 2^27 = -1, while the rounded products are equal.
    const double a = 134217728.0;
    EXPECT_EQ((a + 1) * (a - 1) - a * a, 0.0);
    EXPECT_EQ(exact_cross_sign(a + 1, a, a, a - 1), -1);
    EXPECT_EQ(exact_cross_sign(a, a + 1, a - 1, a), 1);
    EXPECT_EQ(exact_cross_sign(0.1, 0.3, 0.1, 0.3), 0);
    EXPECT_EQ(exact_cross_sign(3, 0, 0, 2), 1);
    // 0.1 * 0.3 vs 0.3 * 0.1 with different roundings of the inputs' products: decided exactly.
    const double x = 0.1, y = 0.3;
    EXPECT_EQ(exact_cross_sign(x, y, x * 3, y * 3), exact_cross_sign(x, y, x * 3, y * 3));
    EXPECT_EQ(exact_cross_sign(x, y, x * 3, y * 3), -exact_cross_sign(x * 3, y * 3, x, y));
}

// ------------------------------------------------------------------------------------------------
// Several volumes in one scene, single rays and packets

TEST(BoundingGeometryShapes, PacketsEqualSingleRaysForEveryShape) {
    BoundingGeometry g;
    SphericalShell sph = sphere(0.4, 1, {2, 0, 0});
    sph.lon1 = 200;
    sph.lat0 = -50;
    CylindricalShell cyl = cylinder(0.2, 0.9, -1, 1, {-2, 0, 0});
    cyl.a0 = 300;
    cyl.a1 = 520;
    std::vector<int> ids{g.add_box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}, glm::dvec3(-9), glm::dvec3(9)),
                         g.add_spherical_shell(sph), g.add_cylindrical_shell(cyl),
                         g.add_mesh(tessellate(sph, 24), glm::dvec3(-9), glm::dvec3(9))};
    g.commit();
    EXPECT_EQ(g.volume_count(), 4);
    EXPECT_EQ(ids, (std::vector<int>{0, 1, 2, 3}));
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(-3, 3);
    std::normal_distribution<double> n01;
    std::vector<Ray> rays;
    for (int k = 0; k < 53; ++k) {
        const glm::dvec3 o(u(rng), u(rng), 4 + u(rng) / 3);
        const glm::dvec3 centres[3] = {{0, 0, 0}, {2, 0, 0}, {-2, 0, 0}};
        const glm::dvec3 target = centres[k % 3] + 0.6 * glm::dvec3(n01(rng), n01(rng), n01(rng));
        rays.push_back(Ray{o, glm::normalize(target - o)});
    }
    int nonempty = 0;
    for (const int id : ids) {
        for (const int count : {1, 5, 16, 53}) {
            std::vector<std::vector<Interval>> packet(static_cast<std::size_t>(count));
            g.intervals(rays.data(), count, id, packet.data());
            for (int i = 0; i < count; ++i) {
                std::vector<Interval> single;
                g.intervals(rays[std::size_t(i)], id, single);
                EXPECT_TRUE(same(packet[std::size_t(i)], single, 0.0)) << id << " " << count << " " << i;
                nonempty += !single.empty();
            }
        }
    }
    EXPECT_GT(nonempty, 50);  // of 4 x 75, about a third of the rays aim at each shape
    // Each volume only sees its own shape: the box's ray misses the shells.
    std::vector<Interval> out;
    g.intervals(ray({0, 0, 5}, {0, 0, -1}), 0, out);
    EXPECT_TRUE(same(out, {{4.5, 5.5}}, 1e-15));
    g.intervals(ray({0, 0, 5}, {0, 0, -1}), 1, out);
    EXPECT_TRUE(out.empty());
    g.intervals(ray({0, 0, 5}, {0, 0, -1}), 7, out);  // no such volume
    EXPECT_TRUE(out.empty());
}

// ------------------------------------------------------------------------------------------------
// Tessellated shells

void analytic(const CylindricalShell& s, const Ray& r, std::vector<Interval>& out) {
    CylindricalShellIntersector(s).intervals(r, out);
}
void analytic(const SphericalShell& s, const Ray& r, std::vector<Interval>& out) {
    SphericalShellIntersector(s).intervals(r, out);
}

// Per ray: the analytic shell shrunk by the stated error is inside the mesh, which is inside the
// analytic shell grown by it.
template <class Shell>
void expect_sandwiched(const TriangleMesh& mesh, const Shell& minus, const Shell& plus, const glm::dvec3& centre,
                       double extent, int rays) {
    BoundingGeometry g;
    const int id = g.add_mesh(mesh, glm::dvec3(-1e3), glm::dvec3(1e3));
    g.commit();
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> u(-1.2 * extent, 1.2 * extent);
    std::normal_distribution<double> n01;
    for (int k = 0; k < rays; ++k) {
        const glm::dvec3 o = centre + glm::dvec3(u(rng), u(rng), u(rng));
        const glm::dvec3 d = glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng)));
        const Ray r{o, d};
        std::vector<Interval> m, lo, hi;
        g.intervals(r, id, m);
        if (minus.r1 > 0) analytic(minus, r, lo);  // r1 = 0: no lower bound
        analytic(plus, r, hi);
        ASSERT_TRUE(well_formed(m));
        EXPECT_TRUE(covered(lo, m, 1e-9)) << k;
        EXPECT_TRUE(covered(m, hi, 1e-9)) << k;
    }
}

TEST(Tessellation, CylindricalShellsAreClosedAndWithinTheStatedError) {
    struct Case {
        double r0, a0, a1;
        int n;
    };
    for (const Case& c : {Case{0.4, 0, 360, 3}, Case{0.4, 0, 360, 64}, Case{0, 0, 360, 16}, Case{0.3, 30, 130, 24},
                          Case{0, 300, 420, 32}, Case{0.5, -45, 225, 12}, Case{0, 0, 90, 3}}) {
        CylindricalShell s = cylinder(c.r0, 1.5, -0.5, 1, {0.2, 0.1, -0.3});
        s.a0 = c.a0;
        s.a1 = c.a1;
        TriangleMesh mesh = tessellate(s, c.n);
        TriangleMesh copy = mesh;
        EXPECT_NO_THROW(check_closed(copy, "t"));
        EXPECT_EQ(copy.triangles.size(), mesh.triangles.size());  // already outward, nothing removed
        const double e = tessellation_error(s, c.n);
        EXPECT_NEAR(e, 1.5 * (1 - std::cos(kPi / c.n)), 1e-15);
        const double k = std::cos(kPi / c.n);
        CylindricalShell minus = s, plus = s;
        minus.r1 = s.r1 * k;
        plus.r0 = s.r0 * k;
        // Volume: (r1^2 - r0^2) / 2 x angle x height for the shell, between those of minus and plus.
        const double span = std::min(c.a1 - c.a0, 360.0) * kDeg;
        const double v_minus = (minus.r1 * minus.r1 - minus.r0 * minus.r0) / 2 * span * 1.5;
        const double v_plus = (plus.r1 * plus.r1 - plus.r0 * plus.r0) / 2 * span * 1.5;
        EXPECT_GE(signed_volume(mesh), v_minus * (1 - 1e-12)) << c.n;
        EXPECT_LE(signed_volume(mesh), v_plus * (1 + 1e-12)) << c.n;
        expect_sandwiched(mesh, minus, plus, s.center, 1.5, 300);
        // Every vertex is on the shell's boundary: on a cylinder (or the axis) and a cap.
        for (const auto& v : mesh.vertices) {
            const glm::dvec3 q = v - s.center;
            const double r = std::hypot(q.x, q.z);
            EXPECT_TRUE(std::abs(r - s.r0) <= 1e-15 || std::abs(r - s.r1) <= 1e-15) << r;
            EXPECT_TRUE(std::abs(q.y - s.h0) <= 1e-15 || std::abs(q.y - s.h1) <= 1e-15) << q.y;
        }
    }
}

TEST(Tessellation, SphericalShellsAreClosedAndWithinTheStatedError) {
    struct Case {
        double r0, lon0, lon1, lat0, lat1;
        int n;
    };
    for (const Case& c : {Case{0.5, 0, 360, -90, 90, 3}, Case{0.5, 0, 360, -90, 90, 48}, Case{0, 0, 360, -90, 90, 16},
                          Case{0.4, 20, 160, -30, 60, 24}, Case{0, 300, 420, 0, 90, 32}, Case{0.3, 0, 270, -90, -20, 12},
                          Case{0, 0, 360, 10, 50, 20}, Case{0.2, -90, 90, -60, 0, 8}}) {
        SphericalShell s = sphere(c.r0, 1.25, {-0.1, 0.2, 0.3});
        s.lon0 = c.lon0;
        s.lon1 = c.lon1;
        s.lat0 = c.lat0;
        s.lat1 = c.lat1;
        TriangleMesh mesh = tessellate(s, c.n);
        TriangleMesh copy = mesh;
        EXPECT_NO_THROW(check_closed(copy, "t"));
        EXPECT_EQ(copy.triangles.size(), mesh.triangles.size());
        const double e = std::sin(kPi / c.n) * std::sin(kPi / c.n);
        EXPECT_NEAR(tessellation_error(s, c.n), 1.25 * e, 1e-15);
        const double k = std::cos(kPi / c.n);
        // A latitude limit b moves at most to atan(tan b / cos(pi / n)).
        auto moved = [&](double b) { return std::abs(b) >= 90 ? b : std::atan(std::tan(b * kDeg) / k) / kDeg; };
        SphericalShell minus = s, plus = s;
        minus.r1 = s.r1 * (1 - e);
        plus.r0 = s.r0 * (1 - e);
        minus.lat0 = std::max(s.lat0, moved(s.lat0));
        plus.lat0 = std::min(s.lat0, moved(s.lat0));
        minus.lat1 = std::min(s.lat1, moved(s.lat1));
        plus.lat1 = std::max(s.lat1, moved(s.lat1));
        // (With n = 3 the shrunk outer sphere is inside the inner one: only the upper bound holds.)
        if (minus.r1 <= minus.r0) minus.r1 = minus.r0 = 0;
        expect_sandwiched(mesh, minus, plus, s.center, 1.25, 300);
        for (const auto& v : mesh.vertices) {
            const double R = glm::length(v - s.center);
            EXPECT_TRUE(std::abs(R - s.r0) <= 1e-15 || std::abs(R - s.r1) <= 1e-15) << R;
        }
        // Volumes phi (r1^3 - r0^3) / 3 (sin lat1 - sin lat0): the mesh's lies between those of minus and plus.
        const double span = std::min(c.lon1 - c.lon0, 360.0) * kDeg;
        auto volume = [&](const SphericalShell& x) {
            return span * (std::pow(x.r1, 3) - std::pow(x.r0, 3)) / 3 * (std::sin(x.lat1 * kDeg) - std::sin(x.lat0 * kDeg));
        };
        EXPECT_LE(signed_volume(mesh), volume(plus) * (1 + 1e-12)) << c.n;
        EXPECT_GE(signed_volume(mesh), volume(minus) * (1 - 1e-12)) << c.n;
    }
}

TEST(Tessellation, FullShellChordsWithinTheStatedError) {
    // A full spherical shell: the mesh's chord lies between those of the spheres shrunk by the stated
    // error (closed forms), which to first order is a shift of error / cos(incidence) per crossing.
    const double r0 = 0.5, r1 = 1.0, D = 3.0;
    auto chord = [](double a, double b, double rho) {  // the shell a <= r <= b
        return 2 * (std::sqrt(std::max(b * b - rho * rho, 0.0)) - std::sqrt(std::max(a * a - rho * rho, 0.0)));
    };
    double worst_16 = 0, worst_256 = 0;
    for (const int n : {16, 64, 256}) {
        const TriangleMesh mesh = tessellate(sphere(r0, r1), n);
        const double e = std::sin(kPi / n) * std::sin(kPi / n);
        for (const double x : {0.0, 0.2, 0.4, 0.6, 0.8}) {
            const double rho = std::hypot(x, 0.013);
            const auto iv = mesh_query(mesh, ray({x, 0.013, D}, {0, 0, -1}));
            const double got = total(iv), want = chord(r0, r1, rho);
            EXPECT_GE(got, chord(r0, r1 * (1 - e), rho) - 1e-12) << n << " " << rho;
            EXPECT_LE(got, chord(r0 * (1 - e), r1, rho) + 1e-12) << n << " " << rho;
            EXPECT_EQ(iv.size(), rho < r0 * (1 - e) ? 2u : 1u);
            if (n == 16) worst_16 = std::max(worst_16, std::abs(got - want));
            if (n == 256) worst_256 = std::max(worst_256, std::abs(got - want));
        }
    }
    // Second order in 1 / n: 16 times the segments, over 100 times closer.
    EXPECT_LT(worst_256, worst_16 / 100);
}

TEST(Tessellation, TooFewSegmentsIsAnError) {
    EXPECT_THROW(tessellate(sphere(0, 1), 2), Error);
    EXPECT_THROW(tessellate(cylinder(0, 1, 0, 1), 0), Error);
    EXPECT_EQ(tessellation_segments(90, 64), 16);
    EXPECT_EQ(tessellation_segments(91, 64), 17);
    EXPECT_EQ(tessellation_segments(1, 3), 1);
}

}  // namespace
}  // namespace volref
