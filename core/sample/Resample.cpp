#include "core/sample/Resample.h"

#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"
#include "core/sample/ShellSampler.h"
#include "core/sample/VolumeSampler.h"
#include "geometry/ShellCoordinates.h"

namespace volref {

namespace {

// Fills out.values by f(i, j, k), in parallel over k slices.
template <class F>
void fill_parallel(Volume& out, const F& f) {
    const std::int64_t nx = out.dims[0], ny = out.dims[1];
    double* values = out.values.data<double>();  // make_output's f64 storage
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, out.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
        for (std::int64_t k = r.begin(); k != r.end(); ++k)
            for (std::int64_t j = 0; j < ny; ++j)
                for (std::int64_t i = 0; i < nx; ++i) values[out.index(i, j, k)] = f(i, j, k);
    });
}

void check_source(const Volume& v, const std::string& what) {
    const std::size_t count = checked_voxel_count(v.dims, what, scalar_type_size(v.values.type()));
    if (v.values.size() != count)
        throw Error(what + ": " + std::to_string(v.values.size()) + " values for dims " + std::to_string(v.dims[0]) +
                    " x " + std::to_string(v.dims[1]) + " x " + std::to_string(v.dims[2]));
}

Volume make_output(const std::array<std::int64_t, 3>& dims, const glm::dvec3& origin, const glm::dvec3& spacing) {
    Volume out;
    out.values.allocate(ScalarType::F64, checked_voxel_count(dims, "resample output"), false);  // filled by fill_parallel
    out.dims = dims;
    out.origin = origin;
    out.spacing = spacing;
    out.type = ScalarType::F64;
    return out;
}

template <class Shell>
Volume to_shell(const Volume& cartesian, Interpolation interpolation, const Shell& shell,
                const std::array<std::int64_t, 3>& dims, double fill) {
    check_source(cartesian, "resample source");
    const ShellGrid grid(shell, dims);
    Volume out = make_output(dims, glm::dvec3(0.0), glm::dvec3(1.0));
    const VolumeSampler sampler(cartesian, interpolation);
    const glm::dvec3 pad = kResampleDomainTolerance * cartesian.spacing;
    const glm::dvec3 lo = cartesian.domain_min() - pad, hi = cartesian.domain_max() + pad;
    fill_parallel(out, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        const glm::dvec3 p = grid.sample_position(i, j, k);
        const bool inside = p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
        return inside ? sampler.value(p) : fill;
    });
    return out;
}

template <class Shell>
Volume to_cartesian(const Volume& beam, const Shell& shell, Interpolation interpolation, const glm::dvec3& origin,
                    const glm::dvec3& spacing, const std::array<std::int64_t, 3>& dims, double fill) {
    check_source(beam, "resample source");
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(origin[a])) throw Error("resample: the origin must be finite");
        if (!(std::isfinite(spacing[a]) && spacing[a] > 0.0)) throw Error("resample: the spacing must be finite and > 0");
    }
    const ShellSampler sampler(beam, shell, interpolation);
    Volume out = make_output(dims, origin, spacing);
    fill_parallel(out, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        const glm::dvec3 p = out.voxel_position(i, j, k);
        return sampler.grid().contains(p, kResampleShellTolerance) ? sampler.value(p) : fill;
    });
    return out;
}

}  // namespace

Volume resample_to_cylindrical(const Volume& cartesian, Interpolation interpolation, const CylindricalShell& shell,
                               const std::array<std::int64_t, 3>& dims, double fill) {
    return to_shell(cartesian, interpolation, shell, dims, fill);
}

Volume resample_to_spherical(const Volume& cartesian, Interpolation interpolation, const SphericalShell& shell,
                             const std::array<std::int64_t, 3>& dims, double fill) {
    return to_shell(cartesian, interpolation, shell, dims, fill);
}

Volume resample_to_cartesian(const Volume& beam, const CylindricalShell& shell, Interpolation interpolation,
                             const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& dims, double fill) {
    return to_cartesian(beam, shell, interpolation, origin, spacing, dims, fill);
}

Volume resample_to_cartesian(const Volume& beam, const SphericalShell& shell, Interpolation interpolation,
                             const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& dims, double fill) {
    return to_cartesian(beam, shell, interpolation, origin, spacing, dims, fill);
}

}  // namespace volref
