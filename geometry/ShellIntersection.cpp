#include "geometry/ShellIntersection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Angles.h"
#include "core/Error.h"

namespace volref {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The split points of a ray: roots of the bounding surfaces (and extrema), t > 0 only.
// With `log` set, every root and extremum is also logged with `surface` (also those not kept).
struct Splits {
    std::array<double, 24> t{};
    int n = 0;
    std::vector<ShellRoot>* log = nullptr;
    const char* surface = "";
    void add(double v) {
        if (log) log->push_back({surface, v});
        if (v > 0.0 && std::isfinite(v) && n < int(t.size())) t[std::size_t(n++)] = v;
    }
    void name(const char* s) { surface = s; }
};

}  // namespace

namespace {

double normalize_degrees(double a) {
    double r = std::fmod(a, 360.0);
    if (r < 0) r += 360.0;
    if (r >= 360.0) r -= 360.0;
    return r;
}

// Whether azimuth `theta` (in [0, 360)) lies in [a0, a0 + span] modulo 360 (a0 in [0, 360)).
bool in_range(double theta, double a0, double span) {
    double d = theta - a0;
    if (d < 0) d += 360.0;
    return d <= span;
}

// The normal of the plane through the y axis holding the half-plane of azimuth a (degrees):
// the half-plane's direction (cos a, 0, -sin a) x (0, 1, 0) = (sin a, 0, cos a).
glm::dvec3 azimuth_plane_normal(double a) {
    double c, s;
    cos_sin_degrees(a, c, s);
    return {s, 0.0, c};
}

void plane_root(const glm::dvec3& n, double k, const glm::dvec3& o, const glm::dvec3& d, Splits& splits) {
    const double nd = glm::dot(n, d);
    if (nd != 0.0) splits.add((k - glm::dot(n, o)) / nd);
}

// |o + t d| = r in the xz-plane (a cylinder about the y axis), plus the closest approach to the axis.
void cylinder_roots(const glm::dvec3& o, const glm::dvec3& d, double r, Splits& splits) {
    const double a = d.x * d.x + d.z * d.z;
    if (a == 0.0) return;  // parallel to the axis
    const double bh = o.x * d.x + o.z * d.z;  // b / 2
    const double tstar = -bh / a;
    splits.add(tstar);
    const double l = std::hypot(o.x + tstar * d.x, o.z + tstar * d.z);  // distance of the line from the axis
    const double disc = a * ((r - l) * (r + l));
    if (!(disc >= 0.0)) return;
    const double rho = std::hypot(o.x, o.z);
    const double c = (rho - r) * (rho + r);
    const double q = -(bh + std::copysign(std::sqrt(disc), bh));
    if (q == 0.0) return;  // double root at t = 0 = tstar
    splits.add(q / a);
    splits.add(c / q);
}

// |o + t d| = r, plus the closest approach to the centre.
void sphere_roots(const glm::dvec3& o, const glm::dvec3& d, double r, Splits& splits) {
    const double a = glm::dot(d, d);
    if (a == 0.0) return;
    const double bh = glm::dot(o, d);
    const double tstar = -bh / a;
    splits.add(tstar);
    const double l = glm::length(o + tstar * d);
    const double disc = a * ((r - l) * (r + l));
    if (!(disc >= 0.0)) return;
    const double rho = glm::length(o);
    const double c = (rho - r) * (rho + r);
    const double q = -(bh + std::copysign(std::sqrt(disc), bh));
    if (q == 0.0) return;
    splits.add(q / a);
    splits.add(c / q);
}

// The cone of latitude `lat` (degrees, not 0 or +-90) through the centre, both nappes:
// y^2 cos^2(lat) - (x^2 + z^2) sin^2(lat) = 0; plus the extremum of that quadratic in t.
void cone_roots(const glm::dvec3& o, const glm::dvec3& d, double lat, Splits& splits) {
    double c, s;
    cos_sin_degrees(lat, c, s);
    const double c2 = c * c, s2 = s * s;
    const double A = d.y * d.y * c2 - (d.x * d.x + d.z * d.z) * s2;
    const double B = 2.0 * (o.y * d.y * c2 - (o.x * d.x + o.z * d.z) * s2);
    const double C = o.y * o.y * c2 - (o.x * o.x + o.z * o.z) * s2;
    double roots[2];
    const int n = solve_quadratic(A, B, C, roots);
    for (int i = 0; i < n; ++i) splits.add(roots[i]);
    if (A != 0.0) splits.add(-B / (2.0 * A));
}

// The pieces between consecutive split points whose midpoints are inside, merged, appended to `out`.
template <class Inside>
void collect(Splits& splits, const glm::dvec3& o, const glm::dvec3& d, const Inside& inside, std::vector<Interval>& out) {
    std::sort(splits.t.begin(), splits.t.begin() + splits.n);
    const std::size_t first = out.size();
    double prev = 0.0;
    for (int i = 0; i < splits.n; ++i) {
        const double t = splits.t[std::size_t(i)];
        if (!(t > prev)) continue;
        const double mid = prev + 0.5 * (t - prev);
        if (inside(o + mid * d)) {
            if (out.size() > first && out.back().t1 == prev)
                out.back().t1 = t;
            else
                out.push_back({prev, t});
        }
        prev = t;
    }
}

void check(bool ok, const std::string& what, const std::string& message) {
    if (!ok) throw Error(what + ": " + message);
}

bool finite(double v) { return std::isfinite(v); }

}  // namespace

