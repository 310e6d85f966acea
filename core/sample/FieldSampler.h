// The two questions the sample pipeline asks of a volume, whatever its grid (a Cartesian
// VolumeSampler, a beam-space ShellSampler): the reconstructed value f(x) and its gradient at a world
// point. Open VKL's sampler split, scalar version.
#pragma once
#include <glm/vec3.hpp>

namespace volref {

class FieldSampler {
public:
    virtual ~FieldSampler() = default;
    virtual double value(const glm::dvec3& world) const = 0;
};

class GradientSource {
public:
    virtual ~GradientSource() = default;
    // grad f in value per world unit.
    virtual glm::dvec3 gradient(const glm::dvec3& world) const = 0;
};

}  // namespace volref
