// The parameters of the curvilinear shells (scene key volume.bounds with type "cylindrical" or
// "spherical"); angles in degrees as in scene files: plain scene description data (the scene loader
// fills them; geometry/ and core/sample/ compute with them). Conventions (docs/conventions.md):
//   cylindrical: axis y through `center`; a point (r, theta, h) is at
//                center + (r cos theta, h, -r sin theta), theta = atan2(-z, x) in [0, 360);
//                grid axes (radius, angle, height).
//   spherical:   a point (R, lon, lat) is at center + (R cos lat cos lon, R sin lat, -R cos lat sin lon);
//                grid axes (longitude, latitude, radius) unless `axes` permutes them.
// Sample i of n along an axis [lo, hi] sits at lo + i (hi - lo) / (n - 1), except a full 360-degree
// angle or longitude range, which is periodic: lo + i 360 / n, interpolation wrapping over the seam.
#pragma once
#include <array>

#include <glm/vec3.hpp>

namespace volref {

struct CylindricalShell {
    glm::dvec3 center{0.0};
    double r0 = 0.0, r1 = 1.0;   // 0 <= r0 < r1
    double a0 = 0.0, a1 = 360.0; // degrees, a0 < a1 <= a0 + 360
    double h0 = 0.0, h1 = 1.0;   // h0 < h1
    bool full_turn() const { return a1 - a0 >= 360.0; }
};

struct SphericalShell {
    glm::dvec3 center{0.0};
    double r0 = 0.0, r1 = 1.0;         // 0 <= r0 < r1
    double lon0 = 0.0, lon1 = 360.0;   // degrees, lon0 < lon1 <= lon0 + 360
    double lat0 = -90.0, lat1 = 90.0;  // degrees, -90 <= lat0 < lat1 <= 90
    // Which shell coordinate each grid axis holds: 0 longitude, 1 latitude, 2 radius.
    // Default (0, 1, 2): grid i = longitude, j = latitude, k = radius.
    std::array<int, 3> axes{0, 1, 2};
    bool full_turn() const { return lon1 - lon0 >= 360.0; }
};

}  // namespace volref
