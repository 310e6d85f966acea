#include "core/sample/ShellSampler.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "core/Error.h"
#include "core/sample/IndexSpace.h"
#include "core/sample/Tricubic.h"
#include "core/sample/Trilinear.h"

namespace volref {

ShellSampler::ShellSampler(const Volume& volume, const CylindricalShell& shell, Interpolation interpolation,
                           double gradient_step)
    : volume_(volume), grid_(shell, volume.dims), interpolation_(interpolation), h_(gradient_step) {
    check();
}

ShellSampler::ShellSampler(const Volume& volume, const SphericalShell& shell, Interpolation interpolation,
                           double gradient_step)
    : volume_(volume), grid_(shell, volume.dims), interpolation_(interpolation), h_(gradient_step) {
    check();
}

void ShellSampler::check() {
    const std::size_t count = std::size_t(volume_.dims[0]) * std::size_t(volume_.dims[1]) * std::size_t(volume_.dims[2]);
    if (volume_.values.size() != count)
        throw Error("beam-space volume: " + std::to_string(volume_.values.size()) + " values for dims " +
                    std::to_string(volume_.dims[0]) + " x " + std::to_string(volume_.dims[1]) + " x " +
                    std::to_string(volume_.dims[2]));
    if (!(std::isfinite(h_) && h_ >= 0.0)) throw Error("shell sampler: the gradient step must be finite and >= 0");
    if (h_ == 0.0) h_ = grid_.default_gradient_step();
    for (int a = 0; a < 3; ++a) periodic_[std::size_t(a)] = grid_.axis(a).periodic;
}

double ShellSampler::index_value(const glm::dvec3& u) const {
    switch (interpolation_) {
        case Interpolation::Nearest: return nearest(u);
        case Interpolation::Trilinear: return trilinear(u);
        default: return tricubic(u);
    }
}

// Index space as on a Cartesian grid (IndexSpace.h), with each axis' boundary rule.
double ShellSampler::nearest(const glm::dvec3& u) const {
    const Volume& v = volume_;
    return v.at(nearest_axis(u.x, v.dims[0], periodic_[0]), nearest_axis(u.y, v.dims[1], periodic_[1]),
                nearest_axis(u.z, v.dims[2], periodic_[2]));
}

double ShellSampler::trilinear(const glm::dvec3& u) const {
    const LinearAxis x = linear_axis(u.x, volume_.dims[0], periodic_[0]);
    const LinearAxis y = linear_axis(u.y, volume_.dims[1], periodic_[1]);
    const LinearAxis z = linear_axis(u.z, volume_.dims[2], periodic_[2]);
    return volref::trilinear(cell_corners(volume_, x, y, z), x.p, y.p, z.p);
}

double ShellSampler::tricubic(const glm::dvec3& u) const {
    const CubicKernel k =
        interpolation_ == Interpolation::TricubicCatmullRom ? CubicKernel::CatmullRom : CubicKernel::BSpline;
    return volref::tricubic(volume_, cubic_axis(k, u.x, volume_.dims[0], periodic_[0]),
                            cubic_axis(k, u.y, volume_.dims[1], periodic_[1]), cubic_axis(k, u.z, volume_.dims[2], periodic_[2]));
}

glm::dvec3 ShellSampler::gradient(const glm::dvec3& world) const {
    glm::dvec3 g(0.0);
    bool have_center = false;
    double f_center = 0.0;
    auto center = [&]() {
        if (!have_center) {
            f_center = value(world);
            have_center = true;
        }
        return f_center;
    };
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 plus = world, minus = world;
        plus[a] += h_;
        minus[a] -= h_;
        const bool in_plus = grid_.contains(plus), in_minus = grid_.contains(minus);
        if (in_plus && in_minus) g[a] = (value(plus) - value(minus)) / (plus[a] - minus[a]);
        else if (in_plus) g[a] = (value(plus) - center()) / (plus[a] - world[a]);
        else if (in_minus) g[a] = (center() - value(minus)) / (world[a] - minus[a]);
    }
    return g;
}

}  // namespace volref
