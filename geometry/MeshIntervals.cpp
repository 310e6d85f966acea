#include "geometry/MeshIntervals.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace volref {

namespace {

// Shewchuk's error-free transformations (Adaptive Precision Floating-Point Arithmetic, 1997).
inline void two_sum(double a, double b, double& x, double& y) {
    x = a + b;
    const double bv = x - a, av = x - bv;
    y = (a - av) + (b - bv);
}
inline void two_diff(double a, double b, double& x, double& y) {
    x = a - b;
    const double bv = a - x, av = x + bv;
    y = (a - av) + (bv - b);
}
// (a1 + a0) - b as the exact expansion x2 + x1 + x0.
inline void two_one_diff(double a1, double a0, double b, double& x2, double& x1, double& x0) {
    double i;
    two_diff(a0, b, i, x0);
    two_sum(a1, i, x2, x1);
}

inline int sign_of(double v) { return (v > 0) - (v < 0); }

// The side of the projected ray (the origin, perturbed by (e, e^2)) of the directed edge p -> q:
// sign(cross(p - Q, q - Q)) = sign(cross(p, q) + e (p - q).y - e^2 (p - q).x). Reversing the edge
// negates it exactly. 0 only for an edge that projects to a point.
inline int edge_side(double px, double py, double qx, double qy) {
    const int s = exact_cross_sign(px, py, qx, qy);
    if (s != 0) return s;
    const double wy = py - qy;  // the sign of a floating-point difference is exact
    if (wy != 0) return sign_of(wy);
    return -sign_of(px - qx);
}

}  // namespace

int exact_cross_sign(double ax, double ay, double bx, double by) {
    const double p = ax * by, q = ay * bx;
    const double det = p - q;
    // Shewchuk's ccwerrboundA: beyond it the rounded difference has the right sign.
    const double bound = 3.3306690738754716e-16 * (std::abs(p) + std::abs(q));
    if (det > bound || -det > bound) return sign_of(det);
    if (!std::isfinite(det)) return sign_of(det);
    // Exactly: ax * by = p + ep, ay * bx = q + eq (fma gives the rounding errors), and
    // (p + ep) - (q + eq) as a non-overlapping expansion whose largest non-zero part has the sign.
    const double ep = std::fma(ax, by, -p), eq = std::fma(ay, bx, -q);
    double j, z, x0, x1, x2, x3;
    two_one_diff(p, ep, eq, j, z, x0);
    two_one_diff(j, z, q, x3, x2, x1);
    if (x3 != 0) return sign_of(x3);
    if (x2 != 0) return sign_of(x2);
    if (x1 != 0) return sign_of(x1);
    return sign_of(x0);
}

RayTriangleFrame::RayTriangleFrame(const Ray& ray) : origin_(ray.origin) {
    const glm::dvec3 d = ray.direction;
    kz_ = 0;
    if (std::abs(d.y) > std::abs(d[kz_])) kz_ = 1;
    if (std::abs(d.z) > std::abs(d[kz_])) kz_ = 2;
    kx_ = (kz_ + 1) % 3;
    ky_ = (kx_ + 1) % 3;
    if (d[kz_] < 0) std::swap(kx_, ky_);  // keeps the projected winding equal to the sign of dot(d, n)
    sx_ = d[kx_] / d[kz_];
    sy_ = d[ky_] / d[kz_];
    sz_ = 1.0 / d[kz_];
}

