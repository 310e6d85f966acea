#pragma once
#include <glm/vec3.hpp>

namespace volref {

// A ray x(t) = origin + t * direction, |direction| = 1, so t is a distance in world units.
// For perspective cameras the origin is the eye; for orthographic ones it is on the eye's plane.
struct Ray {
    glm::dvec3 origin{0.0};
    glm::dvec3 direction{0.0, 0.0, -1.0};
    glm::dvec3 at(double t) const { return origin + t * direction; }
};

}  // namespace volref
