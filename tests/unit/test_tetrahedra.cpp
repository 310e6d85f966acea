// Tetrahedral bounds (issue 54, OpenGL Volumizer's voIndexedTetraSet; geometry/TetrahedralMesh.h): the
// VTK legacy UNSTRUCTURED_GRID reader (ASCII and BINARY, both cell layouts) and its refusals, the union's
// boundary (faces not cancelled by an opposite copy), its intervals against second methods (the box
// slab test for Volumizer's 5-tetrahedron cube, the convex polyhedron of the vertices' hull for the
// icosphere and the shell between two icospheres), the scene key and a render against box bounds.
#include <gtest/gtest.h>

#include "ErrorOf.h"
#include "TempDir.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneWriter.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/MeshIntervals.h"
#include "geometry/TetrahedralMesh.h"
#include "tests/unit/TestScenes.h"

namespace volref {
namespace {

namespace fs = std::filesystem;
using test::ortho_down_z;

const fs::path kData = fs::path(VOLREF_SOURCE_DIR) / "reference_scenes" / "data";

struct TempDir : test::TempDir {
    TempDir() : test::TempDir("tetra_test") {}
};

using test::error_of;

::testing::AssertionResult same(const std::vector<Interval>& got, const std::vector<Interval>& want, double tol) {
    auto list = [](const std::vector<Interval>& v) {
        std::string s;
        for (const auto& i : v) s += " [" + std::to_string(i.t0) + ", " + std::to_string(i.t1) + "]";
        return s;
    };
    if (got.size() != want.size())
        return ::testing::AssertionFailure() << got.size() << " intervals, want " << want.size() << ":" << list(got) << " want"
                                             << list(want);
    for (std::size_t k = 0; k < got.size(); ++k)
        if (!(std::abs(got[k].t0 - want[k].t0) <= tol) || !(std::abs(got[k].t1 - want[k].t1) <= tol))
            return ::testing::AssertionFailure() << "interval " << k << ":" << list(got) << " want" << list(want);
    return ::testing::AssertionSuccess();
}

// ---- the shapes ---------------------------------------------------------------------------------

// Volumizer's cube (seed 003 L1717-1738): vtxData's vertex order, cubeIndices as written.
TetrahedralMesh volumizer_cube(glm::dvec3 lo, glm::dvec3 hi) {
    TetrahedralMesh m;
    const int corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (const auto& c : corners) m.vertices.push_back(lo + (hi - lo) * glm::dvec3(c[0], c[1], c[2]));
    m.tetrahedra = {{0, 2, 5, 7}, {3, 2, 0, 7}, {1, 2, 5, 0}, {2, 7, 6, 5}, {5, 4, 0, 7}};
    return m;
}

std::string ascii_number(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

// The mesh as a VTK legacy ASCII file: version 2.0 records, or version 5.1 arrays.
std::string vtk_ascii(const TetrahedralMesh& m, bool arrays = false) {
    std::string s = std::string("# vtk DataFile Version ") + (arrays ? "5.1" : "2.0") + "\ntetrahedra\nASCII\nDATASET UNSTRUCTURED_GRID\n";
    s += "POINTS " + std::to_string(m.vertices.size()) + " double\n";
    for (const auto& p : m.vertices) s += ascii_number(p.x) + " " + ascii_number(p.y) + " " + ascii_number(p.z) + "\n";
    const std::size_t n = m.tetrahedra.size();
    if (arrays) {
        s += "CELLS " + std::to_string(n + 1) + " " + std::to_string(4 * n) + "\nOFFSETS vtktypeint64\n";
        for (std::size_t k = 0; k <= n; ++k) s += std::to_string(4 * k) + (k == n ? "\n" : " ");
        s += "CONNECTIVITY vtktypeint64\n";
        for (const auto& t : m.tetrahedra) s += std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + " " + std::to_string(t[3]) + "\n";
    } else {
        s += "CELLS " + std::to_string(n) + " " + std::to_string(5 * n) + "\n";
        for (const auto& t : m.tetrahedra) s += "4 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + " " + std::to_string(t[3]) + "\n";
    }
    s += "CELL_TYPES " + std::to_string(n) + "\n";
    for (std::size_t k = 0; k < n; ++k) s += "10\n";
    return s;
}

template <class T>
void put_be(std::string& s, T v) {
    using U = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
    const U u = std::bit_cast<U>(v);
    for (int b = int(sizeof(T)) - 1; b >= 0; --b) s += char((u >> (8 * b)) & 0xff);
}

// The mesh as a VTK legacy BINARY file (big-endian): float or double points, records or 5.1 arrays.
std::string vtk_binary(const TetrahedralMesh& m, bool arrays = false, bool float_points = false) {
    std::string s = std::string("# vtk DataFile Version ") + (arrays ? "5.1" : "3.0") + "\ntetrahedra\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
    s += "POINTS " + std::to_string(m.vertices.size()) + (float_points ? " float\n" : " double\n");
    for (const auto& p : m.vertices)
        for (int a = 0; a < 3; ++a) {
            if (float_points)
                put_be(s, float(p[a]));
            else
                put_be(s, p[a]);
        }
    s += "\n";
    const std::size_t n = m.tetrahedra.size();
    if (arrays) {
        s += "CELLS " + std::to_string(n + 1) + " " + std::to_string(4 * n) + "\nOFFSETS vtktypeint64\n";
        for (std::size_t k = 0; k <= n; ++k) put_be(s, std::int64_t(4 * k));
        s += "\nCONNECTIVITY vtktypeint64\n";
        for (const auto& t : m.tetrahedra)
            for (auto v : t) put_be(s, std::int64_t(v));
    } else {
        s += "CELLS " + std::to_string(n) + " " + std::to_string(5 * n) + "\n";
        for (const auto& t : m.tetrahedra) {
            put_be(s, std::int32_t(4));
            for (auto v : t) put_be(s, std::int32_t(v));
        }
    }
    s += "\nCELL_TYPES " + std::to_string(n) + "\n";
    for (std::size_t k = 0; k < n; ++k) put_be(s, std::int32_t(10));
    s += "\n";
    return s;
}

// ---- second methods -----------------------------------------------------------------------------

// The slab test, written here: the ray's [t0, t1] inside the box, t >= 0.
std::vector<Interval> slab(const Ray& r, glm::dvec3 lo, glm::dvec3 hi) {
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (r.direction[a] == 0.0) {
            if (r.origin[a] < lo[a] || r.origin[a] > hi[a]) return {};
            continue;
        }
        double ta = (lo[a] - r.origin[a]) / r.direction[a], tb = (hi[a] - r.origin[a]) / r.direction[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (t1 > t0) return {{t0, t1}};
    return {};
}

struct Plane {
    glm::dvec3 n;  // outward
    double d;      // inside: n . x <= d
};

// The facets of the convex hull of `points`: every plane through three of them with all the others
// on one side (up to `eps`), oriented outward.
std::vector<Plane> hull_planes(const std::vector<glm::dvec3>& points, double eps) {
    std::vector<Plane> planes;
    const std::size_t n = points.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            for (std::size_t k = j + 1; k < n; ++k) {
                glm::dvec3 nn = glm::cross(points[j] - points[i], points[k] - points[i]);
                if (glm::length(nn) < 1e-9) continue;
                nn = glm::normalize(nn);
                const double d = glm::dot(nn, points[i]);
                bool above = false, below = false;
                for (const auto& p : points) {
                    const double s = glm::dot(nn, p) - d;
                    above = above || s > eps;
                    below = below || s < -eps;
                }
                if (above && below) continue;
                planes.push_back(above ? Plane{-nn, -d} : Plane{nn, d});
            }
    return planes;
}

// The ray's interval inside the convex polyhedron of `planes` (Cyrus-Beck), t >= 0.
std::vector<Interval> convex(const Ray& r, const std::vector<Plane>& planes) {
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (const Plane& p : planes) {
        const double nd = glm::dot(p.n, r.direction), s = p.d - glm::dot(p.n, r.origin);
        if (nd == 0.0) {
            if (s < 0) return {};
        } else if (nd < 0) {
            t0 = std::max(t0, s / nd);
        } else {
            t1 = std::min(t1, s / nd);
        }
    }
    if (t1 > t0) return {{t0, t1}};
    return {};
}

// a minus b (each at most one interval).
std::vector<Interval> minus(const std::vector<Interval>& a, const std::vector<Interval>& b) {
    if (a.empty() || b.empty()) return a;
    std::vector<Interval> out;
    if (b[0].t0 > a[0].t0) out.push_back({a[0].t0, std::min(a[0].t1, b[0].t0)});
    if (b[0].t1 < a[0].t1) out.push_back({std::max(a[0].t0, b[0].t1), a[0].t1});
    std::erase_if(out, [](const Interval& i) { return !(i.t1 > i.t0); });
    return out;
}

std::vector<Interval> query(const BoundingGeometry& g, int id, const Ray& r) {
    std::vector<Interval> out;
    g.intervals(r, id, out);
    return out;
}

Ray random_ray(std::mt19937_64& rng, glm::dvec3 lo, glm::dvec3 hi, int k) {
    std::uniform_real_distribution<double> u(-0.5, 1.5), w(0.3, 0.7);
    std::normal_distribution<double> n01;
    const glm::dvec3 o = lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng));
    const glm::dvec3 target = lo + (hi - lo) * glm::dvec3(w(rng), w(rng), w(rng));
    const glm::dvec3 d = k % 2 ? glm::normalize(target - o) : glm::normalize(glm::dvec3(n01(rng), n01(rng), n01(rng)));
    return Ray{o, d};
}

// ---- the boundary -------------------------------------------------------------------------------

TEST(Tetrahedra, VolumizerCubeHasTwelveBoundaryTrianglesAndFourSharedFaces) {
    TetrahedralMesh m = volumizer_cube(glm::dvec3(0), glm::dvec3(1));
    // cubeIndices is oriented against VTK's right-hand rule: det -2 for the central tetrahedron, -1 for the others.
    std::vector<double> dets;
    for (const auto& t : m.tetrahedra) dets.push_back(tetrahedron_det(m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]], m.vertices[t[3]]));
    EXPECT_EQ(dets, (std::vector<double>{-2, -1, -1, -1, -1}));
    orient_tetrahedra(m, "cube");
    for (const auto& t : m.tetrahedra)
        EXPECT_GT(tetrahedron_det(m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]], m.vertices[t[3]]), 0.0);
    EXPECT_DOUBLE_EQ(tetrahedra_volume(m), 1.0);  // 1/3 + 4 x 1/6
    TetrahedralBoundary b = tetrahedra_boundary(m);
    EXPECT_EQ(b.surface.triangles.size(), 12u);
    EXPECT_EQ(b.internal_faces, 4u);
    EXPECT_EQ(b.surface.vertices.size(), 8u);
    EXPECT_NO_THROW(check_closed(b.surface, "cube"));  // a 2-manifold even
    EXPECT_NEAR(signed_volume(b.surface), 1.0, 1e-15);  // outward already
}

