#include "core/sample/VolumeSampler.h"

#include <algorithm>
#include <cmath>

#include "core/sample/IndexSpace.h"
#include "core/sample/Trilinear.h"
#include "core/sample/Tricubic.h"

namespace volref {

VolumeSampler::VolumeSampler(const Volume& volume, Interpolation interpolation)
    : volume_(volume), interpolation_(interpolation) {
    inv_spacing_ = 1.0 / volume.spacing;
    max_index_ = glm::dvec3(double(volume.dims[0] - 1), double(volume.dims[1] - 1), double(volume.dims[2] - 1));
}

namespace {
CubicKernel kernel_of(Interpolation i) {
    return i == Interpolation::TricubicBSpline ? CubicKernel::BSpline : CubicKernel::CatmullRom;
}
}  // namespace

double VolumeSampler::tricubic(const glm::dvec3& world) const {
    return volref::tricubic(volume_, kernel_of(interpolation_), continuous_index(world));
}

glm::dvec3 VolumeSampler::tricubic_gradient(const glm::dvec3& world) const {
    return tricubic_index_gradient(volume_, kernel_of(interpolation_), continuous_index(world)) * inv_spacing_;
}

double VolumeSampler::nearest(const glm::dvec3& world) const {
    const glm::dvec3 u = continuous_index(world);  // clamped: IndexSpace.h's clamp leaves it as it is
    return volume_.at(nearest_axis(u.x, volume_.dims[0], false), nearest_axis(u.y, volume_.dims[1], false),
                      nearest_axis(u.z, volume_.dims[2], false));
}

}  // namespace volref
