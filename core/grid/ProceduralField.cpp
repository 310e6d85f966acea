#include "core/grid/ProceduralField.h"

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"

namespace volref {

namespace {

double marschner_lobb_coordinate(std::int64_t i, std::int64_t n) {
    return n == 1 ? 0.0 : -1.0 + 2.0 * double(i) / double(n - 1);
}

double field_value(const FieldSpec& f, const Volume& v, const glm::dvec3& p, std::int64_t i, std::int64_t j,
                   std::int64_t k) {
    switch (f.kind) {
        case FieldSpec::Kind::Constant: return f.value;
        case FieldSpec::Kind::Linear:
            return f.coefficients[0] * p.x + f.coefficients[1] * p.y + f.coefficients[2] * p.z + f.coefficients[3];
        case FieldSpec::Kind::Radial: return glm::length(p - f.center);
        case FieldSpec::Kind::MarschnerLobb: {
            constexpr double pi = std::numbers::pi;
            const double x = marschner_lobb_coordinate(i, v.dims[0]);
            const double y = marschner_lobb_coordinate(j, v.dims[1]);
            const double z = marschner_lobb_coordinate(k, v.dims[2]);
            const double r = std::sqrt(x * x + y * y);
            const double rho = std::cos(2.0 * pi * f.fm * std::cos(pi * r / 2.0));
            return (1.0 - std::sin(pi * z / 2.0) + f.alpha * (1.0 + rho)) / (2.0 * (1.0 + f.alpha));
        }
        case FieldSpec::Kind::Gaussian: {
            const glm::dvec3 d = p - f.center;
            return f.amplitude * std::exp(-glm::dot(d, d) / (2.0 * f.sigma * f.sigma));
        }
        case FieldSpec::Kind::Cells: return f.values[v.index(i, j, k)];
    }
    return 0.0;
}

}  // namespace

Volume make_procedural_volume(const FieldSpec& field, const glm::dvec3& origin, const glm::dvec3& spacing) {
    Volume v = make_procedural_volume(field, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        return origin + glm::dvec3(double(i), double(j), double(k)) * spacing;
    });
    v.origin = origin;
    v.spacing = spacing;
    return v;
}

Volume make_procedural_volume(const FieldSpec& field,
                              const std::function<glm::dvec3(std::int64_t, std::int64_t, std::int64_t)>& position) {
    Volume v;
    v.dims = field.dims;
    v.type = ScalarType::F64;
    const std::size_t count = checked_voxel_count(v.dims, "volume.source.dims");
    if (field.kind == FieldSpec::Kind::Cells && field.values.size() != count)
        throw Error("volume.source.values: expected " + std::to_string(count) + " values (dims product), got " +
                    std::to_string(field.values.size()));
    v.values.allocate(ScalarType::F64, count, false);  // every voxel is written below
    double* out = v.values.data<double>();
    // Each voxel depends on its indices alone, so the slices are filled in parallel (TBB, in the
    // caller's arena: render_scene's --threads) and the volume is the same bits for any thread count.
    const Volume& grid = v;
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, v.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
        for (std::int64_t k = r.begin(); k != r.end(); ++k)
            for (std::int64_t j = 0; j < grid.dims[1]; ++j)
                for (std::int64_t i = 0; i < grid.dims[0]; ++i)
                    out[grid.index(i, j, k)] = field_value(field, grid, position(i, j, k), i, j, k);
    });
    return v;
}

Volume make_procedural_brick(const FieldSpec& field, const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims) {
    Volume whole;  // the whole grid's dims (indices of marschner-lobb and cells); no values
    whole.dims = field.dims;
    if (field.kind == FieldSpec::Kind::Cells &&
        field.values.size() != std::size_t(whole.dims[0]) * std::size_t(whole.dims[1]) * std::size_t(whole.dims[2]))
        throw Error("volume.source.values: expected " + std::to_string(whole.dims[0] * whole.dims[1] * whole.dims[2]) +
                    " values (dims product), got " + std::to_string(field.values.size()));
    Volume v;
    v.dims = dims;
    v.type = ScalarType::F64;
    v.origin = origin + glm::dvec3(double(lo[0]), double(lo[1]), double(lo[2])) * spacing;
    v.spacing = spacing;
    const std::size_t count = checked_voxel_count(v.dims, "volume.source.dims (this rank's brick)");
    v.values.allocate(ScalarType::F64, count, false);
    double* out = v.values.data<double>();
    const Volume& grid = v;
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, v.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
        for (std::int64_t k = r.begin(); k != r.end(); ++k)
            for (std::int64_t j = 0; j < grid.dims[1]; ++j)
                for (std::int64_t i = 0; i < grid.dims[0]; ++i) {
                    const std::int64_t gi = i + lo[0], gj = j + lo[1], gk = k + lo[2];
                    const glm::dvec3 p = origin + glm::dvec3(double(gi), double(gj), double(gk)) * spacing;
                    out[grid.index(i, j, k)] = field_value(field, whole, p, gi, gj, gk);
                }
    });
    return v;
}

}  // namespace volref