bool RayTriangleFrame::cross(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double& t,
                             int& winding) const {
    const glm::dvec3 A = a - origin_, B = b - origin_, C = c - origin_;
    const double ax = A[kx_] - sx_ * A[kz_], ay = A[ky_] - sy_ * A[kz_];
    const double bx = B[kx_] - sx_ * B[kz_], by = B[ky_] - sy_ * B[kz_];
    const double cx = C[kx_] - sx_ * C[kz_], cy = C[ky_] - sy_ * C[kz_];
    const int s_ab = edge_side(ax, ay, bx, by);
    if (s_ab == 0) return false;
    if (edge_side(bx, by, cx, cy) != s_ab) return false;
    if (edge_side(cx, cy, ax, ay) != s_ab) return false;
    // The projected triangle winds counter-clockwise around the ray (+1) exactly when dot(d, n) > 0.
    winding = -s_ab;
    const double e_ab = ax * by - ay * bx, e_bc = bx * cy - by * cx, e_ca = cx * ay - cy * ax;
    const double az = sz_ * A[kz_], bz = sz_ * B[kz_], cz = sz_ * C[kz_];
    const double den = e_ab + e_bc + e_ca;
    double tt = (e_bc * az + e_ca * bz + e_ab * cz) / den;
    if (!std::isfinite(tt)) tt = (az + bz + cz) / 3.0;
    t = std::clamp(tt, std::min({az, bz, cz}), std::max({az, bz, cz}));
    return true;
}

void crossings_to_intervals(std::vector<MeshCrossing>& crossings, const TriangleMesh& mesh, double scale,
                            std::vector<Interval>& out) {
    std::erase_if(crossings, [](const MeshCrossing& c) { return !(c.t >= 0.0); });
    if (crossings.empty()) return;
    std::sort(crossings.begin(), crossings.end(), [](const MeshCrossing& x, const MeshCrossing& y) {
        return x.t < y.t || (x.t == y.t && x.triangle < y.triangle);
    });
    auto share_vertex = [&](std::uint32_t p, std::uint32_t q) {
        const auto& a = mesh.triangles[p];
        const auto& b = mesh.triangles[q];
        for (const auto u : a)
            for (const auto v : b)
                if (u == v) return true;
        return false;
    };
    // Groups of crossings at one place (an edge or a vertex of the mesh): consecutive in t, within the
    // tolerance of the previous one, on a triangle sharing a vertex with one of the group's.
    struct Group {
        double t;
        int winding;
    };
    thread_local std::vector<Group> groups;
    groups.clear();
    int total = 0;
    for (std::size_t g = 0; g < crossings.size();) {
        std::size_t e = g + 1;
        int winding = crossings[g].winding;
        while (e < crossings.size()) {
            const double tol = kMeshMergeRelative * (std::abs(crossings[e].t) + scale);
            if (crossings[e].t - crossings[e - 1].t > tol) break;
            bool adjacent = false;
            for (std::size_t k = g; k < e && !adjacent; ++k) adjacent = share_vertex(crossings[k].triangle, crossings[e].triangle);
            if (!adjacent) break;
            winding += crossings[e].winding;
            ++e;
        }
        if (winding != 0) groups.push_back({crossings[g].t, winding});
        total += winding;
        g = e;
    }
    // The winding number is 0 beyond the last crossing, so it is -total at t = 0.
    int w = -total;
    double start = 0.0;
    for (const Group& g : groups) {
        const int before = w;
        w += g.winding;
        if (before <= 0 && w > 0) start = g.t;
        if (before > 0 && w <= 0 && g.t > start) out.push_back({start, g.t});
    }
}

void mesh_intervals_brute_force(const Ray& ray, const TriangleMesh& mesh, std::vector<Interval>& out) {
    const RayTriangleFrame frame(ray);
    std::vector<MeshCrossing> crossings;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        const auto& tri = mesh.triangles[i];
        double t;
        int winding;
        if (frame.cross(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]], t, winding))
            crossings.push_back({t, winding, std::uint32_t(i)});
    }
    crossings_to_intervals(crossings, mesh, mesh_scale(mesh), out);
}

double mesh_scale(const TriangleMesh& mesh) {
    if (mesh.vertices.empty()) return 0.0;
    glm::dvec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
    for (const auto& p : mesh.vertices) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], p[a]);
            hi[a] = std::max(hi[a], p[a]);
        }
    }
    const glm::dvec3 e = hi - lo;
    return std::max({e.x, e.y, e.z});
}

}  // namespace volref