double azimuth_degrees(double x, double z) {
    double a = std::atan2(-z, x) / kDegree;
    if (a < 0) a += 360.0;
    if (a >= 360.0) a -= 360.0;
    return a;
}

int solve_quadratic(double a, double b, double c, double roots[2]) {
    if (a == 0.0) {
        if (b == 0.0) return 0;
        roots[0] = -c / b;
        return 1;
    }
    const double disc = b * b - 4.0 * a * c;
    if (!(disc >= 0.0)) return 0;
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    if (q == 0.0) {  // b = 0 and disc = 0, so c = 0
        roots[0] = 0.0;
        return 1;
    }
    roots[0] = q / a;
    roots[1] = c / q;
    return roots[0] == roots[1] ? 1 : 2;
}

void validate_shell(const CylindricalShell& s, const std::string& what) {
    check(finite(s.center.x) && finite(s.center.y) && finite(s.center.z), what, "the centre must be finite");
    check(finite(s.r0) && finite(s.r1) && s.r0 >= 0 && s.r0 < s.r1, what, "the radius range [r0, r1] needs 0 <= r0 < r1");
    check(finite(s.a0) && finite(s.a1) && s.a0 < s.a1, what, "the angle range [a0, a1] needs a0 < a1");
    check(finite(s.h0) && finite(s.h1) && s.h0 < s.h1, what, "the height range [h0, h1] needs h0 < h1");
}

void validate_shell(const SphericalShell& s, const std::string& what) {
    check(finite(s.center.x) && finite(s.center.y) && finite(s.center.z), what, "the centre must be finite");
    check(finite(s.r0) && finite(s.r1) && s.r0 >= 0 && s.r0 < s.r1, what, "the radius range [r0, r1] needs 0 <= r0 < r1");
    check(finite(s.lon0) && finite(s.lon1) && s.lon0 < s.lon1, what,
          "the longitude range [lon0, lon1] needs lon0 < lon1");
    check(finite(s.lat0) && finite(s.lat1) && -90 <= s.lat0 && s.lat0 < s.lat1 && s.lat1 <= 90, what,
          "the latitude range [lat0, lat1] needs -90 <= lat0 < lat1 <= 90");
}

namespace {

// Azimuths where x = cos or z = -sin is extreme over [a0, a1]: the ends and the multiples of 90 inside.
std::vector<double> extreme_azimuths(double a0, double a1) {
    if (a1 - a0 >= 360.0) return {0.0, 90.0, 180.0, 270.0};
    std::vector<double> v{a0, a1};
    for (double k = std::ceil(a0 / 90.0); k * 90.0 <= a1; k += 1.0) v.push_back(k * 90.0);
    return v;
}

}  // namespace

