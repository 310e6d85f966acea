// Shell coordinates of the curvilinear shells (core/scene/ShellSpec.h, docs/shells.md) and the mapping
// of a shell point to the continuous index of its beam-space grid.
//
//   cylindrical: p - center = (r cos theta, h, -r sin theta); r = |(x, z)| >= 0,
//                theta = atan2(-z, x) in degrees in [0, 360), h = y.
//   spherical:   p - center = (R cos lat cos lon, R sin lat, -R cos lat sin lon); R = |p - center|,
//                lon = atan2(-z, x) in degrees in [0, 360), lat = atan2(y, |(x, z)|) in [-90, 90].
// Where an angle is undefined it is 0: theta and lon on the axis (x = z = 0: r = 0, or a pole),
// lat at the centre (R = 0). The reconstruction there is then that of angle 0, which equals the
// value at any other angle only if the data agree there (the samples at r = 0 or at a pole).
//
// Grid placement, per grid axis over [lo, hi] with n samples (ShellAxis):
//   non-periodic: sample i at lo + i (hi - lo) / (n - 1) (lo when n = 1); u = (c - lo) (n - 1) / (hi - lo);
//   periodic (a full 360-degree angle or longitude range, hi - lo >= 360): sample i at lo + i 360 / n,
//             u = ((c - lo) mod 360) n / 360 in [0, n): interpolation wraps from sample n - 1 to 0.
// An angle (theta, lon) is first moved by a multiple of 360 into [lo, lo + 360), so ranges that do
// not start at 0 ([300, 660) full turn, a wedge [300, 420] over the seam) work. On a wedge, an angle
// in the gap (hi, lo + 360) is moved to the nearer edge (by another -360 when lo is nearer; hi on a
// tie), so its index is < 0 or > n - 1 and clamping gives that edge's samples.
// Grid axes: cylindrical (radius, angle, height); spherical as SphericalShell::axes says (default
// (longitude, latitude, radius)). Shell coordinates in "canonical order" are (r, theta, h) for a
// cylinder and (lon, lat, R) for a sphere (the numbering of SphericalShell::axes).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>

#include <glm/vec3.hpp>

#include "core/scene/ShellSpec.h"

namespace volref {

struct CylindricalCoordinates {
    double r = 0.0;      // >= 0
    double theta = 0.0;  // degrees, [0, 360) from to_cylindrical; any value for from_cylindrical
    double h = 0.0;
};

struct SphericalCoordinates {
    double radius = 0.0;  // >= 0
    double lon = 0.0;     // degrees, [0, 360) from to_spherical
    double lat = 0.0;     // degrees, [-90, 90]
};

// World point <-> shell coordinates around `center`.
CylindricalCoordinates to_cylindrical(const glm::dvec3& world, const glm::dvec3& center);
glm::dvec3 from_cylindrical(const CylindricalCoordinates& c, const glm::dvec3& center);
SphericalCoordinates to_spherical(const glm::dvec3& world, const glm::dvec3& center);
glm::dvec3 from_spherical(const SphericalCoordinates& c, const glm::dvec3& center);

// atan2(y, x) in degrees in [0, 360); 0 when x = y = 0; exact (0, 90, 180, 270) on the axes.
double atan2_degrees(double y, double x);
// sin and cos of an angle in degrees, reduced exactly modulo 360 first; exact at multiples of 90.
void sincos_degrees(double degrees, double& s, double& c);
// `degrees` reduced into [0, 360).
double wrap_degrees(double degrees);

// Throws volref::Error (one line, starting with "cylindrical shell: " / "spherical shell: ") unless
// the parameters are finite and valid: 0 <= r0 < r1, a0 < a1 <= a0 + 360, h0 < h1;
// -90 <= lat0 < lat1 <= 90, lon0 < lon1 <= lon0 + 360, axes a permutation of (0, 1, 2).
void check_shell(const CylindricalShell& shell);
void check_shell(const SphericalShell& shell);

// The smallest axis-aligned box holding the shell region: [min, max].
std::array<glm::dvec3, 2> bounding_box(const CylindricalShell& shell);
std::array<glm::dvec3, 2> bounding_box(const SphericalShell& shell);

// One grid axis of a beam-space volume.
struct ShellAxis {
    double lo = 0.0, hi = 1.0;
    std::int64_t n = 1;
    bool angular = false;   // an angle in degrees (theta, lon): coordinates are taken modulo 360
    bool periodic = false;  // angular with hi - lo >= 360

