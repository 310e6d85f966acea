// The SIMD path of front-to-back compositing (Google Highway, dispatched at run time to the best
// instruction set: AVX-512 = 8 rays per vector, AVX2 = 4, SSE4 = 2).
//
// Rays travel in structure-of-arrays packets; each lane walks its own intervals and segments (the
// placement of SamplePlacement.h), and a mask retires lanes whose ray has ended, become opaque or reached
// early termination. Every step is the scalar CompositeIntegrator's arithmetic in the same order:
// the position origin + t direction, the continuous index, Levoy's trilinear sum term by term, the
// piecewise-linear transfer function (first row with x > v), the optical depth
// -(d / l) log1p(-a), alpha = -expm1(-tau_k), C += (exp(-tau) alpha) c and the Neumaier sum of tau,
// all in double, without fused multiply-adds. The only difference is that exp, expm1 and log1p are
// Highway's vector versions (at most 1, 4 and 2 ulp from the correctly rounded value, against
// glibc's < 1 ulp), so a pixel differs from the scalar path by a few ulp of its exp/log terms:
// below 1e-13 absolute in tests, far inside the 1e-6 the reference contract allows. A lane's result
// does not depend on the other lanes, the packet size or the instruction set (AVX2 and AVX-512 use
// the same polynomials with the same fused operations inside them).
//
// Gradients (GradientField.h) follow the scalar scheme exactly: central or forward differences of
// the same trilinear field (with its one-sided differences at the domain boundary), or the trilinear
// interpolation of the cached per-voxel gradients. Gradient-magnitude opacity multiplies and clamps
// as TransferFunction::classify. Shading (Shader.h) repeats Shader::shade operation by operation
// (glm's dot = (x x' + y y') + z z', length = sqrt(dot), normalize = v (1 / sqrt(dot))), except
// that the specular power s^n is exp(n log s) with Highway's exp and log instead of std::pow: a
// relative difference of a few ulp times (1 + n |log s|), below 1e-13 absolute for colours <= 1.
//
// It serves composite, front to back, trilinear, post-classification by a transfer function (with
// or without gradient opacity), unshaded or shaded (Blinn-Phong, Phong, nodal; up to
// kMaxPacketLights lights) with central, forward or cached gradients. Everything else (back to
// front, tricubic or nearest, pre-classification, Levoy's classifiers, shells) takes the scalar
// path. Each lane walks its segments with ForwardSegmentWalk (SegmentWalk.h), so empty-space
// skipping passes over the same segments as in the scalar path.
//
// The fast profile (render.profile "fast", FastProfile.h) runs the same kernel on float lanes (twice
// as many rays per vector): positions, reconstruction, transfer function, gradients and shading in
// float, the tables and voxels as float copies where needed; compositing keeps the transmittance as
// a float product, Tr *= 1 - alpha with alpha = -expm1((d / l) log1p(-a)), C += Tr alpha c, and stops
// a ray once Tr <= kFastTransmittanceCutoff (termination.transmittance_at_most).
#pragma once
#include <cstdint>
#include <vector>

#include "core/camera/Ray.h"
#include "core/grid/VoxelArray.h"
#include "core/integrate/packet/PacketGrid.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/march/Accumulators.h"
#include "geometry/RayIntervals.h"

namespace volref {

class MacrocellGrid;

// The kernel's tables in its lane type T (double: the classifier's own rows; float: copies).
template <typename T>
struct PacketTables {
    const T* color_x = nullptr;  // color rows: x sorted, y = r, g, b per row
    const T* color_y = nullptr;
    const T* opacity_x = nullptr;  // opacity rows
    const T* opacity_y = nullptr;
    const T* gradient_opacity_x = nullptr;  // gradient-magnitude opacity rows [|grad f|, factor]
    const T* gradient_opacity_y = nullptr;
    const void* cached_gradient[3] = {nullptr, nullptr, nullptr};  // Cached: per-voxel components (T)
};

// Everything the kernel reads, as plain arrays.
struct PacketCompositeInputs {
    PacketGrid grid;  // the volume's values, dims, origin and 1 / spacing (PacketGrid.h)
    bool normalized = false;  // transfer coordinate (v - lo) * inv_width, else v
    double lo = 0.0, inv_width = 1.0;
    PacketTables<double> tables_double;  // the reference profile's
    PacketTables<float> tables_float;    // the fast profile's
    template <typename T>
    const PacketTables<T>& tables() const {
        if constexpr (sizeof(T) == sizeof(double)) return tables_double;
        else return tables_float;
    }
    int color_rows = 0;
    int opacity_rows = 0;
    double unit_distance = 1.0;
    double step = 1.0;
    Termination termination;  // early termination (and the fast profile's cutoff: march/Accumulators.h)
    const MacrocellGrid* macrocells = nullptr;  // empty-space skipping (SegmentWalk.h), or none
    bool fast = false;         // the fast profile: float lanes (voxels: 32-bit-gathered types only)

    int gradient_opacity_rows = 0;  // gradient-magnitude opacity rows, or none (0)

    // Gradients, when shading or gradient opacity needs them (GradientField.h).
    enum class Gradient { None, Central, Forward, Cached };
    Gradient gradient = Gradient::None;
    double spacing[3] = {1, 1, 1};
    double domain_lo[3] = {0, 0, 0}, domain_hi[3] = {0, 0, 0};

    // Shading (Shader.h), when `shaded`.
    static constexpr int kMaxPacketLights = 8;
    struct Light {
        bool headlight = true;
        double direction[3] = {0, 0, 1};  // towards the light (directional)
        double color[3] = {1, 1, 1};
    };
    bool shaded = false;
    bool phong = false;      // R.V instead of N.H
    bool two_sided = false;
    double ka = 0, kd = 0, ks = 0, n = 1, kc = 1, kl = 0;
    double zero_gradient_tolerance = 0;
    int light_count = 0;
    Light lights[kMaxPacketLights];

    // The fast profile's pre-integrated segments (FastProfile.h, transfer/PreIntegration.h): the table's
    // entries (4 floats per node pair), its n + 1 nodes per axis at pre_x0 + i / pre_inv_dx; null: off.
    const float* preintegration = nullptr;
    int pre_n = 0;
    double pre_x0 = 0.0, pre_inv_dx = 1.0;
    // Skipping decided on the lanes (PacketKernels-inl.h, VectorSkip): per octant of ray directions and
    // macrocell, the empty distance ahead where it is empty, else minus the solid distance ahead
    // (MacrocellGrid::octant_radii, held by CompositeIntegrator);
    // null: no skipping.
    const std::int32_t* skip_radius = nullptr;
};

// Composites `count` (<= kMaxPacketRays) rays front to back into out[0 .. count). With `states`
// (the reference's double lanes only; march/RaySpan.h), instead resumes states[i] over the samples
// spans[i] owns and writes nothing to `out`.
void composite_packet(const PacketCompositeInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                      PixelValue* out, int count, const RaySpan* spans = nullptr, RayState* states = nullptr);

}  // namespace volref