TEST(Tetrahedra, EveryFileLayoutReadsTheSameTetrahedra) {
    TempDir dir;
    const TetrahedralMesh cube = volumizer_cube(glm::dvec3(-0.5, 0.25, 1), glm::dvec3(1.5, 2, 1.75));
    TetrahedralMesh want = cube;
    orient_tetrahedra(want, "cube");
    const std::vector<std::string> files{dir.write("records.vtk", vtk_ascii(cube)), dir.write("arrays.vtk", vtk_ascii(cube, true)),
                                         dir.write("records_bin.vtk", vtk_binary(cube)),
                                         dir.write("arrays_bin.vtk", vtk_binary(cube, true)),
                                         dir.write("float_bin.vtk", vtk_binary(cube, false, true))};
    for (const std::string& f : files) {
        const TetrahedralMesh m = read_tetrahedra(f);
        EXPECT_EQ(m.vertices, want.vertices) << f;
        EXPECT_EQ(m.tetrahedra, want.tetrahedra) << f;
        EXPECT_EQ(read_tetrahedral_bounds(f).triangles.size(), 12u) << f;
    }
    // Keywords in any case, CRLF line ends, FIELD and METADATA skipped, attributes after the geometry ignored.
    std::string text = vtk_ascii(cube);
    text.insert(text.find("POINTS"), "FIELD FieldData 2\nTIME 1 1 double\n0.5\nCYCLE 1 1 int\n3\nMETADATA\nINFORMATION 0\n\n");
    text += "CELL_DATA 5\nSCALARS region int 1\nLOOKUP_TABLE default\n1 2 3 4 5\n";
    std::string crlf;
    for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    for (std::string& k : std::vector<std::string>{"points", "cells", "cell_types"}) {
        std::string up = k;
        for (char& c : up) c = char(std::toupper(c));
        const auto at = crlf.find(up + " ");
        crlf.replace(at, up.size(), k);
    }
    const TetrahedralMesh m = read_tetrahedra(dir.write("extras.vtk", crlf));
    EXPECT_EQ(m.tetrahedra, want.tetrahedra);
    // ASCII float points are rounded to float, as VTK holds them.
    std::string floats = "# vtk DataFile Version 2.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0\n0.1 0 0\n0 1 0\n0 0 1\n"
                         "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";
    EXPECT_EQ(read_tetrahedra(dir.write("float.vtk", floats)).vertices[1].x, double(0.1f));
}

