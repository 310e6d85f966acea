#include "core/Angles.h"

#include <cmath>
#include <numbers>

namespace volref {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

}  // namespace

void cos_sin_degrees(double deg, double& c, double& s) {
    const double k = deg / 90.0;
    if (k == std::floor(k) && std::abs(k) < 1e15) {
        const long long q = ((static_cast<long long>(k) % 4) + 4) % 4;
        static constexpr double cs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
        c = cs[q][0];
        s = cs[q][1];
        return;
    }
    c = std::cos(deg * kDegree);
    s = std::sin(deg * kDegree);
}

glm::dmat3 rotation_matrix(const glm::dvec3& a, double degrees) {
    double c, s;
    cos_sin_degrees(degrees, c, s);
    const double k = 1.0 - c;
    // Columns of R (glm is column-major: m[col][row]).
    glm::dmat3 r;
    r[0] = glm::dvec3(c + k * a.x * a.x, k * a.x * a.y + s * a.z, k * a.x * a.z - s * a.y);
    r[1] = glm::dvec3(k * a.y * a.x - s * a.z, c + k * a.y * a.y, k * a.y * a.z + s * a.x);
    r[2] = glm::dvec3(k * a.z * a.x + s * a.y, k * a.z * a.y - s * a.x, c + k * a.z * a.z);
    return r;
}

}  // namespace volref
