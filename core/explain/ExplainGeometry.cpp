// explain coords / intersect: the shell conventions of docs/shells.md (geometry/ShellCoordinates.h)
// and a ray's intervals in a box (geometry/BoxIntersection.h) or a shell (geometry/ShellIntersection.h),
// with every slab or root those functions compute.
#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "geometry/BoxIntersection.h"
#include "geometry/ShellCoordinates.h"
#include "geometry/ShellIntersection.h"

namespace volref::explain {

namespace {

std::vector<double> v3(const glm::dvec3& c) { return {c.x, c.y, c.z}; }

void check_finite(const glm::dvec3& v, const char* what) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(v[a])) throw Error(std::string(what) + ": must be finite");
}

void ray_section(Explanation& e, const Ray& ray) {
    check_finite(ray.origin, "--origin");
    check_finite(ray.direction, "--direction");
    Section& s = e.section("ray x(t) = origin + t direction");
    add(s, "origin", v3(ray.origin));
    add(s, "direction", v3(ray.direction), "unit length");
}

void intervals_section(Explanation& e, const std::vector<Interval>& iv) {
    Section& s = e.section("intervals (t >= 0)");
    s.columns = {"t0", "t1", "length"};
    for (const Interval& i : iv) s.rows.push_back({i.t0, i.t1, i.length()});
    if (iv.empty()) s.notes.push_back("none: the ray misses");
}

template <class Intersector>
void shell_roots(Explanation& e, const Ray& ray, const Intersector& shell) {
    std::vector<Interval> out;
    std::vector<ShellRoot> roots;
    shell.intervals(ray, out, &roots);
    Section& s = e.section("roots and extrema, in the order found (only finite t > 0 split the ray)");
    for (const ShellRoot& r : roots) {
        const glm::dvec3 p = ray.at(r.t);
        add(s, r.surface, {r.t, p.x, p.y, p.z}, r.t > 0.0 && std::isfinite(r.t) ? "(t, x, y, z): splits" : "(t, x, y, z): not used");
    }
    if (roots.empty()) s.notes.push_back("none");
    s.notes.push_back("each piece between consecutive split points (from t = 0) is inside iff its midpoint is");
    intervals_section(e, out);
}

}  // namespace

Explanation coords(CoordinateSystem given, const glm::dvec3& v, const glm::dvec3& center) {
    check_finite(v, "the point");
    check_finite(center, "--center");
    Explanation e;
    e.topic = "coords";
    Section& in = e.section("given");
    add(in, "center", v3(center));
    glm::dvec3 world;
    switch (given) {
        case CoordinateSystem::Cartesian:
            add(in, "(x, y, z)", v3(v), "Cartesian");
            world = v;
            break;
        case CoordinateSystem::Cylindrical: {
            if (v.x < 0.0) throw Error("--cylindrical: r must be >= 0");
            add(in, "(r, theta, h)", v3(v), "cylindrical, theta in degrees");
            world = from_cylindrical({v.x, v.y, v.z}, center);
            break;
        }
        case CoordinateSystem::Spherical: {
            if (v.x < 0.0) throw Error("--spherical: R must be >= 0");
            if (v.z < -90.0 || v.z > 90.0) throw Error("--spherical: lat must be in [-90, 90]");
            add(in, "(R, lon, lat)", v3(v), "spherical, degrees");
            SphericalCoordinates s;
            s.radius = v.x;
            s.lon = v.y;
            s.lat = v.z;
            world = from_spherical(s, center);
            break;
        }
    }
    Section& c = e.section("Cartesian");
    add(c, "(x, y, z)", v3(world), given == CoordinateSystem::Cartesian ? "" : "from the given coordinates");
    add(c, "p - center", v3(world - center));
    const CylindricalCoordinates cy = to_cylindrical(world, center);
    Section& s1 = e.section("cylindrical (axis y): p - center = (r cos theta, h, -r sin theta)");
    add(s1, "r", cy.r, "|(x, z)| (hypot)");
    add(s1, "theta", cy.theta, "atan2(-z, x) in degrees, [0, 360); 0 on the axis");
    add(s1, "h", cy.h, "y");
    const glm::dvec3 back1 = from_cylindrical(cy, center);
    add(s1, "back to Cartesian", v3(back1));
    add(s1, "round-trip error", v3(back1 - world));
    const SphericalCoordinates sp = to_spherical(world, center);
    Section& s2 = e.section("spherical: p - center = (R cos lat cos lon, R sin lat, -R cos lat sin lon)");
    add(s2, "R", sp.radius, "|p - center|");
    add(s2, "lon", sp.lon, "atan2(-z, x) in degrees, [0, 360); 0 at the poles");
    add(s2, "lat", sp.lat, "atan2(y, |(x, z)|) in degrees, [-90, 90]; 0 at the centre");
    const glm::dvec3 back2 = from_spherical(sp, center);
    add(s2, "back to Cartesian", v3(back2));
    add(s2, "round-trip error", v3(back2 - world));
    return e;
}