TEST(Tetrahedra, EitherOrientationGivesTheSameRegion) {
    TempDir dir;
    TetrahedralMesh cube = volumizer_cube(glm::dvec3(0), glm::dvec3(2));
    TetrahedralMesh flipped = cube, mixed = cube;
    for (auto& t : flipped.tetrahedra) std::swap(t[0], t[1]);
    for (std::size_t k = 0; k < 5; k += 2) std::swap(mixed.tetrahedra[k][1], mixed.tetrahedra[k][3]);
    const TriangleMesh a = read_tetrahedral_bounds(dir.write("a.vtk", vtk_ascii(cube)));
    const TriangleMesh b = read_tetrahedral_bounds(dir.write("b.vtk", vtk_ascii(flipped)));
    const TriangleMesh c = read_tetrahedral_bounds(dir.write("c.vtk", vtk_ascii(mixed)));
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.triangles, c.triangles);
    EXPECT_NEAR(signed_volume(a), 8.0, 1e-14);
}

TEST(Tetrahedra, RepeatedPointsAreMergedSoFacesAreShared) {
    // Each cell with its own four points (as some exporters write): 20 points, the same 8 positions.
    TetrahedralMesh cube = volumizer_cube(glm::dvec3(0), glm::dvec3(1)), split;
    for (const auto& t : cube.tetrahedra) {
        std::array<std::uint32_t, 4> s{};
        for (int i = 0; i < 4; ++i) {
            s[std::size_t(i)] = std::uint32_t(split.vertices.size());
            split.vertices.push_back(cube.vertices[t[std::size_t(i)]]);
        }
        split.tetrahedra.push_back(s);
    }
    orient_tetrahedra(split, "split");
    const TetrahedralBoundary b = tetrahedra_boundary(split);
    EXPECT_EQ(b.surface.triangles.size(), 12u);
    EXPECT_EQ(b.internal_faces, 4u);
    EXPECT_EQ(b.surface.vertices.size(), 8u);
}

// ---- intervals against second methods -------------------------------------------------------------

TEST(Tetrahedra, FiveTetrahedronBoxEqualsTheBoxOnRandomRays) {
    TempDir dir;
    const glm::dvec3 lo(-0.5, 0.25, 1), hi(1.5, 2, 1.75);
    const TriangleMesh surface = read_tetrahedral_bounds(dir.write("cube.vtk", vtk_ascii(volumizer_cube(lo, hi))));
    BoundingGeometry g;
    const int box = g.add_box(lo, hi, glm::dvec3(-100), glm::dvec3(100));
    const int tets = g.add_mesh(surface, glm::dvec3(-100), glm::dvec3(100), Closedness::Cycle);
    g.commit();
    std::mt19937_64 rng(54);
    int hits = 0;
    for (int k = 0; k < 4000; ++k) {
        const Ray r = random_ray(rng, lo, hi, k);
        const std::vector<Interval> a = query(g, tets, r), b = query(g, box, r);
        EXPECT_TRUE(same(a, b, 1e-13)) << k;             // the box bounds (BoundingGeometry's slab test)
        EXPECT_TRUE(same(a, slab(r, lo, hi), 1e-13)) << k;  // the slab test written here
        std::vector<Interval> brute;
        mesh_intervals_brute_force(r, surface, brute);
        normalize_intervals(brute);
        EXPECT_TRUE(same(a, brute, 0.0)) << k;  // Embree finds every crossing
        hits += !a.empty();
    }
    EXPECT_GT(hits, 1500);
    // Rays through the cube's edges, vertices and its internal faces' diagonals: one chord, never split
    // where the five tetrahedra meet.
    const double s3 = std::sqrt(3.0);
    const TriangleMesh unit = read_tetrahedral_bounds(dir.write("unit.vtk", vtk_ascii(volumizer_cube(glm::dvec3(0), glm::dvec3(1)))));
    BoundingGeometry u;
    const int id = u.add_mesh(unit, glm::dvec3(-9), glm::dvec3(9), Closedness::Cycle);
    u.commit();
    EXPECT_TRUE(same(query(u, id, Ray{{-1, -1, -1}, glm::normalize(glm::dvec3(1, 1, 1))}), {{s3, 2 * s3}}, 1e-14));
    EXPECT_TRUE(same(query(u, id, Ray{{0.5, 0.5, 3}, {0, 0, -1}}), {{2, 3}}, 1e-15));  // the internal tetrahedron's edge
    EXPECT_TRUE(same(query(u, id, Ray{{1.0 / 3, 2.0 / 3, 3}, {0, 0, -1}}), {{2, 3}}, 1e-15));
    EXPECT_TRUE(same(query(u, id, Ray{{0.5, 0.5, 0.5}, {0, 0, 1}}), {{0, 0.5}}, 1e-15));  // starting inside
}

