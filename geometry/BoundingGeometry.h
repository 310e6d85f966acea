// BoundingGeometry: the Embree scene of every volume's bounding shape, and the per-ray query that
// returns the ray's intervals inside a volume (its shape AND its data domain, t >= 0).
//
// Each shape is an Embree user geometry whose intersect callback computes its exact intervals in
// double precision (the float ray Embree traverses with only finds the candidate shapes) and
// records them in the query's context without reporting a hit, so traversal visits every shape the
// ray meets and a ray may enter and leave a shape several times. Meshes and shells slot in as
// further shape types.
#pragma once
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "geometry/RayIntervals.h"

namespace volref {

class BoundingGeometry {
public:
    BoundingGeometry();
    ~BoundingGeometry();
    BoundingGeometry(const BoundingGeometry&) = delete;
    BoundingGeometry& operator=(const BoundingGeometry&) = delete;

    // Adds volume `volume_id`'s bounding box [lo, hi] and its data domain [domain_lo, domain_hi].
    // Returns the volume id. Call commit() after the last add.
    int add_box(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& domain_lo, const glm::dvec3& domain_hi);
    void commit();

    // The intervals of `ray` inside volume `volume_id` (sorted, disjoint, t >= 0), into `out`.
    void intervals(const Ray& ray, int volume_id, std::vector<Interval>& out) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace volref
