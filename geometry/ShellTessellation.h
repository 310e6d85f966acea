// Shells as triangle meshes (`"tessellate": N` in a shell's bounds): a closed, outward-oriented mesh of
// the shell's boundary, rendered through BoundingGeometry::add_mesh, to compare speed and difference
// with the analytic shells (geometry/ShellIntersection.h).
//
// Subdivision: n segments per full turn (n >= 3). An angle or longitude range of span s degrees has
// m = max(1, ceil(n s / 360)) equal segments (exactly n for a full turn, which is periodic: no seam
// vertices are doubled); a latitude range of span s has max(1, ceil(n s / 360)) equal segments, so no
// curved edge spans more than 360 / n degrees. Straight directions (radius, height) are not subdivided.
// All vertices lie on the analytic surfaces (the meshes are inscribed); rows at latitude +-90 collapse
// to one pole vertex and the inner surface with r0 = 0 to the centre (or the axis), so the mesh is
// closed; degenerate triangles are not emitted.
//
// Geometric error (the largest distance between the mesh and the analytic boundary, both ways):
//   cylindrical shell: r1 (1 - cos(pi / n)), the sagitta of a chord spanning 360 / n degrees on the
//     outer circle (the inner cylinder's is r0 (1 - cos(pi / n))); caps and angle faces are exact;
//   spherical shell: r1 sin^2(pi / n) = r1 (1 - cos^2(pi / n)) (about twice the circle's): the depth of
//     a planar latitude-longitude cell of 360 / n x 360 / n degrees centred on the equator below the
//     sphere (its corners are at angle theta from its centre with cos theta = cos^2(pi / n)); the
//     latitude cones (inscribed trapezoids) deviate by at most R cos(lat) (1 - cos(pi / n)), and the
//     longitude faces are exact planes.
// In terms of the shell's coordinates: the mesh's radii lie within [r (1 - e), r] of each radius r
// (e = 1 - cos(pi / n) cylindrical, sin^2(pi / n) spherical), and a latitude limit b moves at most to
// atan(tan(b) / cos(pi / n)) (away from the equator). A ray crossing the boundary at incidence angle
// phi from the normal moves its crossing by at most error / cos(phi).
#pragma once
#include "core/scene/ShellSpec.h"
#include "geometry/TriangleMesh.h"

namespace volref {

TriangleMesh tessellate(const CylindricalShell& shell, int n);
TriangleMesh tessellate(const SphericalShell& shell, int n);

// The geometric error stated above.
double tessellation_error(const CylindricalShell& shell, int n);
double tessellation_error(const SphericalShell& shell, int n);

// The number of equal segments for an angular span of `span_degrees` at n segments per full turn.
int tessellation_segments(double span_degrees, int n);

}  // namespace volref