TEST(Tetrahedra, IcosphereEqualsItsConvexPolyhedron) {
    const TetrahedralMesh m = read_tetrahedra((kData / "tetra-icosphere.vtk").string());
    EXPECT_EQ(m.vertices.size(), 43u);  // the centre and 42 on the sphere
    EXPECT_EQ(m.tetrahedra.size(), 80u);
    const TetrahedralBoundary b = tetrahedra_boundary(m);
    EXPECT_EQ(b.surface.triangles.size(), 80u);
    EXPECT_EQ(b.internal_faces, 120u);  // 80 x 3 / 2: every face through the centre is shared
    const std::vector<glm::dvec3> shell(m.vertices.begin() + 1, m.vertices.end());
    const std::vector<Plane> planes = hull_planes(shell, 1e-9);
    EXPECT_GE(planes.size(), 80u);
    TriangleMesh surface = b.surface;
    check_closed(surface, "icosphere", Closedness::Cycle);
    // Its volume is the hull's (the union is convex).
    EXPECT_NEAR(signed_volume(surface), tetrahedra_volume(m), 1e-10);
    BoundingGeometry g;
    const int id = g.add_mesh(surface, glm::dvec3(-1e3), glm::dvec3(1e3), Closedness::Cycle);
    g.commit();
    std::mt19937_64 rng(80);
    int hits = 0;
    for (int k = 0; k < 4000; ++k) {
        const Ray r = random_ray(rng, glm::dvec3(6), glm::dvec3(58), k);
        const std::vector<Interval> got = query(g, id, r);
        EXPECT_TRUE(same(got, convex(r, planes), 1e-11)) << k;
        hits += !got.empty();
    }
    EXPECT_GT(hits, 1500);
}

TEST(Tetrahedra, ShellBetweenTwoIcospheresIsTheOuterPolyhedronMinusTheInner) {
    const TetrahedralMesh m = read_tetrahedra((kData / "tetra-shell.vtk").string());
    EXPECT_EQ(m.vertices.size(), 84u);
    EXPECT_EQ(m.tetrahedra.size(), 240u);
    const TetrahedralBoundary b = tetrahedra_boundary(m);
    EXPECT_EQ(b.surface.triangles.size(), 160u);  // 80 outer, 80 inner (facing the hole)
    EXPECT_EQ(b.internal_faces, (240u * 4 - 160) / 2);
    std::vector<glm::dvec3> outer, inner;
    for (const auto& p : m.vertices) (glm::length(p) > 21 ? outer : inner).push_back(p);
    ASSERT_EQ(outer.size(), 42u);
    const std::vector<Plane> po = hull_planes(outer, 1e-9), pi = hull_planes(inner, 1e-9);
    TriangleMesh surface = b.surface;
    check_closed(surface, "shell", Closedness::Cycle);
    BoundingGeometry g;
    const int id = g.add_mesh(surface, glm::dvec3(-1e3), glm::dvec3(1e3), Closedness::Cycle);
    g.commit();
    std::mt19937_64 rng(240);
    int two = 0;
    for (int k = 0; k < 4000; ++k) {
        const Ray r = random_ray(rng, glm::dvec3(-26), glm::dvec3(26), k);
        const std::vector<Interval> got = query(g, id, r);
        EXPECT_TRUE(same(got, minus(convex(r, po), convex(r, pi)), 1e-11)) << k;
        two += got.size() == 2;
    }
    EXPECT_GT(two, 800);  // through the hole
}

