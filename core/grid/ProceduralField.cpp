#include "core/grid/ProceduralField.h"

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Cancellation.h"
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

namespace {

// A `cells` field lists one value per voxel of the whole grid (field.dims, `whole_count` voxels).
void check_cell_values(const FieldSpec& field, std::size_t whole_count) {
    if (field.kind == FieldSpec::Kind::Cells && field.values.size() != whole_count)
        throw Error("volume.source.values: expected " + std::to_string(whole_count) + " values (dims product), got " +
                    std::to_string(field.values.size()));
}

// Fills v (its dims set, `count` = their checked product) with the field at the whole grid's voxels
// lo + (i, j, k), placed at position(gi, gj, gk). Each voxel depends on its indices alone, so the slices are filled in parallel
// (TBB, in the caller's arena: render_scene's --threads) and the volume is the same bits for any
// thread count.
void fill_field(const FieldSpec& field, Volume& v, const std::array<std::int64_t, 3>& lo,
                const std::function<glm::dvec3(std::int64_t, std::int64_t, std::int64_t)>& position,
                std::size_t count) {
    Volume whole;  // the whole grid's dims (the indices of marschner-lobb and cells); no values
    whole.dims = field.dims;
    v.type = ScalarType::F64;
    v.values.allocate(ScalarType::F64, count, false);  // every voxel is written below
    double* out = v.values.data<double>();
    const Volume& grid = v;
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, v.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
        for (std::int64_t k = r.begin(); k != r.end(); ++k)
            for (std::int64_t j = 0; j < grid.dims[1]; ++j) {
                if (cancel_requested()) return;  // SIGINT / SIGTERM: polled per row, thrown below
                for (std::int64_t i = 0; i < grid.dims[0]; ++i) {
                    const std::int64_t gi = i + lo[0], gj = j + lo[1], gk = k + lo[2];
                    out[grid.index(i, j, k)] = field_value(field, whole, position(gi, gj, gk), gi, gj, gk);
                }
            }
    });
    throw_if_cancelled();
}

}  // namespace

Volume make_procedural_volume(const FieldSpec& field,
                              const std::function<glm::dvec3(std::int64_t, std::int64_t, std::int64_t)>& position) {
    Volume v;
    v.dims = field.dims;
    const std::size_t count = checked_voxel_count(v.dims, "volume.source.dims");
    check_cell_values(field, count);
    fill_field(field, v, {0, 0, 0}, position, count);
    return v;
}

Volume make_procedural_brick(const FieldSpec& field, const glm::dvec3& origin, const glm::dvec3& spacing,
                             const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims) {
    check_cell_values(field, std::size_t(field.dims[0]) * std::size_t(field.dims[1]) * std::size_t(field.dims[2]));
    Volume v;
    v.dims = dims;
    v.origin = origin + glm::dvec3(double(lo[0]), double(lo[1]), double(lo[2])) * spacing;
    v.spacing = spacing;
    fill_field(field, v, lo, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        return origin + glm::dvec3(double(i), double(j), double(k)) * spacing;
    }, checked_voxel_count(v.dims, "volume.source.dims (this rank's brick)"));
    return v;
}

}  // namespace volref
