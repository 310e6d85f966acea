// The intervals of a ray inside a closed, outward-oriented triangle mesh, in double precision.
//
// Crossings: the watertight ray/triangle test of Woop, Benthin and Wald (JCGT 2013) in double: the
// vertices are translated to the ray origin and sheared so the ray runs along +z (the same arithmetic
// for a vertex whichever triangle it belongs to); the three 2-D edge functions of the projected
// triangle decide whether the ray passes through it. Their signs are exact (an error-free expansion
// when the fast floating-point filter cannot decide), and a zero edge function (a ray through an edge
// or a vertex) is resolved by a fixed symbolic perturbation of the ray (an offset (e, e^2) in the
// projected plane, e -> 0+): every edge then has one side for the ray, shared by the triangles on both
// sides of it, so a ray through an edge or a vertex crosses exactly the triangles the perturbed ray
// crosses: no crossing is lost or counted twice. (The signs are exact for the projected vertices as
// rounded, which every triangle sharing a vertex shares: the count is exact for that projected mesh.)
// A triangle whose projection has no area (seen edge-on, or of zero area) is never crossed; one that
// rounding leaves a sliver of area is crossed as that sliver, consistently with its neighbours. A ray
// lying in a face or along an edge is thus just inside or just outside. A crossing enters (winding +1) where dot(direction, normal)
// < 0 and leaves (-1) where it is > 0, normal = (b - a) x (c - a). Its t is the barycentric mix of the
// vertices' depths along the ray, clamped to their range.
//
// Intervals: crossings at t >= 0 are sorted; crossings of triangles sharing a vertex whose t differ by
// at most kMeshMergeRelative (|t| + the mesh's size) are one crossing (their windings add: a ray through
// an edge that only touches the surface gives 0); the winding number at t = 0 is minus the sum of all
// crossings' windings (it is 0 beyond the last one), so a ray that starts inside begins with an
// interval at t = 0; the intervals are where the winding number is > 0.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "geometry/RayIntervals.h"
#include "geometry/TriangleMesh.h"

namespace volref {

inline constexpr double kMeshMergeRelative = 1e-10;

struct MeshCrossing {
    double t;
    int winding;            // +1 entering, -1 leaving
    std::uint32_t triangle;  // index into the mesh's triangles
};

// A ray prepared for the watertight test (once per ray).
class RayTriangleFrame {
public:
    explicit RayTriangleFrame(const Ray& ray);
    // Whether the ray crosses triangle (a, b, c); if so its t (any sign) and winding (+1 entering).
    bool cross(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double& t, int& winding) const;

private:
    glm::dvec3 origin_;
    int kx_, ky_, kz_;
    double sx_, sy_, sz_;
};

// The exact sign (-1, 0, +1) of ax * by - ay * bx.
int exact_cross_sign(double ax, double ay, double bx, double by);

// Turns the crossings of `mesh` (any order; t < 0 ones are ignored) into sorted, disjoint intervals
// with t >= 0, appended to `out`. `scale` is the mesh's size (for the merge tolerance). Reorders
// `crossings`.
void crossings_to_intervals(std::vector<MeshCrossing>& crossings, const TriangleMesh& mesh, double scale,
                            std::vector<Interval>& out);

// Every triangle of the mesh, without Embree (for tests and tiny meshes); appends to `out`.
void mesh_intervals_brute_force(const Ray& ray, const TriangleMesh& mesh, std::vector<Interval>& out);

// The largest extent of the mesh's bounding box.
double mesh_scale(const TriangleMesh& mesh);

}  // namespace volref