TEST(Tetrahedra, OverlappingAndTouchingTetrahedraGiveTheUnion) {
    // Two cubes of five tetrahedra touching along an edge only (the union's boundary is not a 2-manifold
    // there: 4 triangles at that edge), and one of them repeated (every face twice, on one side).
    TetrahedralMesh a = volumizer_cube(glm::dvec3(0), glm::dvec3(1)), b = volumizer_cube(glm::dvec3(1, 1, 0), glm::dvec3(2, 2, 1));
    TetrahedralMesh m = a;
    for (auto t : b.tetrahedra) {
        for (auto& v : t) v += 8;
        m.tetrahedra.push_back(t);
    }
    m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
    TetrahedralMesh twice = m;
    twice.tetrahedra.insert(twice.tetrahedra.end(), a.tetrahedra.begin(), a.tetrahedra.end());
    // And a tetrahedron crossing the first cube's top face.
    TetrahedralMesh poke = m;
    const std::uint32_t base = std::uint32_t(poke.vertices.size());
    for (const glm::dvec3 p : {glm::dvec3(0.2, 0.2, 0.5), glm::dvec3(0.8, 0.2, 0.5), glm::dvec3(0.5, 0.8, 0.5), glm::dvec3(0.5, 0.4, 1.6)})
        poke.vertices.push_back(p);
    poke.tetrahedra.push_back({base, base + 1, base + 2, base + 3});
    for (TetrahedralMesh* t : {&m, &twice, &poke}) orient_tetrahedra(*t, "two cubes");
    const TetrahedralBoundary bm = tetrahedra_boundary(m), bt = tetrahedra_boundary(twice), bp = tetrahedra_boundary(poke);
    EXPECT_EQ(bm.surface.triangles.size(), 24u);
    EXPECT_EQ(bt.surface.triangles.size(), 2u * 12u + 12u);  // the repeated cube's outer faces twice; its inner ones still cancel
    EXPECT_EQ(bt.internal_faces, 2u * 4u + 4u);
    TriangleMesh sm = bm.surface;
    EXPECT_THROW(check_closed(sm, "edge"), Error);  // not a 2-manifold ...
    EXPECT_NO_THROW(check_closed(sm, "edge", Closedness::Cycle));  // ... but closed
    BoundingGeometry g;
    const int im = g.add_mesh(bm.surface, glm::dvec3(-9), glm::dvec3(9), Closedness::Cycle);
    const int it = g.add_mesh(bt.surface, glm::dvec3(-9), glm::dvec3(9), Closedness::Cycle);
    const int ip = g.add_mesh(bp.surface, glm::dvec3(-9), glm::dvec3(9), Closedness::Cycle);
    g.commit();
    // Membership by hand: in either cube, or in the poking tetrahedron (barycentric coordinates).
    const auto& pv = poke.vertices;
    const auto& pt = poke.tetrahedra.back();
    auto in_tet = [&](glm::dvec3 x) {
        const glm::dvec3 &p0 = pv[pt[0]], &p1 = pv[pt[1]], &p2 = pv[pt[2]], &p3 = pv[pt[3]];
        const double d = tetrahedron_det(p0, p1, p2, p3);
        return tetrahedron_det(x, p1, p2, p3) / d >= 0 && tetrahedron_det(p0, x, p2, p3) / d >= 0 &&
               tetrahedron_det(p0, p1, x, p3) / d >= 0 && tetrahedron_det(p0, p1, p2, x) / d >= 0;
    };
    auto in_cube = [](glm::dvec3 x, glm::dvec3 lo) {
        return x.x >= lo.x && x.x <= lo.x + 1 && x.y >= lo.y && x.y <= lo.y + 1 && x.z >= lo.z && x.z <= lo.z + 1;
    };
    auto inside = [&](const std::vector<Interval>& v, double t) {
        for (const auto& i : v)
            if (i.t0 <= t && t <= i.t1) return true;
        return false;
    };
    std::mt19937_64 rng(3);
    for (int k = 0; k < 1500; ++k) {
        const Ray r = random_ray(rng, glm::dvec3(0), glm::dvec3(2, 2, 1.6), k);
        const std::vector<Interval> vm = query(g, im, r), vt = query(g, it, r), vp = query(g, ip, r);
        EXPECT_TRUE(same(vt, vm, 1e-14)) << k;  // a tetrahedron twice is still inside once
        // Both cubes' chords by the slab test, merged where they touch.
        std::vector<Interval> want = slab(r, glm::dvec3(0), glm::dvec3(1));
        for (const auto& i : slab(r, glm::dvec3(1, 1, 0), glm::dvec3(2, 2, 1))) want.push_back(i);
        normalize_intervals(want);
        EXPECT_TRUE(same(vm, want, 1e-13)) << k;
        // The poked union at sample points (away from the boundary by 1e-9).
        for (int s = 0; s < 40; ++s) {
            const double t = 0.1 * s + 0.0123;
            const glm::dvec3 x = r.origin + t * r.direction;
            const bool want_in = in_cube(x, glm::dvec3(0)) || in_cube(x, glm::dvec3(1, 1, 0)) || in_tet(x);
            bool near_edge = false;
            for (const auto& i : vp) near_edge = near_edge || std::abs(t - i.t0) < 1e-9 || std::abs(t - i.t1) < 1e-9;
            if (!near_edge) {
                EXPECT_EQ(inside(vp, t), want_in) << k << " t " << t;
            }
        }
    }
}

// ---- bad input ------------------------------------------------------------------------------------

const std::string kHead = "# vtk DataFile Version 2.0\nbad\nASCII\nDATASET UNSTRUCTURED_GRID\n";
const std::string kPoints = "POINTS 5 double\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";  // lines 5 to 10

