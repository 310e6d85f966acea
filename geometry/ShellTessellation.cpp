#include "geometry/ShellTessellation.h"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "core/Angles.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/Conventions.h"
#include "geometry/ShellIntersection.h"

namespace volref {

namespace {

// Vertices by key (so that faces sharing an edge share its vertices), triangles oriented by the
// outward direction their face is known to have.
class MeshBuilder {
public:
    template <class Position>
    std::uint32_t vertex(const std::array<int, 3>& key, const Position& position) {
        const auto it = ids_.find(key);
        if (it != ids_.end()) return it->second;
        const std::uint32_t id = std::uint32_t(mesh_.vertices.size());
        mesh_.vertices.push_back(position());
        ids_.emplace(key, id);
        return id;
    }
    void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, const glm::dvec3& outward) {
        if (a == b || b == c || c == a) return;  // collapsed at a pole, the axis or the centre
        const glm::dvec3& va = mesh_.vertices[a];
        const glm::dvec3 n = glm::cross(mesh_.vertices[b] - va, mesh_.vertices[c] - va);
        if (glm::dot(n, outward) < 0) std::swap(b, c);
        mesh_.triangles.push_back({a, b, c});
    }
    // The quad a b c d (in order around it), as triangles a b c and a c d.
    void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, const glm::dvec3& outward) {
        triangle(a, b, c, outward);
        triangle(a, c, d, outward);
    }
    glm::dvec3 centroid(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) const {
        return 0.25 * (mesh_.vertices[a] + mesh_.vertices[b] + mesh_.vertices[c] + mesh_.vertices[d]);
    }
    TriangleMesh finish(const char* what) {
        check_closed(mesh_, what);  // a failure here is a bug in this file
        return std::move(mesh_);
    }

private:
    TriangleMesh mesh_;
    std::map<std::array<int, 3>, std::uint32_t> ids_;
};

void check_n(int n) {
    if (n < 3) throw Error("tessellate: needs at least 3 segments per full turn, not " + std::to_string(n));
}

// The mesh's memory (conventions::kMeshBytesPerTriangle per triangle, at most `triangles`),
// checked against --max-memory before it is built.
void check_mesh_memory(double triangles, int n) {
    const double bytes = triangles * double(conventions::kMeshBytesPerTriangle);
    check_memory(bytes >= 0x1p62 ? std::size_t(1) << 62 : std::size_t(bytes),
                 "volume.bounds.tessellate: " + std::to_string(n) + " segments per turn (a mesh of up to " +
                     std::to_string(std::llround(std::min(triangles, 0x1p62))) + " triangles)");
}

// The unit vector of azimuth a (degrees) in the xz-plane, and d/da of it (per radian).
glm::dvec3 radial(double a) {
    double c, s;
    cos_sin_degrees(a, c, s);
    return {c, 0.0, -s};
}
glm::dvec3 tangential(double a) {
    double c, s;
    cos_sin_degrees(a, c, s);
    return {-s, 0.0, -c};
}

}  // namespace

int tessellation_segments(double span_degrees, int n) {
    return std::max(1, int(std::ceil(double(n) * span_degrees / 360.0 - 1e-9)));
}

double tessellation_error(const CylindricalShell& shell, int n) {
    return shell.r1 * (1.0 - std::cos(std::numbers::pi / n));
}

double tessellation_error(const SphericalShell& shell, int n) {
    const double s = std::sin(std::numbers::pi / n);
    return shell.r1 * s * s;
}

TriangleMesh tessellate(const CylindricalShell& shell, int n) {
    validate_shell(shell);
    check_n(n);
    const bool full = shell.full_turn();
    const double span = full ? 360.0 : shell.a1 - shell.a0;
    const int m = full ? n : tessellation_segments(span, n);
    check_mesh_memory(8.0 * (double(m) + 1.0) + 4.0, n);  // 4 quads per segment, 2 end walls
    auto angle = [&](int k) { return k == m && !full ? shell.a1 : shell.a0 + span * k / m; };
    MeshBuilder b;
    // ring 0 = inner (the axis when r0 = 0), 1 = outer; level 0 = h0, 1 = h1.
    auto v = [&](int ring, int k, int level) {
        if (ring == 0 && shell.r0 == 0) k = 0;
        if (full && k == m) k = 0;
        return b.vertex({ring, k, level}, [&] {
            const double r = ring == 0 ? shell.r0 : shell.r1;
            return shell.center + r * radial(angle(k)) + glm::dvec3(0.0, level == 0 ? shell.h0 : shell.h1, 0.0);
        });
    };
    const glm::dvec3 up(0.0, 1.0, 0.0);
    for (int k = 0; k < m; ++k) {
        const glm::dvec3 out = radial(angle(k) + 0.5 * span / m);
        b.quad(v(1, k, 0), v(1, k + 1, 0), v(1, k + 1, 1), v(1, k, 1), out);
        if (shell.r0 > 0) b.quad(v(0, k, 0), v(0, k + 1, 0), v(0, k + 1, 1), v(0, k, 1), -out);
        b.quad(v(0, k, 0), v(1, k, 0), v(1, k + 1, 0), v(0, k + 1, 0), -up);
        b.quad(v(0, k, 1), v(1, k, 1), v(1, k + 1, 1), v(0, k + 1, 1), up);
    }
    if (!full) {
        b.quad(v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1), -tangential(shell.a0));
        b.quad(v(0, m, 0), v(1, m, 0), v(1, m, 1), v(0, m, 1), tangential(shell.a1));
    }
    return b.finish("tessellated cylindrical shell");
}