Explanation intersect_box(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi) {
    check_finite(lo, "--box");
    check_finite(hi, "--box");
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) throw Error("--box: min must not exceed max on any axis");
    Explanation e;
    e.topic = "intersect";
    ray_section(e, ray);
    Section& b = e.section("box");
    add(b, "min", v3(lo));
    add(b, "max", v3(hi));
    Section& s = e.section("slabs (geometry/BoxIntersection.h): t where lo <= o + t d <= hi per axis");
    s.columns = {"axis", "t_near", "t_far"};
    double t0 = -INFINITY, t1 = INFINITY;
    bool empty = false;
    for (int a = 0; a < 3; ++a) {
        double ta, tb;
        if (!intersect_slab(ray.origin[a], ray.direction[a], lo[a], hi[a], ta, tb)) {
            s.notes.push_back(std::string("axis ") + "xyz"[a] + ": direction 0 and origin outside the slab: no interval");
            empty = true;
            continue;
        }
        if (ray.direction[a] == 0.0)
            s.notes.push_back(std::string("axis ") + "xyz"[a] + ": direction 0, origin inside the slab: every t");
        s.rows.push_back({double(a), ta, tb});
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    Section& r = e.section("line");
    if (!empty) {
        add(r, "t_enter", t0, "max of t_near");
        add(r, "t_exit", t1, "min of t_far");
    }
    Interval iv;
    std::vector<Interval> out;
    if (intersect_box(ray, lo, hi, iv)) {
        iv.t0 = std::max(iv.t0, 0.0);  // t >= 0, as BoundingGeometry keeps
        out.push_back(iv);
        normalize_intervals(out);
    }
    r.notes.push_back("the ray is the part t >= 0; an interval of length 0 (an edge or corner) is dropped");
    intervals_section(e, out);
    return e;
}

Explanation intersect_cylinder(const Ray& ray, const CylindricalShell& shell) {
    const CylindricalShellIntersector x(shell);  // validates (throws naming the parameter)
    Explanation e;
    e.topic = "intersect";
    ray_section(e, ray);
    Section& s = e.section("cylindrical shell (axis y through the centre)");
    add(s, "center", v3(shell.center));
    add(s, "radius", {shell.r0, shell.r1});
    add(s, "angle", {shell.a0, shell.a1}, shell.full_turn() ? "a full turn: no angle limit" : "degrees");
    add(s, "height", {shell.h0, shell.h1}, "y - center.y");
    shell_roots(e, ray, x);
    return e;
}

Explanation intersect_sphere(const Ray& ray, const SphericalShell& shell) {
    const SphericalShellIntersector x(shell);
    Explanation e;
    e.topic = "intersect";
    ray_section(e, ray);
    Section& s = e.section("spherical shell");
    add(s, "center", v3(shell.center));
    add(s, "radius", {shell.r0, shell.r1});
    add(s, "longitude", {shell.lon0, shell.lon1}, shell.full_turn() ? "a full turn: no longitude limit" : "degrees");
    add(s, "latitude", {shell.lat0, shell.lat1}, "degrees");
    shell_roots(e, ray, x);
    return e;
}

}  // namespace volref::explain
