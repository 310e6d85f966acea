// VolumeView: one plain description of what a volume's sample reads, built once per volume
// (PreparedVolume) and read by every path: the scalar stages it points to (the sampler, the shell's grid,
// the transfer function, the gradient field: explain, the mirrors and the scalar loops ask for them
// here) and the same data as plain arrays for the SIMD packet kernels (the grid's voxels, the transfer
// function's rows, the gradient scheme, the shading constants and lights, the pre-integration table, the
// skipping radii). Nothing here is copied per integrator: the kernels and the scalar stages read one
// description, the Open VKL shape (one shared struct read by uniform and varying code).
//
// The float lanes of the fast profile (FastProfile.h) read the `_float` members: the same rows and
// voxels as float, copies held by VolumeViewStore where the volume's own storage does not serve.
#pragma once
#include <cstdint>
#include <vector>

#include "core/grid/Volume.h"
#include "core/grid/VoxelArray.h"
#include "core/scene/Scene.h"
#include "transfer/PreIntegration.h"

namespace volref {

class GradientField;
class MacrocellGrid;
class Shader;
class ShellGrid;
class TransferFunction;
class VolumeSampler;

// A Cartesian grid as plain arrays: the values in their storage type (i fastest), the dims, the origin
// and 1 / spacing per axis.
struct GridView {
    const void* voxels = nullptr;
    ScalarType voxel_type = ScalarType::F64;
    std::int64_t dims[3] = {1, 1, 1};
    double origin[3] = {0, 0, 0}, inv_spacing[3] = {1, 1, 1};
    static GridView of(const Volume& v);
};

// The transfer function's rows in a lane type T (double: the classifier's own rows; float: copies).
template <typename T>
struct TransferRows {
    const T* color_x = nullptr;  // color rows: x sorted, y = r, g, b per row
    const T* color_y = nullptr;
    const T* opacity_x = nullptr;  // opacity rows
    const T* opacity_y = nullptr;
    const T* gradient_opacity_x = nullptr;  // gradient-magnitude opacity rows [|grad f|, factor]
    const T* gradient_opacity_y = nullptr;
    const void* cached_gradient[3] = {nullptr, nullptr, nullptr};  // Gradient::Cached: per-voxel components (T)
};

struct VolumeView {
    // --- the scalar stages (null where the scene uses another kind) ----------------------------------
    const Volume* volume = nullptr;
    const VolumeSampler* cartesian = nullptr;             // a Cartesian grid's sampler (null for shells)
    const ShellGrid* shell_grid = nullptr;                 // a shell's beam-space grid
    const TransferFunction* transfer_function = nullptr;  // null for Levoy's classifiers
    const GradientField* grid_gradient = nullptr;          // the Cartesian grid's gradients, when used
    const Shader* shader = nullptr;                        // null: unshaded
    bool preclassified = false;
    Interpolation interpolation = Interpolation::Trilinear;

    // --- the grid ------------------------------------------------------------------------------------
    GridView grid;        // the volume's own voxels (Cartesian)
    GridView grid_float;  // the float lanes' voxels: the grid's own where 32-bit gathered, else a float copy
    template <typename T>
    const GridView& grid_of() const {
        if constexpr (sizeof(T) == sizeof(double)) return grid;
        else return grid_float;
    }

    // --- the transfer function (a TransferFunction classifies) ---------------------------------------
    bool normalized = false;  // transfer coordinate (v - lo) * inv_width, else v
    double lo = 0.0, inv_width = 1.0;
    TransferRows<double> rows;
    TransferRows<float> rows_float;
    template <typename T>
    const TransferRows<T>& rows_of() const {
        if constexpr (sizeof(T) == sizeof(double)) return rows;
        else return rows_float;
    }
    int color_rows = 0;
    int opacity_rows = 0;
    int gradient_opacity_rows = 0;  // gradient-magnitude opacity rows, or none (0)
    double unit_distance = 1.0;

    // --- gradients, when shading or gradient opacity needs them (GradientField.h) ----------------------
    enum class Gradient { None, Central, Forward, Cached };
    Gradient gradient = Gradient::None;
    double spacing[3] = {1, 1, 1};
    double domain_lo[3] = {0, 0, 0}, domain_hi[3] = {0, 0, 0};

    // --- shading (Shader.h), when `shaded` ------------------------------------------------------------
    static constexpr int kMaxPacketLights = 8;
    struct Light {
        bool headlight = true;
        double direction[3] = {0, 0, 1};  // towards the light (directional)
        double color[3] = {1, 1, 1};
    };
    bool shaded = false;
    bool phong = false;  // R.V instead of N.H
    bool two_sided = false;
    double ka = 0, kd = 0, ks = 0, n = 1, kc = 1, kl = 0;
    double zero_gradient_tolerance = 0;
    int light_count = 0;
    Light lights[kMaxPacketLights];

    // What the composite kernel does not take of the gradient or the shading (its reason), or null.
    const char* composite_unavailable = nullptr;

    // --- the fast profile's pre-integrated segments (FastProfile.h, transfer/PreIntegration.h) ---------
    // The table's entries (4 floats per node pair), its n + 1 nodes per axis at pre_x0 + i / pre_inv_dx;
    // null: off.
    const float* preintegration = nullptr;
    int pre_n = 0;
    double pre_x0 = 0.0, pre_inv_dx = 1.0;

    // --- empty-space skipping of the composite packets ------------------------------------------------
    // Per octant of ray directions and macrocell, the empty distance ahead where it is empty, else minus
    // the solid distance ahead (MacrocellGrid::octant_radii); null: none.
    const std::int32_t* skip_radius = nullptr;

    // Why the SIMD packet path does not apply to this volume (the reason the fast profile's error gives),
    // or null when it does: a Cartesian grid, trilinear, every voxel finite (non-finite voxels take the
    // scalar path, which makes them transparent or ignores them: docs/accuracy.md), and for compositing
    // also a transfer function, post-classification, front-to-back order, a gradient the kernels take
    // and at most kMaxPacketLights lights. The checks in this order.
    const char* packet_unavailable(bool composite, CompositeOrder order) const;
    // Every voxel finite: scanned on the first ask and kept (set-up asks from one thread).
    bool finite_voxels() const;

private:
    mutable signed char finite_ = -1;  // -1: not scanned yet
};

// What a view holds that the volume and its stages do not: the float lanes' copies, the
// pre-integration table, the skipping radii. Kept beside the view (PreparedVolume) for its lifetime.
struct VolumeViewStore {
    std::vector<float> voxels;  // empty when the volume's own storage serves the float lanes
    std::vector<float> color_x, color_y, opacity_x, opacity_y, gradient_opacity_x, gradient_opacity_y;
    std::vector<float> cached_gradient[3];
    PreIntegrationTable preintegration;
    std::vector<std::int32_t> skip_radius;
};

// The view of a volume's stages (any may be null but `volume`): the grid, the transfer function's
// rows, the gradient scheme and the shading constants. The float lanes, the pre-integration table and
// the skipping radii are added by their owners (FastProfile.h; describe_skipping).
VolumeView describe_volume(const Volume& volume, const VolumeSampler* cartesian, const ShellGrid* shell_grid,
                           const TransferFunction* transfer_function, const GradientField* grid_gradient,
                           const Shader* shader, bool preclassified);

// The composite packets' skipping radii of `macrocells` (MacrocellGrid::octant_radii), held by `store`.
void describe_skipping(VolumeView& view, const MacrocellGrid& macrocells, VolumeViewStore& store);

}  // namespace volref