TriangleMesh tessellate(const SphericalShell& shell, int n) {
    validate_shell(shell);
    check_n(n);
    const bool full = shell.full_turn();
    const double span = full ? 360.0 : shell.lon1 - shell.lon0;
    const int m = full ? n : tessellation_segments(span, n);
    const int p = tessellation_segments(shell.lat1 - shell.lat0, n);
    check_mesh_memory(4.0 * (double(m) + 2.0) * (double(p) + 2.0) + 4.0 * (double(m) + double(p) + 4.0), n);
    auto lon = [&](int k) { return k == m && !full ? shell.lon1 : shell.lon0 + span * k / m; };
    auto lat = [&](int j) { return j == p ? shell.lat1 : shell.lat0 + (shell.lat1 - shell.lat0) * j / p; };
    MeshBuilder b;
    // ring 0 = inner (the centre when r0 = 0), 1 = outer; row j = latitude, column k = longitude.
    auto v = [&](int ring, int j, int k) {
        std::array<int, 3> key{ring, j, k};
        if (full && k == m) key[2] = 0;
        if (std::abs(lat(j)) == 90.0) key[2] = -1;     // a pole
        if (ring == 0 && shell.r0 == 0) key = {0, -1, -1};  // the centre
        return b.vertex(key, [&] {
            const double r = ring == 0 ? shell.r0 : shell.r1;
            double cb, sb;
            cos_sin_degrees(lat(j), cb, sb);
            return shell.center + r * (cb * radial(lon(k)) + glm::dvec3(0.0, sb, 0.0));
        });
    };
    for (int j = 0; j < p; ++j) {
        for (int k = 0; k < m; ++k) {
            const std::uint32_t o00 = v(1, j, k), o01 = v(1, j, k + 1), o11 = v(1, j + 1, k + 1), o10 = v(1, j + 1, k);
            b.quad(o00, o01, o11, o10, b.centroid(o00, o01, o11, o10) - shell.center);
            if (shell.r0 > 0) {
                const std::uint32_t i00 = v(0, j, k), i01 = v(0, j, k + 1), i11 = v(0, j + 1, k + 1), i10 = v(0, j + 1, k);
                b.quad(i00, i01, i11, i10, shell.center - b.centroid(i00, i01, i11, i10));
            }
        }
    }
    if (!full) {
        for (int j = 0; j < p; ++j) {
            b.quad(v(0, j, 0), v(1, j, 0), v(1, j + 1, 0), v(0, j + 1, 0), -tangential(shell.lon0));
            b.quad(v(0, j, m), v(1, j, m), v(1, j + 1, m), v(0, j + 1, m), tangential(shell.lon1));
        }
    }
    // d/dlat of the unit vector at (lat, lon).
    auto northward = [](double lat_deg, double lon_deg) {
        double cb, sb;
        cos_sin_degrees(lat_deg, cb, sb);
        return -sb * radial(lon_deg) + glm::dvec3(0.0, cb, 0.0);
    };
    for (int k = 0; k < m; ++k) {
        const double mid = lon(k) + 0.5 * span / m;
        if (shell.lat0 > -90.0)
            b.quad(v(0, 0, k), v(1, 0, k), v(1, 0, k + 1), v(0, 0, k + 1), -northward(shell.lat0, mid));
        if (shell.lat1 < 90.0)
            b.quad(v(0, p, k), v(1, p, k), v(1, p, k + 1), v(0, p, k + 1), northward(shell.lat1, mid));
    }
    return b.finish("tessellated spherical shell");
}

}  // namespace volref
