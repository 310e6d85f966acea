// VolumeTransform: a volume's placement in the world (scene key volume.transform; conventions
// section 1). M maps the volume's own space (where its grid, bounding shape and crop planes live) to
// world space: x_world = A x_local + b, with A the upper-left 3x3 block and b the last column.
//
// A world ray x(t) = o + t d becomes the local ray x_local(t) = A^-1 (o - b) + t A^-1 d: the same t
// (so segment lengths and distances stay world lengths), a direction that is in general not unit. The
// bounding shapes and crop planes are intersected with the local ray; samples are taken at
// A^-1 (x - b); gradients come back by the chain rule, grad_world f = A^-T grad_local f.
#pragma once
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>

#include "core/camera/Ray.h"

namespace volref {

class VolumeTransform {
public:
    // `to_world` must be affine and invertible (the scene loader checks).
    explicit VolumeTransform(const glm::dmat4& to_world)
        : a_(to_world), b_(to_world[3]), a_inv_(glm::inverse(a_)), normal_(glm::transpose(a_inv_)) {}

    glm::dvec3 to_local(const glm::dvec3& world) const { return a_inv_ * (world - b_); }
    glm::dvec3 to_world(const glm::dvec3& local) const { return a_ * local + b_; }
    // A local gradient (value per local unit) as a world gradient: A^-T g.
    glm::dvec3 gradient_to_world(const glm::dvec3& g_local) const { return normal_ * g_local; }
    glm::dvec3 direction_to_world(const glm::dvec3& d_local) const { return a_ * d_local; }
    // The world length of a local vector.
    double world_length(const glm::dvec3& local) const { return glm::length(a_ * local); }
    Ray local_ray(const Ray& world) const { return {to_local(world.origin), a_inv_ * world.direction}; }

private:
    glm::dmat3 a_;
    glm::dvec3 b_;
    glm::dmat3 a_inv_, normal_;
};

}  // namespace volref
