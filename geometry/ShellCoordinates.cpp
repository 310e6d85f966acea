#include "geometry/ShellCoordinates.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "core/Error.h"

namespace volref {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadiansPerDegree = kPi / 180.0;
constexpr double kDegreesPerRadian = 180.0 / kPi;

// The shortest text that reads back as x (for messages).
std::string num(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

std::string range_text(double lo, double hi) {
    std::string s("[");  // appended: GCC 12 warns falsely on "[" + std::string
    s.append(num(lo)).append(", ").append(num(hi)).append("]");
    return s;
}

bool finite(double x) { return std::isfinite(x); }

}  // namespace

double wrap_degrees(double degrees) {
    double d = std::fmod(degrees, 360.0);  // exact
    if (d < 0.0) d += 360.0;
    if (d >= 360.0) d = 0.0;  // -tiny + 360 rounds to 360
    return d + 0.0;           // -0 -> +0
}

double atan2_degrees(double y, double x) {
    if (y == 0.0) return x < 0.0 ? 180.0 : 0.0;  // also x = y = 0: 0 by convention
    if (x == 0.0) return y > 0.0 ? 90.0 : 270.0;
    double a = std::atan2(y, x) * kDegreesPerRadian;
    if (a < 0.0) a += 360.0;
    if (a >= 360.0) a = 0.0;
    return a;
}

void sincos_degrees(double degrees, double& s, double& c) {
    if (!std::isfinite(degrees)) {
        s = c = std::numeric_limits<double>::quiet_NaN();
        return;
    }
    const double d = wrap_degrees(degrees);
    int q = std::min(3, int(d / 90.0));
    double rem = d - 90.0 * double(q);  // exact (Sterbenz) for q >= 1, d itself for q = 0
    if (rem < 0.0) {
        --q;
        rem += 90.0;
    }
    const double x = rem * kRadiansPerDegree;
    const double s0 = rem == 0.0 ? 0.0 : std::sin(x);
    const double c0 = rem == 0.0 ? 1.0 : std::cos(x);
    switch (q) {
        case 0: s = s0; c = c0; break;
        case 1: s = c0; c = -s0; break;
        case 2: s = -s0; c = -c0; break;
        default: s = -c0; c = s0; break;
    }
    s += 0.0;
    c += 0.0;
}

CylindricalCoordinates to_cylindrical(const glm::dvec3& world, const glm::dvec3& center) {
    const glm::dvec3 d = world - center;
    CylindricalCoordinates c;
    c.r = std::hypot(d.x, d.z);
    c.theta = atan2_degrees(-d.z, d.x);
    c.h = d.y;
    return c;
}

glm::dvec3 from_cylindrical(const CylindricalCoordinates& c, const glm::dvec3& center) {
    double s, co;
    sincos_degrees(c.theta, s, co);
    return center + glm::dvec3(c.r * co, c.h, -c.r * s);
}

SphericalCoordinates to_spherical(const glm::dvec3& world, const glm::dvec3& center) {
    const glm::dvec3 d = world - center;
    SphericalCoordinates c;
    const double rho = std::hypot(d.x, d.z);
    c.radius = std::hypot(rho, d.y);
    c.lon = atan2_degrees(-d.z, d.x);
    if (rho == 0.0) c.lat = d.y > 0.0 ? 90.0 : (d.y < 0.0 ? -90.0 : 0.0);
    else c.lat = std::atan2(d.y, rho) * kDegreesPerRadian;
    return c;
}

glm::dvec3 from_spherical(const SphericalCoordinates& c, const glm::dvec3& center) {
    double slon, clon, slat, clat;
    sincos_degrees(c.lon, slon, clon);
    sincos_degrees(c.lat, slat, clat);
    const double rho = c.radius * clat;
    return center + glm::dvec3(rho * clon, c.radius * slat, -rho * slon);
}

// ---- validation ----

void check_shell(const CylindricalShell& s) {
    const std::string what = "cylindrical shell: ";
    if (!(finite(s.center.x) && finite(s.center.y) && finite(s.center.z)))
        throw Error(what + "center must be finite");
    if (!(finite(s.r0) && finite(s.r1) && 0.0 <= s.r0 && s.r0 < s.r1))
        throw Error(what + "radius must be [r0, r1] with 0 <= r0 < r1, got " + range_text(s.r0, s.r1));
    if (!(finite(s.a0) && finite(s.a1) && s.a0 < s.a1 && s.a1 - s.a0 <= 360.0))
        throw Error(what + "angle must be [a0, a1] with a0 < a1 <= a0 + 360 (degrees), got " + range_text(s.a0, s.a1));
    if (!(finite(s.h0) && finite(s.h1) && s.h0 < s.h1))
        throw Error(what + "height must be [h0, h1] with h0 < h1, got " + range_text(s.h0, s.h1));
}

void check_shell(const SphericalShell& s) {
    const std::string what = "spherical shell: ";
    if (!(finite(s.center.x) && finite(s.center.y) && finite(s.center.z)))
        throw Error(what + "center must be finite");
    if (!(finite(s.r0) && finite(s.r1) && 0.0 <= s.r0 && s.r0 < s.r1))
        throw Error(what + "radius must be [r0, r1] with 0 <= r0 < r1, got " + range_text(s.r0, s.r1));
    if (!(finite(s.lon0) && finite(s.lon1) && s.lon0 < s.lon1 && s.lon1 - s.lon0 <= 360.0))
        throw Error(what + "longitude must be [l0, l1] with l0 < l1 <= l0 + 360 (degrees), got " +
                    range_text(s.lon0, s.lon1));
    if (!(finite(s.lat0) && finite(s.lat1) && -90.0 <= s.lat0 && s.lat0 < s.lat1 && s.lat1 <= 90.0))
        throw Error(what + "latitude must be [b0, b1] with -90 <= b0 < b1 <= 90 (degrees), got " +
                    range_text(s.lat0, s.lat1));
    std::array<int, 3> seen{0, 0, 0};
    for (int a : s.axes) {
        if (a < 0 || a > 2 || seen[std::size_t(a)]++)
            throw Error(what + "axes must be a permutation of longitude (0), latitude (1), radius (2), got (" +
                        std::to_string(s.axes[0]) + ", " + std::to_string(s.axes[1]) + ", " +
                        std::to_string(s.axes[2]) + ")");
    }
}

// ---- bounding boxes ----

namespace {

// The angles in [lo, hi] where a coordinate of the circle can be extreme: the ends and the
// multiples of 90 in between.
std::vector<double> critical_angles(double lo, double hi) {
    std::vector<double> a{lo, hi};
    for (double m = std::ceil(lo / 90.0) * 90.0; m <= hi; m += 90.0) a.push_back(m);
    return a;
}

void grow(std::array<glm::dvec3, 2>& box, const glm::dvec3& p) {
    box[0] = glm::min(box[0], p);
    box[1] = glm::max(box[1], p);
}

}  // namespace

std::array<glm::dvec3, 2> bounding_box(const CylindricalShell& s) {
    std::array<glm::dvec3, 2> box{glm::dvec3(std::numeric_limits<double>::infinity()),
                                  glm::dvec3(-std::numeric_limits<double>::infinity())};
    const std::vector<double> angles = s.full_turn() ? critical_angles(0.0, 360.0) : critical_angles(s.a0, s.a1);
    for (double r : {s.r0, s.r1})
        for (double t : angles)
            for (double h : {s.h0, s.h1}) grow(box, from_cylindrical({r, t, h}, s.center));
    return box;
}

std::array<glm::dvec3, 2> bounding_box(const SphericalShell& s) {
    std::array<glm::dvec3, 2> box{glm::dvec3(std::numeric_limits<double>::infinity()),
                                  glm::dvec3(-std::numeric_limits<double>::infinity())};
    const std::vector<double> lons = s.full_turn() ? critical_angles(0.0, 360.0) : critical_angles(s.lon0, s.lon1);
    std::vector<double> lats{s.lat0, s.lat1};
    if (s.lat0 < 0.0 && 0.0 < s.lat1) lats.push_back(0.0);
    // x = R cos(lat) cos(lon), z = -R cos(lat) sin(lon): products of a factor of lat and one of lon,
    // each extreme at its ends or critical angles; y = R sin(lat) at the latitude ends.
    for (double r : {s.r0, s.r1})
        for (double lon : lons)
            for (double lat : lats) grow(box, from_spherical({r, lon, lat}, s.center));
    return box;
}

// ---- ShellAxis ----

double ShellAxis::representative(double c) const {
    if (!angular) return c;
    double rep = lo + wrap_degrees(c - lo);  // in [lo, lo + 360)
    if (!periodic && rep > hi && (rep - hi) > (lo + 360.0 - rep)) rep -= 360.0;  // nearer to the low edge
    return rep;
}

double ShellAxis::index(double c) const {
    if (periodic) {
        double u = wrap_degrees(c - lo) * double(n) / 360.0;
        if (u >= double(n)) u = 0.0;
        return u;
    }
    if (n <= 1) return 0.0;
    return (representative(c) - lo) * double(n - 1) / (hi - lo);
}

double ShellAxis::coordinate(double u) const {
    if (periodic) return lo + u * 360.0 / double(n);
    if (n <= 1) return lo;
    return lo + u * (hi - lo) / double(n - 1);
}

bool ShellAxis::contains(double c, double tolerance) const {
    if (periodic) return !std::isnan(c);
    const double rep = representative(c);
    const double pad = tolerance * (hi - lo);
    return rep >= lo - pad && rep <= hi + pad;
}

double ShellAxis::step() const {
    if (periodic) return 360.0 / double(n);
    return n <= 1 ? 0.0 : (hi - lo) / double(n - 1);
}

// ---- ShellGrid ----

namespace {
void check_dims(const std::array<std::int64_t, 3>& dims, const std::string& what) {
    for (int a = 0; a < 3; ++a)
        if (dims[std::size_t(a)] < 1)
            throw Error(what + "grid dims must be >= 1 (got " + std::to_string(dims[std::size_t(a)]) + " on axis " +
                        std::to_string(a) + ")");
}
}  // namespace

ShellGrid::ShellGrid(const CylindricalShell& shell, const std::array<std::int64_t, 3>& dims)
    : kind_(Kind::Cylindrical), cylinder_(shell), dims_(dims) {
    check_shell(shell);
    check_dims(dims, "cylindrical shell: ");
    init_axes();
}

ShellGrid::ShellGrid(const SphericalShell& shell, const std::array<std::int64_t, 3>& dims)
    : kind_(Kind::Spherical), sphere_(shell), dims_(dims) {
    check_shell(shell);
    check_dims(dims, "spherical shell: ");
    init_axes();
}

void ShellGrid::init_axes() {
    // Canonical coordinate axes, then assigned to grid axes.
    std::array<ShellAxis, 3> canonical;
    if (kind_ == Kind::Cylindrical) {
        const CylindricalShell& s = cylinder_;
        canonical[0] = {s.r0, s.r1, 1, false, false};
        canonical[1] = {s.a0, s.a1, 1, true, s.full_turn()};
        canonical[2] = {s.h0, s.h1, 1, false, false};
        coord_of_axis_ = {0, 1, 2};
    } else {
        const SphericalShell& s = sphere_;
        canonical[0] = {s.lon0, s.lon1, 1, true, s.full_turn()};
        canonical[1] = {s.lat0, s.lat1, 1, false, false};
        canonical[2] = {s.r0, s.r1, 1, false, false};
        coord_of_axis_ = s.axes;
    }
    for (int a = 0; a < 3; ++a) {
        const int c = coord_of_axis_[std::size_t(a)];
        axis_of_coord_[std::size_t(c)] = a;
        axes_[std::size_t(a)] = canonical[std::size_t(c)];
        axes_[std::size_t(a)].n = dims_[std::size_t(a)];
    }
}

glm::dvec3 ShellGrid::shell_coordinates(const glm::dvec3& world) const {
    if (kind_ == Kind::Cylindrical) {
        const CylindricalCoordinates c = to_cylindrical(world, cylinder_.center);
        return {c.r, c.theta, c.h};
    }
    const SphericalCoordinates c = to_spherical(world, sphere_.center);
    return {c.lon, c.lat, c.radius};
}

glm::dvec3 ShellGrid::world_position(const glm::dvec3& shell) const {
    if (kind_ == Kind::Cylindrical) return from_cylindrical({shell[0], shell[1], shell[2]}, cylinder_.center);
    return from_spherical({shell[2], shell[0], shell[1]}, sphere_.center);
}

glm::dvec3 ShellGrid::continuous_index(const glm::dvec3& world) const {
    const glm::dvec3 c = shell_coordinates(world);
    glm::dvec3 u;
    for (int a = 0; a < 3; ++a) u[a] = axes_[std::size_t(a)].index(c[coord_of_axis_[std::size_t(a)]]);
    return u;
}

glm::dvec3 ShellGrid::index_position(const glm::dvec3& u) const {
    glm::dvec3 c;
    for (int a = 0; a < 3; ++a) c[coord_of_axis_[std::size_t(a)]] = axes_[std::size_t(a)].coordinate(u[a]);
    return world_position(c);
}

bool ShellGrid::contains(const glm::dvec3& world, double tolerance) const {
    const glm::dvec3 c = shell_coordinates(world);
    // Where an angle is undefined the point is in every range of it (the closure of any wedge):
    // theta on the cylinder's axis; lon at the poles and the centre; lat at the centre.
    std::array<bool, 3> skip{false, false, false};  // canonical coordinates
    if (kind_ == Kind::Cylindrical) {
        skip[1] = c[0] == 0.0;
    } else {
        skip[0] = c[2] == 0.0 || std::abs(c[1]) == 90.0;
        skip[1] = c[2] == 0.0;
    }
    for (int a = 0; a < 3; ++a) {
        const int k = coord_of_axis_[std::size_t(a)];
        if (!skip[std::size_t(k)] && !axes_[std::size_t(a)].contains(c[k], tolerance)) return false;
    }
    return true;
}

double ShellGrid::default_gradient_step() const {
    double h = std::numeric_limits<double>::infinity();
    auto consider = [&h](double step) {
        if (step > 0.0) h = std::min(h, step);
    };
    auto step_of = [this](int coord) -> const ShellAxis& { return axes_[std::size_t(axis_of_coord_[std::size_t(coord)])]; };
    auto has_samples = [](const ShellAxis& a) { return a.n >= 2; };
    double r1 = 0.0;
    if (kind_ == Kind::Cylindrical) {
        r1 = cylinder_.r1;
        const ShellAxis &r = step_of(0), &t = step_of(1), &y = step_of(2);
        if (has_samples(r)) consider(r.step());
        if (has_samples(t)) consider(r1 * t.step() * kRadiansPerDegree);
        if (has_samples(y)) consider(y.step());
        if (!std::isfinite(h)) h = cylinder_.r1 - cylinder_.r0;
    } else {
        r1 = sphere_.r1;
        const ShellAxis &lon = step_of(0), &lat = step_of(1), &r = step_of(2);
        // The largest cos(lat) over [lat0, lat1]: 1 if the range holds the equator.
        double cmax = 1.0;
        if (!(sphere_.lat0 <= 0.0 && 0.0 <= sphere_.lat1)) {
            double s, c;
            sincos_degrees(std::min(std::abs(sphere_.lat0), std::abs(sphere_.lat1)), s, c);
            cmax = c;
        }
        if (has_samples(r)) consider(r.step());
        if (has_samples(lat)) consider(r1 * lat.step() * kRadiansPerDegree);
        if (has_samples(lon)) consider(r1 * cmax * lon.step() * kRadiansPerDegree);
        if (!std::isfinite(h)) h = sphere_.r1 - sphere_.r0;
    }
    return h;
}

}  // namespace volref