TEST(Tetrahedra, BadFilesAreRefusedNamingTheFileAndPlace) {
    TempDir dir;
    struct Case {
        const char* name;
        std::string text;
        std::string message;  // after "PATH: "
    };
    const std::vector<Case> cases{
        {"flat.vtk", kHead + "POINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n2 3 0\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
         "line 11: cell 0 (points 0, 1, 2, 3) is degenerate: |det(b - a, c - a, d - a)| = 0 <= 1e-12 l^3"},
        {"nearly_flat.vtk", kHead + "POINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n0.3 0.3 1e-13\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
         "line 11: cell 0 (points 0, 1, 2, 3) is degenerate"},
        {"repeated.vtk", kHead + kPoints + "CELLS 2 10\n4 0 1 2 3\n4 0 1 1 4\nCELL_TYPES 2\n10 10\n",
         "line 13: cell 1 (points 0, 1, 1, 4) is degenerate"},
        {"range.vtk", kHead + kPoints + "CELLS 2 10\n4 0 1 2 3\n4 1 2 3 5\nCELL_TYPES 2\n10\n10\n",
         "line 13: cell 1: point index 5 is not one of the 5 POINTS (0 to 4)"},
        {"negative.vtk", kHead + kPoints + "CELLS 1 5\n4 0 1 -2 3\nCELL_TYPES 1\n10\n",
         "line 12: cell 0: point index -2 is not one of the 5 POINTS (0 to 4)"},
        {"nan.vtk", kHead + "POINTS 4 double\n0 0 0\n1 nan 0\n0 1 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
         "line 7: POINTS: point 1: 'nan' is not a finite number"},
        {"inf.vtk", kHead + "POINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n0 0 -inf\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
         "line 9: POINTS: point 3: '-inf' is not a finite number"},
        {"huge.vtk", kHead + "POINTS 4 double\n0 0 0\n1 0 0\n0 1e101 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
         "line 8: POINTS: point 2 (0, 1e+101, 0) is beyond volref's range (|x| <= 1e100)"},
        {"float_overflow.vtk", kHead + "POINTS 4 float\n0 0 0\n1 0 0\n0 1e39 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
         "line 8: POINTS: point 2: 1e+39 is out of the range of float"},
        {"hexahedron.vtk", kHead + kPoints + "CELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n12\n",
         "line 16: CELL_TYPES: cell 1 has type 12 (VTK_HEXAHEDRON); volref reads tetrahedra only (type 10, VTK_TETRA)"},
        {"triangle.vtk", kHead + kPoints + "CELLS 2 9\n4 0 1 2 3\n3 1 2 3\nCELL_TYPES 2\n10 5\n",
         "line 15: CELL_TYPES: cell 1 has type 5 (VTK_TRIANGLE)"},
        {"three_points.vtk", kHead + kPoints + "CELLS 2 9\n4 0 1 2 3\n3 1 2 3\nCELL_TYPES 2\n10 10\n",
         "line 13: cell 1 has 3 points; a tetrahedron (type 10) has 4"},
        {"types_count.vtk", kHead + kPoints + "CELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 1\n10\n",
         "line 14: CELL_TYPES 1 does not match the 2 cells of CELLS (line 11)"},
        {"cells_size.vtk", kHead + kPoints + "CELLS 2 9\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n10\n",
         "line 13: CELLS: cell 1's 4 points run past the 9 numbers CELLS gives"},
        {"cells_more.vtk", kHead + kPoints + "CELLS 2 11\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n10\n",
         "line 14: CELLS: expected an integer, got 'CELL_TYPES'"},
        {"cells_fewer.vtk", kHead + kPoints + "CELLS 3 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 3\n10\n10\n10\n",
         "line 13: CELLS: the 10 numbers hold 2 records, CELLS gives 3"},
        {"offsets.vtk", kHead + kPoints + "CELLS 3 8\nOFFSETS vtktypeint64\n0 4 7\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 3 4\nCELL_TYPES 2\n10 10\n",
         "line 13: OFFSETS: the last offset is 7, CELLS gives 8 indices"},
        {"offsets_order.vtk", kHead + kPoints + "CELLS 3 8\nOFFSETS vtktypeint64\n0 5 4\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 3 4\nCELL_TYPES 2\n10 10\n",
         "line 13: OFFSETS: offset 2 (4) is less than the one before it (5)"},
        {"arrays_size.vtk", kHead + kPoints + "CELLS 3 8\nOFFSETS vtktypeint64\n0 4 8\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 1 0\nCELL_TYPES 2\n10 10\n",
         "line 15: cell 1 (points 1, 2, 1, 0) is degenerate"},
        {"points_short.vtk", kHead + "POINTS 5 double\n0 0 0\n1 0 0\n", "line 5: POINTS: 15 numbers cannot fit in the 13 bytes left in the file"},
        {"truncated.vtk", kHead + kPoints + "CELLS 2 10\n4 0 1 2 3\n4 1 2      \n", "unexpected end of file: expected CELLS"},
        {"no_types.vtk", kHead + kPoints + "CELLS 1 5\n4 0 1 2 3\n", "no CELL_TYPES section (tetrahedra need POINTS, CELLS and CELL_TYPES)"},
        {"empty.vtk", kHead + kPoints + "CELLS 0 0\nCELL_TYPES 0\n", "line 11: CELLS: the file has no tetrahedra"},
        {"twice.vtk", kHead + kPoints + kPoints, "line 11: POINTS given twice (first on line 5)"},
        {"polydata.vtk", "# vtk DataFile Version 2.0\nbad\nASCII\nDATASET POLYDATA\n",
         "line 4: DATASET 'POLYDATA' is not a set of tetrahedra (volref reads UNSTRUCTURED_GRID with cell type 10)"},
        {"not_vtk.vtk", "ply\nformat ascii 1.0\nend_header\n", "not a VTK legacy file: line 1 is 'ply'"},
        {"keyword.vtk", kHead + kPoints + "POLYGONS 1 5\n", "line 11: unknown keyword 'POLYGONS'"},
        {"long_points.vtk", kHead + "POINTS 4 long\n", "line 5: POINTS: type 'long' is not supported (volref reads float or double)"},
    };
    for (const Case& c : cases) {
        const std::string path = dir.write(c.name, c.text);
        const std::string msg = error_of([&] { read_tetrahedral_bounds(path); });
        EXPECT_EQ(msg.rfind(path + ": " + c.message, 0), 0u) << c.name << ": " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << c.name;
    }
    // A missing file and a directory, by check_input_file.
    const std::string missing = (dir.path / "missing.vtk").string();
    EXPECT_EQ(error_of([&] { read_tetrahedra(missing); }).rfind(missing + ": cannot read file: ", 0), 0u);
    EXPECT_EQ(error_of([&] { read_tetrahedra(dir.path.string()); }).rfind(dir.path.string() + ": cannot read file: ", 0), 0u);
}

