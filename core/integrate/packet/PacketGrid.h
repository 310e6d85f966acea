// What the SIMD packet kernels (PacketComposite, PacketExtremum) read of a volume, and when they apply.
#pragma once
#include <cstdint>

#include "core/grid/Volume.h"
#include "core/grid/VoxelArray.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/scene/Scene.h"

namespace volref {

// The Cartesian grid as plain arrays: the values in their storage type (i fastest), the dims, the
// origin and 1 / spacing per axis.
struct PacketGrid {
    const void* voxels = nullptr;
    ScalarType voxel_type = ScalarType::F64;
    std::int64_t dims[3] = {1, 1, 1};
    double origin[3] = {0, 0, 0}, inv_spacing[3] = {1, 1, 1};

    static PacketGrid of(const Volume& v) {
        PacketGrid g;
        g.voxels = v.values.raw();
        g.voxel_type = v.values.type();
        for (int a = 0; a < 3; ++a) {
            g.dims[a] = v.dims[a];
            g.origin[a] = v.origin[a];
            g.inv_spacing[a] = 1.0 / v.spacing[a];
        }
        return g;
    }
};

// Why the packet path does not apply to this volume (the reason the fast profile's error gives),
// or null when it does: a Cartesian grid, trilinear, every voxel finite (non-finite voxels take the
// scalar path, which makes them transparent or ignores them: docs/accuracy.md), and for compositing
// also a transfer function, post-classification and front-to-back order. The checks in this order.
inline const char* packet_path_unavailable(const SamplePipeline& p, bool composite, CompositeOrder order) {
    const VolumeSampler* sampler = p.cartesian_sampler();
    if (composite && !p.stages().transfer_function) return "this volume is classified otherwise";
    if (!sampler) return "this volume is not on a Cartesian grid";
    if (composite && p.preclassified()) return "this volume is pre-classified";
    if (sampler->interpolation() != Interpolation::Trilinear) return "this volume is not trilinear";
    if (composite && order != CompositeOrder::FrontToBack) return "this scene composites back to front";
    if (!all_finite(sampler->volume().values)) return "this volume has non-finite voxels";
    return nullptr;
}

}  // namespace volref