void shell_bounds(const CylindricalShell& s, glm::dvec3& lo, glm::dvec3& hi) {
    lo = glm::dvec3(INFINITY);
    hi = glm::dvec3(-INFINITY);
    for (const double a : extreme_azimuths(s.a0, s.a1)) {
        double c, sn;
        cos_sin_degrees(a, c, sn);
        for (const double r : {s.r0, s.r1}) {
            for (const double h : {s.h0, s.h1}) {
                const glm::dvec3 p = s.center + glm::dvec3(r * c, h, -r * sn);
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
        }
    }
}

void shell_bounds(const SphericalShell& s, glm::dvec3& lo, glm::dvec3& hi) {
    lo = glm::dvec3(INFINITY);
    hi = glm::dvec3(-INFINITY);
    std::vector<double> lats{s.lat0, s.lat1};
    if (s.lat0 < 0 && s.lat1 > 0) lats.push_back(0.0);
    for (const double lon : extreme_azimuths(s.lon0, s.lon1)) {
        double cl, sl;
        cos_sin_degrees(lon, cl, sl);
        for (const double lat : lats) {
            double cb, sb;
            cos_sin_degrees(lat, cb, sb);
            for (const double r : {s.r0, s.r1}) {
                const glm::dvec3 p = s.center + glm::dvec3(r * cb * cl, r * sb, -r * cb * sl);
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
        }
    }
}

CylindricalShellIntersector::CylindricalShellIntersector(const CylindricalShell& shell) : shell_(shell) {
    validate_shell(shell_);
    full_ = shell_.full_turn();
    a0_ = normalize_degrees(shell_.a0);
    span_ = shell_.a1 - shell_.a0;
    n0_ = azimuth_plane_normal(shell_.a0);
    n1_ = azimuth_plane_normal(shell_.a1);
}

bool CylindricalShellIntersector::contains(const glm::dvec3& p) const { return contains_relative(p - shell_.center); }

bool CylindricalShellIntersector::contains_relative(const glm::dvec3& q) const {
    if (q.y < shell_.h0 || q.y > shell_.h1) return false;
    const double r = std::hypot(q.x, q.z);
    if (r < shell_.r0 || r > shell_.r1) return false;
    if (full_ || r == 0.0) return true;
    return in_range(azimuth_degrees(q.x, q.z), a0_, span_);
}

void CylindricalShellIntersector::intervals(const Ray& ray, std::vector<Interval>& out) const {
    intervals(ray, out, nullptr);
}

void CylindricalShellIntersector::intervals(const Ray& ray, std::vector<Interval>& out, std::vector<ShellRoot>* roots) const {
    const glm::dvec3 o = ray.origin - shell_.center, d = ray.direction;
    Splits splits;
    splits.log = roots;
    splits.name("cylinder r1 (extremum, root, root)");
    cylinder_roots(o, d, shell_.r1, splits);
    splits.name("cylinder r0 (extremum, root, root)");
    if (shell_.r0 > 0) cylinder_roots(o, d, shell_.r0, splits);
    if (d.y != 0.0) {
        splits.name("plane h0");
        splits.add((shell_.h0 - o.y) / d.y);
        splits.name("plane h1");
        splits.add((shell_.h1 - o.y) / d.y);
    }
    if (!full_) {
        splits.name("half-plane a0");
        plane_root(n0_, 0.0, o, d, splits);
        splits.name("half-plane a1");
        plane_root(n1_, 0.0, o, d, splits);
    }
    collect(splits, o, d, [this](const glm::dvec3& q) { return contains_relative(q); }, out);
}

SphericalShellIntersector::SphericalShellIntersector(const SphericalShell& shell) : shell_(shell) {
    validate_shell(shell_);
    full_ = shell_.full_turn();
    lon0_ = normalize_degrees(shell_.lon0);
    span_ = shell_.lon1 - shell_.lon0;
    n0_ = azimuth_plane_normal(shell_.lon0);
    n1_ = azimuth_plane_normal(shell_.lon1);
}

bool SphericalShellIntersector::contains(const glm::dvec3& p) const { return contains_relative(p - shell_.center); }

bool SphericalShellIntersector::contains_relative(const glm::dvec3& q) const {
    const double R = glm::length(q);
    if (R < shell_.r0 || R > shell_.r1) return false;
    if (R == 0.0) return true;  // the centre, with r0 = 0
    const double rho = std::hypot(q.x, q.z);
    const double lat = std::atan2(q.y, rho) / kDegree;
    if (lat < shell_.lat0 || lat > shell_.lat1) return false;
    if (full_ || rho == 0.0) return true;
    return in_range(azimuth_degrees(q.x, q.z), lon0_, span_);
}

void SphericalShellIntersector::intervals(const Ray& ray, std::vector<Interval>& out) const {
    intervals(ray, out, nullptr);
}

void SphericalShellIntersector::intervals(const Ray& ray, std::vector<Interval>& out, std::vector<ShellRoot>* roots) const {
    const glm::dvec3 o = ray.origin - shell_.center, d = ray.direction;
    Splits splits;
    splits.log = roots;
    splits.name("sphere r1 (extremum, root, root)");
    sphere_roots(o, d, shell_.r1, splits);
    splits.name("sphere r0 (extremum, root, root)");
    if (shell_.r0 > 0) sphere_roots(o, d, shell_.r0, splits);
    if (!full_) {
        splits.name("half-plane lon0");
        plane_root(n0_, 0.0, o, d, splits);
        splits.name("half-plane lon1");
        plane_root(n1_, 0.0, o, d, splits);
    }
    for (const double lat : {shell_.lat0, shell_.lat1}) {
        splits.name(lat == shell_.lat0 ? "latitude lat0 (roots, extremum)" : "latitude lat1 (roots, extremum)");
        if (lat <= -90.0 || lat >= 90.0) continue;
        if (lat == 0.0)
            plane_root({0.0, 1.0, 0.0}, 0.0, o, d, splits);
        else
            cone_roots(o, d, lat, splits);
    }
    collect(splits, o, d, [this](const glm::dvec3& q) { return contains_relative(q); }, out);
}

}  // namespace volref