TEST(Tetrahedra, BadBinaryFilesNameTheByte) {
    TempDir dir;
    TetrahedralMesh cube = volumizer_cube(glm::dvec3(0), glm::dvec3(1));
    const std::string head = "# vtk DataFile Version 3.0\ntetrahedra\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 double\n";
    const std::size_t points_at = head.size();
    // A NaN vertex: point 6's x at byte points_at + 6 * 24.
    TetrahedralMesh nan = cube;
    nan.vertices[6].x = std::numeric_limits<double>::quiet_NaN();
    std::string msg = error_of([&] { read_tetrahedra(dir.write("nan.vtk", vtk_binary(nan))); });
    EXPECT_NE(msg.find(": byte " + std::to_string(points_at + 6 * 24) + ": POINTS: point 6 is not finite (nan, 1, 1)"), std::string::npos) << msg;
    // An index out of range: cell 3's first index (records after "CELLS 5 25\n").
    TetrahedralMesh range = cube;
    range.tetrahedra[3][0] = 8;
    const std::string text = vtk_binary(range);
    const std::size_t cells_at = text.find("CELLS 5 25\n") + std::string("CELLS 5 25\n").size();
    msg = error_of([&] { read_tetrahedra(dir.write("range.vtk", text)); });
    EXPECT_NE(msg.find(": byte " + std::to_string(cells_at + 3 * 20) + ": cell 3: point index 8 is not one of the 8 POINTS"), std::string::npos) << msg;
    // A wrong type in the 5.1 arrays, a degenerate cell, a truncated block.
    TetrahedralMesh flat = cube;
    flat.vertices[3] = glm::dvec3(0.5, 0.5, 0);  // cell 1 = {3, 2, 0, 7}: 3 on the segment 0-2, flat (no other cell has 3)
    const std::string arrays = vtk_binary(flat, true);
    msg = error_of([&] { read_tetrahedra(dir.write("flat.vtk", arrays)); });
    const std::size_t conn_at = arrays.find("CONNECTIVITY vtktypeint64\n") + std::string("CONNECTIVITY vtktypeint64\n").size();
    EXPECT_NE(msg.find(": byte " + std::to_string(conn_at + 4 * 8) + ": cell 1 (points 3, 2, 0, 7) is degenerate"), std::string::npos) << msg;
    std::string types = vtk_binary(cube);
    types[types.size() - 2] = 12;  // the last cell's type
    msg = error_of([&] { read_tetrahedra(dir.write("type.vtk", types)); });
    EXPECT_NE(msg.find(": byte " + std::to_string(types.size() - 5) + ": CELL_TYPES: cell 4 has type 12 (VTK_HEXAHEDRON)"), std::string::npos) << msg;
    const std::string cut = vtk_binary(cube).substr(0, points_at + 100);
    msg = error_of([&] { read_tetrahedra(dir.write("cut.vtk", cut)); });
    EXPECT_NE(msg.find("POINTS: 24 numbers cannot fit in the"), std::string::npos) << msg;
}

TEST(Tetrahedra, FileOverTheMemoryLimitIsRefusedBeforeItIsRead) {
    TempDir dir;
    const std::string path = dir.write("big.vtk", vtk_ascii(volumizer_cube(glm::dvec3(0), glm::dvec3(1))) + std::string(4096, ' '));
    const std::size_t saved = memory_limit();
    set_memory_limit(1024);
    const std::string msg = error_of([&] { read_tetrahedra(path); });
    set_memory_limit(saved);
    EXPECT_EQ(msg.rfind(path + ": reading the file: needs", 0), 0u) << msg;
    EXPECT_NE(msg.find("memory limit"), std::string::npos) << msg;
}

TEST(Tetrahedra, InMemoryChecksNameTheTetrahedron) {
    TetrahedralMesh m = volumizer_cube(glm::dvec3(0), glm::dvec3(1));
    m.tetrahedra[2][1] = 9;
    EXPECT_EQ(error_of([&] { orient_tetrahedra(m, "set"); }), "set: tetrahedron 2: vertex index 9 is not one of the 8 vertices");
    m = volumizer_cube(glm::dvec3(0), glm::dvec3(1));
    m.tetrahedra[4] = {0, 1, 2, 3};  // the bottom face: flat
    EXPECT_EQ(error_of([&] { orient_tetrahedra(m, "set"); }).rfind("set: tetrahedron 4 (points 0, 1, 2, 3) is degenerate", 0), 0u);
}

// ---- the scene key and a render -------------------------------------------------------------------

TEST(TetrahedraBounds, SceneKeyIsReadWrittenAndCountIsASlicers) {
    TempDir dir;
    dir.write("box.vtk", vtk_ascii(volumizer_cube(glm::dvec3(2), glm::dvec3(6))));
    auto scene = [&](const std::string& bounds) {
        return R"({"volume": {"source": {"field": "constant", "dims": [9, 9, 9]}, "bounds": )" + bounds + "}}";
    };
    const Scene s = parse_scene(scene(R"({"type": "tetrahedra", "file": "box.vtk"})"), dir.path, "scene.json");
    EXPECT_EQ(s.volume().bounds.type, BoundsSpec::Type::Tetrahedra);
    EXPECT_EQ(s.volume().bounds.mesh, dir.path / "box.vtk");
    EXPECT_EQ(s.volume().bounds.overlap, BoundsSpec::Overlap::Union);
    const nlohmann::ordered_json j = scene_json(s);
    EXPECT_EQ(j["volume"]["bounds"]["type"], "tetrahedra");
    EXPECT_EQ(j["volume"]["bounds"]["overlap"], "union");
    const Scene t = parse_scene(j.dump(), dir.path, "written.json");
    EXPECT_EQ(scene_json(t), j);  // a fixed point of read and write
    EXPECT_NO_THROW(parse_scene(scene(R"({"type": "tetrahedra", "file": "box.vtk", "overlap": "union"})"), dir.path, "scene.json"));
    // "count" is a slicer's (placement "slices"): a ray caster refuses it when the scene is prepared.
    const Scene counted = parse_scene(scene(R"({"type": "tetrahedra", "file": "box.vtk", "overlap": "count"})"), dir.path, "scene.json");
    EXPECT_EQ(counted.volume().bounds.overlap, BoundsSpec::Overlap::Count);
    EXPECT_EQ(scene_json(counted)["volume"]["bounds"]["overlap"], "count");
    EXPECT_NE(error_of([&] { render_scene(counted, {.threads = 1}); }).find("volume.bounds.overlap: \"count\""), std::string::npos);
    EXPECT_EQ(error_of([&] { parse_scene(scene(R"({"type": "tetrahedra", "file": "box.vtk", "overlap": "twice"})"), dir.path, "scene.json"); }),
              "scene.json: volume.bounds.overlap: expected one of \"union\", \"count\", got \"twice\"");
    EXPECT_EQ(error_of([&] { parse_scene(scene(R"({"type": "tetrahedra"})"), dir.path, "scene.json"); }), "scene.json: volume.bounds.file: required");
    const std::string msg = error_of([&] { parse_scene(scene(R"({"type": "tetrahedra", "file": "box.vtk", "min": [0, 0, 0]})"), dir.path, "scene.json"); });
    EXPECT_EQ(msg.rfind("scene.json: volume.bounds.min: ", 0), 0u) << msg;
    EXPECT_NE(msg.find("overlap"), std::string::npos) << msg;
    // A bad file is refused when the scene is rendered, naming the file.
    dir.write("flat.vtk", kHead + "POINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n2 3 0\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n");
    const Scene f = parse_scene(scene(R"({"type": "tetrahedra", "file": "flat.vtk"})"), dir.path, "scene.json");
    EXPECT_NE(error_of([&] { render_scene(f, {.threads = 1}); }).find((dir.path / "flat.vtk").string() + ": line 11: cell 0"), std::string::npos);
}

