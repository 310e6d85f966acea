#include "core/sample/VolumeSampler.h"

#include <algorithm>
#include <cmath>

#include "core/sample/Trilinear.h"
#include "core/sample/Tricubic.h"

namespace volref {

VolumeSampler::VolumeSampler(const Volume& volume, Interpolation interpolation)
    : volume_(volume), interpolation_(interpolation) {
    inv_spacing_ = 1.0 / volume.spacing;
    max_index_ = glm::dvec3(double(volume.dims[0] - 1), double(volume.dims[1] - 1), double(volume.dims[2] - 1));
}

glm::dvec3 VolumeSampler::continuous_index(const glm::dvec3& world) const {
    const glm::dvec3 u = (world - volume_.origin) * inv_spacing_;
    return glm::dvec3(std::clamp(u.x, 0.0, max_index_.x), std::clamp(u.y, 0.0, max_index_.y),
                      std::clamp(u.z, 0.0, max_index_.z));
}

void VolumeSampler::locate(const glm::dvec3& u, std::array<std::int64_t, 3>& cell, glm::dvec3& frac) const {
    for (int a = 0; a < 3; ++a) {
        const std::int64_t n = volume_.dims[a];
        const std::int64_t i = n == 1 ? 0 : std::min<std::int64_t>(std::int64_t(std::floor(u[a])), n - 2);
        cell[a] = i;
        frac[a] = n == 1 ? 0.0 : u[a] - double(i);
    }
}

std::array<double, 8> VolumeSampler::corners(const std::array<std::int64_t, 3>& c) const {
    const std::int64_t i0 = c[0], j0 = c[1], k0 = c[2];
    const std::int64_t i1 = std::min(i0 + 1, volume_.dims[0] - 1);
    const std::int64_t j1 = std::min(j0 + 1, volume_.dims[1] - 1);
    const std::int64_t k1 = std::min(k0 + 1, volume_.dims[2] - 1);
    const Volume& v = volume_;
    return {v.at(i0, j0, k0), v.at(i1, j0, k0), v.at(i1, j1, k0), v.at(i0, j1, k0),
            v.at(i0, j0, k1), v.at(i1, j0, k1), v.at(i1, j1, k1), v.at(i0, j1, k1)};
}

double VolumeSampler::trilinear(const glm::dvec3& world) const {
    std::array<std::int64_t, 3> cell;
    glm::dvec3 frac;
    locate(continuous_index(world), cell, frac);
    return volref::trilinear(corners(cell), frac.x, frac.y, frac.z);
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
    const glm::dvec3 u = continuous_index(world);
    std::array<std::int64_t, 3> idx;
    for (int a = 0; a < 3; ++a)
        idx[a] = std::min<std::int64_t>(std::int64_t(std::floor(u[a] + 0.5)), volume_.dims[a] - 1);
    return volume_.at(idx[0], idx[1], idx[2]);
}

}  // namespace volref