    // The representative of coordinate c on this axis: for an angle, c moved into [lo, lo + 360),
    // or just below lo when the wedge's low edge is nearer (see above); otherwise c itself.
    double representative(double c) const;
    // Continuous index of coordinate c: in [0, n) on a periodic axis, unclamped otherwise.
    double index(double c) const;
    // Coordinate of continuous index u (the inverse of index for u in [0, n - 1], or [0, n)).
    double coordinate(double u) const;
    // Whether c lies in [lo, hi] widened by `tolerance` (hi - lo) on each side; always on a periodic axis.
    bool contains(double c, double tolerance = 0.0) const;
    // Coordinate distance between neighbouring samples (0 when n = 1 on a non-periodic axis).
    double step() const;
};

// The beam-space grid of a shell: dims (n0, n1, n2) over the shell's grid axes.
class ShellGrid {
public:
    enum class Kind { Cylindrical, Spherical };

    // Both check the shell (check_shell) and dims >= 1; throw volref::Error otherwise.
    ShellGrid(const CylindricalShell& shell, const std::array<std::int64_t, 3>& dims);
    ShellGrid(const SphericalShell& shell, const std::array<std::int64_t, 3>& dims);

    Kind kind() const { return kind_; }
    const CylindricalShell& cylindrical() const { return cylinder_; }
    const SphericalShell& spherical() const { return sphere_; }
    const std::array<std::int64_t, 3>& dims() const { return dims_; }
    // Grid axis a (0, 1, 2).
    const ShellAxis& axis(int a) const { return axes_[std::size_t(a)]; }
    // Which canonical shell coordinate grid axis a holds.
    int coordinate_of_axis(int a) const { return coord_of_axis_[std::size_t(a)]; }

    // Shell coordinates of a world point in canonical order: (r, theta, h) or (lon, lat, R).
    glm::dvec3 shell_coordinates(const glm::dvec3& world) const;
    // The world point of shell coordinates in canonical order.
    glm::dvec3 world_position(const glm::dvec3& shell) const;
    // Continuous grid index (u0, u1, u2) of a world point: unclamped on non-periodic axes, in [0, n)
    // on periodic ones.
    glm::dvec3 continuous_index(const glm::dvec3& world) const;
    // World position of a continuous grid index.
    glm::dvec3 index_position(const glm::dvec3& u) const;
    // World position of sample (i, j, k).
    glm::dvec3 sample_position(std::int64_t i, std::int64_t j, std::int64_t k) const {
        return index_position(glm::dvec3(double(i), double(j), double(k)));
    }
    // Whether a world point is in the shell region: every coordinate within its axis' [lo, hi], widened
    // by `tolerance` times the axis' range (closed). Where an angle is undefined the point is in every
    // range of it, as the closure of any wedge: the cylinder's axis (r = 0) in every angle range, the
    // poles in every longitude range, the centre (R = 0) in every longitude and latitude range.
    bool contains(const glm::dvec3& world, double tolerance = 0.0) const;

    // The gradient step of ShellSampler (docs/shells.md): the smallest world-space distance between
    // neighbouring samples at the outer radius r1 over the axes with n >= 2:
    //   cylinder: (r1 - r0) / (n_r - 1), r1 * dtheta (radians), (h1 - h0) / (n_h - 1);
    //   sphere:   (r1 - r0) / (n_R - 1), r1 * dlat (radians), r1 * max cos(lat) * dlon (radians);
    // r1 - r0 when every axis has n = 1 (the field is then constant).
    double default_gradient_step() const;

private:
    void init_axes();
    Kind kind_;
    CylindricalShell cylinder_;
    SphericalShell sphere_;
    std::array<std::int64_t, 3> dims_;
    std::array<ShellAxis, 3> axes_;
    std::array<int, 3> coord_of_axis_{0, 1, 2};
    std::array<int, 3> axis_of_coord_{0, 1, 2};
};

}  // namespace volref
