// Analytic ray intervals in the curvilinear shells of core/scene/ShellSpec.h, in double precision.
//
// Cylindrical region (relative to the centre, axis y, theta = atan2(-z, x)):
//   r0 <= sqrt(x^2 + z^2) <= r1, h0 <= y <= h1, theta in [a0, a1] (mod 360; no limit when a1 - a0 >= 360).
// Spherical region (R = |p - centre|, lat = atan2(y, sqrt(x^2 + z^2)), lon = atan2(-z, x)):
//   r0 <= R <= r1, lat in [lat0, lat1], lon in [lon0, lon1] (mod 360; no limit when lon1 - lon0 >= 360).
// Both regions are closed. Points on the axis belong to every angle/longitude range (the axis is in the
// closure of any wedge), the poles to every longitude range, the centre (when r0 = 0) to every range.
//
// Method: every root t > 0 of every bounding surface along the ray is collected: the cylinders or
// spheres r = r0 (when r0 > 0) and r = r1; the height planes y = h0, y = h1; the planes through the
// axis at a0 and a1 (longitudes lon0, lon1) unless the range is a full turn; the cones of latitude
// lat0 and lat1 (both nappes; the plane y = 0 for latitude 0; none for +-90). Each quadratic adds the
// t of its extremum (the ray's closest approach to the axis or centre, where the angles jump) as a
// further split. Between consecutive split points (and from t = 0) the ray does not cross the region's
// boundary, so the midpoint decides whether the whole piece is inside; consecutive inside pieces are
// merged. Pieces of zero length (tangent rays) are dropped. Quadratics are solved without
// cancellation: q = -(b + sign(b) sqrt(disc)) / 2, roots q / a and c / q, and for cylinders and spheres
// disc = a (r - l)(r + l) with l the distance from the axis or centre to the ray's line.
#pragma once
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/scene/ShellSpec.h"
#include "geometry/RayIntervals.h"

namespace volref {

// Throw volref::Error naming the first invalid parameter (`what` prefixes the message, e.g. a file
// and JSON path): radii 0 <= r0 < r1, a0 < a1, h0 < h1, -90 <= lat0 < lat1 <= 90, all finite.
void validate_shell(const CylindricalShell& shell, const std::string& what = "cylindrical shell");
void validate_shell(const SphericalShell& shell, const std::string& what = "spherical shell");

// The smallest axis-aligned box holding the shell.
void shell_bounds(const CylindricalShell& shell, glm::dvec3& lo, glm::dvec3& hi);
void shell_bounds(const SphericalShell& shell, glm::dvec3& lo, glm::dvec3& hi);

// The real roots of a t^2 + b t + c = 0 (a linear equation when a = 0), without cancellation; returns
// how many (0, 1 or 2) were written to `roots`, in no particular order. A double root is written once.
int solve_quadratic(double a, double b, double c, double roots[2]);

// One split point of intervals(): the surface it belongs to and its t (any sign; only finite t > 0 split).
struct ShellRoot {
    const char* surface;
    double t;
};

class CylindricalShellIntersector {
public:
    explicit CylindricalShellIntersector(const CylindricalShell& shell);  // validates
    const CylindricalShell& shell() const { return shell_; }
    bool contains(const glm::dvec3& p) const;
    // Appends the sorted, disjoint intervals (t >= 0) of `ray` inside the shell to `out`.
    void intervals(const Ray& ray, std::vector<Interval>& out) const;
    // The same, also listing every root and extremum found, in the order found (`volref explain intersect`).
    void intervals(const Ray& ray, std::vector<Interval>& out, std::vector<ShellRoot>* roots) const;

private:
    bool contains_relative(const glm::dvec3& q) const;  // q = p - centre
    CylindricalShell shell_;
    bool full_;
    double a0_, span_;     // a0 in [0, 360), span = a1 - a0
    glm::dvec3 n0_, n1_;   // normals of the planes through the axis at a0 and a1
};

class SphericalShellIntersector {
public:
    explicit SphericalShellIntersector(const SphericalShell& shell);  // validates
    const SphericalShell& shell() const { return shell_; }
    bool contains(const glm::dvec3& p) const;
    void intervals(const Ray& ray, std::vector<Interval>& out) const;
    void intervals(const Ray& ray, std::vector<Interval>& out, std::vector<ShellRoot>* roots) const;

private:
    bool contains_relative(const glm::dvec3& q) const;
    SphericalShell shell_;
    bool full_;
    double lon0_, span_;
    glm::dvec3 n0_, n1_;
};

// theta = atan2(-z, x) in degrees, in [0, 360).
double azimuth_degrees(double x, double z);

}  // namespace volref
