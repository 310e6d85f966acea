// Angles in degrees, as scene files give them, with exact values at multiples of 90 degrees (so a grid
// turned by them lands exactly on a grid): the one cos/sin of the shells (geometry/ShellIntersection,
// geometry/ShellTessellation) and the rotation of a volume's transform (the scene loader's "rotate").
#pragma once
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace volref {

// cos and sin of an angle in degrees; exact (0, +-1) at multiples of 90.
void cos_sin_degrees(double degrees, double& c, double& s);

// The rotation by `degrees` about the unit `axis` (right-handed), by Rodrigues' formula
// R = c I + s [axis]x + (1 - c) axis axis^T; multiples of 90 degrees use exact cosines and sines
// (0, +-1), so a grid rotated by them lands exactly on a grid.
glm::dmat3 rotation_matrix(const glm::dvec3& axis, double degrees);

}  // namespace volref
