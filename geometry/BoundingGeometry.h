// BoundingGeometry: the Embree scene of every volume's bounding shape, and the per-ray query that
// returns the ray's intervals inside a volume (its shape AND its data domain, t >= 0).
//
// Every shape is an Embree user geometry whose intersect callback computes exact results in double
// precision (the float ray Embree traverses with only finds the candidates: each primitive's bounds
// are padded by kEmbreeBoundsPadding (1 + the shape's largest extent) and rounded outwards, and the
// scene is built with RTC_SCENE_FLAG_ROBUST) and records them in the query's context without
// reporting a hit, so traversal visits every shape the ray meets and a ray may enter and leave a
// shape several times:
//   box:   the slab test (geometry/BoxIntersection.h), one interval; intervals() of a box volume runs
//          the same test directly, with no Embree query (the padded bounds make Embree call it for
//          every ray the double test can hit, so the result is the same);
//   mesh:  one primitive per triangle; the watertight double-precision ray/triangle test
//          (geometry/MeshIntervals.h) records each crossing, and after traversal the crossings become
//          the intervals where the winding number is > 0. (Embree's own float triangle test is not
//          watertight, even in robust mode, so a ray through an edge could lose a crossing.)
//   shell: the analytic intervals of geometry/ShellIntersection.h.
// Callbacks find their double-precision ray through the float ray's id (an index into the query's
// rays), so they handle any packet width N.
#pragma once
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/scene/ShellSpec.h"
#include "geometry/RayIntervals.h"
#include "geometry/TriangleMesh.h"

namespace volref {

class BoundingGeometry {
public:
    BoundingGeometry();
    ~BoundingGeometry();
    BoundingGeometry(const BoundingGeometry&) = delete;
    BoundingGeometry& operator=(const BoundingGeometry&) = delete;

    // Each add_* adds one volume and returns its id (0, 1, 2, ... in the order of the calls).
    // Call commit() after the last add.

    // The bounding box [lo, hi] and the data domain [domain_lo, domain_hi].
    int add_box(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& domain_lo, const glm::dvec3& domain_hi);
    // A closed triangle mesh (see check_closed; it is checked again, by `rule`, and oriented outward
    // here, an Error naming "bounding mesh" if it is not closed) and the data domain. A set of
    // tetrahedra bounds through its boundary (geometry/TetrahedralMesh.h: tetrahedra_boundary), a
    // Closedness::Cycle.
    int add_mesh(const TriangleMesh& mesh, const glm::dvec3& domain_lo, const glm::dvec3& domain_hi,
                 Closedness rule = Closedness::Manifold);
    // Curvilinear shells (core/scene/ShellSpec.h): the shell is also the data domain.
    int add_cylindrical_shell(const CylindricalShell& shell);
    int add_spherical_shell(const SphericalShell& shell);

    void commit();
    int volume_count() const;

    // The intervals of `ray` inside volume `volume_id` (sorted, disjoint, t >= 0), into `out`.
    void intervals(const Ray& ray, int volume_id, std::vector<Interval>& out) const;
    // The same for `count` rays at once (Embree packets of 16 rays): out[i] for rays[i]. The results
    // equal those of the single-ray query.
    void intervals(const Ray* rays, int count, int volume_id, std::vector<Interval>* out) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace volref