TEST(TetrahedraBounds, FiveTetrahedronBoxRendersAsTheBox) {
    TempDir dir;
    const glm::dvec3 lo(3.25, 2.5, 4), hi(27.5, 26.75, 25.5);
    const std::string file = dir.write("box.vtk", vtk_ascii(volumizer_cube(lo, hi)));
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {33, 33, 33};
    g.center = glm::dvec3(15, 16, 14);
    g.sigma = 7;
    Scene box = test::field_scene(g);
    box.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {1.0, 1.0, 0.8, 0.3}};
    box.volume().transfer.opacity = {{0.0, 0.02}, {1.0, 0.4}};
    box.volume().bounds.min = lo;
    box.volume().bounds.max = hi;
    box.camera.type = CameraSpec::Type::Perspective;
    box.camera.eye = {70, -45, 60};
    box.camera.target = {16, 16, 16};
    box.camera.up = {0, 0, 1};
    box.camera.fov_y = 40;
    box.image.width = box.image.height = 40;
    box.render.step = 0.5;
    Scene tets = box;
    tets.volume().bounds = BoundsSpec{};
    tets.volume().bounds.type = BoundsSpec::Type::Tetrahedra;
    tets.volume().bounds.mesh = file;
    for (const CameraSpec& camera : {box.camera, ortho_down_z(16, 16, 80, 34)}) {
        box.camera = tets.camera = camera;
        const Image a = render_scene(box, {.threads = 2}), b = render_scene(tets, {.threads = 2});
        ASSERT_EQ(a.pixels.size(), b.pixels.size());
        double largest = 0.0, sum = 0.0;
        for (std::size_t i = 0; i < a.pixels.size(); ++i) {
            largest = std::max(largest, std::abs(a.pixels[i] - b.pixels[i]));
            sum += a.pixels[i];
        }
        EXPECT_LE(largest, 1e-12);  // measured: within a few ulps (the crossings' t to ~1e-15 of the slab test's)
        EXPECT_GT(sum, 10.0);      // something drawn
    }
}

// overlap "count" (Volumizer slicing each tetrahedron on its own): a slicer's fragment covered by m
// tetrahedra is blended m times. The 5-tetrahedron cube written twice over a constant slab, one ray
// down z off the inner faces: 16 planes, each blended twice in rgba8: the hand recurrence of 32 blends;
// union: 16.
TEST(TetrahedraBounds, OverlapCountBlendsEachFragmentOncePerTetrahedron) {
    TempDir dir;
    TetrahedralMesh twice = volumizer_cube(glm::dvec3(0.0), glm::dvec3(4.0, 4.0, 15.0));
    const std::size_t n = twice.tetrahedra.size();
    for (std::size_t i = 0; i < n; ++i) twice.tetrahedra.push_back(twice.tetrahedra[i]);
    dir.write("twice.vtk", vtk_ascii(twice));
    auto render = [&](const char* overlap) {
        const std::string text = std::string(R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [5, 5, 16]},
            "bounds": {"type": "tetrahedra", "file": "twice.vtk", "overlap": ")") + overlap + R"("},
            "transfer": {"color": [[0, 1, 1, 1], [1, 1, 1, 1]], "opacity": [[0, 0.2], [1, 0.2]]}},
            "camera": {"type": "orthographic", "eye": [1.7, 2.3, 25], "target": [1.7, 2.3, 0], "up": [0, 1, 0], "height": 0.01},
            "image": {"width": 1, "height": 1},
            "render": {"step": 1, "step_units": "world", "profile": "volumizer"}})";
        const Image im = render_scene(parse_scene(text, dir.path, "scene.json"), {.threads = 1});
        return glm::dvec4(im.at(0, 0, 0), im.at(0, 0, 1), im.at(0, 0, 2), im.at(0, 0, 3));
    };
    auto iterate = [](int blends) {
        int c = 0;  // src-alpha in codes: round((255 * 51 + C * 204) / 255)
        for (int k = 0; k < blends; ++k) c = int(std::floor((255.0 * 51.0 + double(c) * 204.0) / 255.0 + 0.5));
        return c / 255.0;
    };
    EXPECT_EQ(render("union").r, iterate(16));
    EXPECT_EQ(render("count").r, iterate(32));
}

}  // namespace
}  // namespace volref
