#include "core/integrate/packet/FastProfile.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/sample/MacrocellGrid.h"
#include "transfer/TransferFunction.h"

namespace volref {

namespace {

std::vector<float> to_float(const double* p, std::size_t n) {
    std::vector<float> out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = float(p[i]);
    return out;
}

}  // namespace

[[noreturn]] void fast_profile_unavailable(const std::string& reason) {
    throw Error("render.profile: \"fast\" runs composite (front to back), mip and minip on Cartesian trilinear "
                "grids classified by a transfer function; " + reason + " (use \"reference\")");
}

[[noreturn]] void fast_profile_not_traced() {
    throw Error("trace: the fast profile is not traced (its float packets are its only path); trace with "
                "render.profile \"reference\"");
}

namespace {

void fast_voxels(const Volume& volume, VolumeViewStore& copies, GridView& grid) {
    const ScalarType t = volume.values.type();
    const std::size_t n = volume.values.size();
    const bool gathered32 = t == ScalarType::F32 || t == ScalarType::I32 || t == ScalarType::U32 ||
                            t == ScalarType::U16 || t == ScalarType::I16 || t == ScalarType::U8 || t == ScalarType::I8;
    constexpr std::uint64_t kLimit = (std::uint64_t(1) << 31) - 64;  // PacketTrilinear's 32-bit offsets
    if (gathered32 && std::endian::native == std::endian::little && std::uint64_t(volume.values.bytes()) < kLimit) {
        grid.voxels = volume.values.raw();
        grid.voxel_type = t;
        return;
    }
    if (std::uint64_t(n) * 4 >= kLimit)
        fast_profile_unavailable("the volume's " + std::to_string(n) + " voxels are too many for its 32-bit indices");
    // Held: the volume itself; allocated: its float copy.
    check_memory(volume.values.bytes() + n * sizeof(float), "render.profile: the fast profile's float copy of the voxels");
    copies.voxels.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        copies.voxels[i] = float(volume.values[i]);
        if (!std::isfinite(copies.voxels[i]))
            fast_profile_unavailable("voxel " + std::to_string(i) + " (" + std::to_string(volume.values[i]) +
                                     ") is beyond float's range");
    }
    grid.voxels = copies.voxels.data();
    grid.voxel_type = ScalarType::F32;
}

}  // namespace

void describe_float_lanes(VolumeView& view, bool composite, VolumeViewStore& copies) {
    const Volume& volume = *view.volume;
    if (!composite) return fast_voxels(volume, copies, view.grid_float);
    const TransferRows<double>& td = view.rows;
    copies.color_x = to_float(td.color_x, std::size_t(view.color_rows));
    copies.color_y = to_float(td.color_y, std::size_t(view.color_rows) * 3);  // r, g, b per row
    copies.opacity_x = to_float(td.opacity_x, std::size_t(view.opacity_rows));
    copies.opacity_y = to_float(td.opacity_y, std::size_t(view.opacity_rows));
    TransferRows<float>& tf = view.rows_float;
    tf.color_x = copies.color_x.data();
    tf.color_y = copies.color_y.data();
    tf.opacity_x = copies.opacity_x.data();
    tf.opacity_y = copies.opacity_y.data();
    if (view.gradient_opacity_rows > 0) {
        copies.gradient_opacity_x = to_float(td.gradient_opacity_x, std::size_t(view.gradient_opacity_rows));
        copies.gradient_opacity_y = to_float(td.gradient_opacity_y, std::size_t(view.gradient_opacity_rows));
        tf.gradient_opacity_x = copies.gradient_opacity_x.data();
        tf.gradient_opacity_y = copies.gradient_opacity_y.data();
    }
    fast_voxels(volume, copies, view.grid_float);
    if (view.gradient == VolumeView::Gradient::Cached) {
        // Held: the volume, its f64 gradient cache and any float voxels; allocated: the float cache.
        check_memory(volume.values.bytes() + 3 * volume.values.size() * (sizeof(double) + sizeof(float)) +
                         copies.voxels.size() * sizeof(float),
                     "render.profile: the fast profile's float gradient cache");
        for (int a = 0; a < 3; ++a) {
            const double* c = static_cast<const double*>(td.cached_gradient[a]);
            copies.cached_gradient[a] = to_float(c, volume.values.size());
            tf.cached_gradient[a] = copies.cached_gradient[a].data();
        }
    }
}

Termination fast_termination(Termination t) {
    t.test_transmittance = true;
    t.transmittance_at_most = conventions::kFastTransmittanceCutoff;
    return t;
}

void make_preintegrated(VolumeView& in, double step, int n, VolumeViewStore& copies) {
    const TransferFunction& tf = *in.transfer_function;
    const Volume& volume = *in.volume;
    auto refuse = [](const std::string& why) {
        throw Error("render.profile_options.preintegration: pre-integrated segments " + why +
                    " (remove preintegration, or use render.profile \"reference\")");
    };
    if (in.shaded) refuse("do not shade (the table integrates the transfer function of the value alone)");
    if (in.gradient_opacity_rows > 0) refuse("do not take gradient-magnitude opacity");
    // Every coordinate a sample can take: the trilinear field stays within the voxels' range; the rows
    // beyond it are included so that the table's ends are the transfer function's.
    const std::array<double, 2> range = volume.value_range();
    double lo = std::min(tf.coordinate(range[0]), tf.coordinate(range[1]));
    double hi = std::max(tf.coordinate(range[0]), tf.coordinate(range[1]));
    for (const auto* xs : {&tf.opacity_function().xs(), &tf.color_function().xs()})
        if (!xs->empty()) {
            lo = std::min(lo, xs->front());
            hi = std::max(hi, xs->back());
        }
    const std::size_t entries = (std::size_t(n) + 1) * (std::size_t(n) + 1) * 4;
    check_memory(entries * sizeof(float), "render.profile_options.preintegration: the pre-integration table");
    copies.preintegration = build_preintegration_table(tf, lo, hi, step, n);
    const PreIntegrationTable& t = copies.preintegration;
    in.preintegration = t.entries.data();
    in.pre_n = t.n;
    in.pre_x0 = t.x0;
    in.pre_inv_dx = 1.0 / t.dx;
    // Empty space is skipped only where a segment's ends lie in empty macrocells too (VectorSkip's
    // end_margin, PacketComposite.cpp).
}

}  // namespace volref
