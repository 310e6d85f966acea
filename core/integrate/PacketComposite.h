// The SIMD path of front-to-back compositing (Google Highway, dispatched at run time to the best
// instruction set: AVX-512 = 8 rays per vector, AVX2 = 4, SSE4 = 2).
//
// Rays travel in structure-of-arrays packets; each lane walks its own intervals and segments (the
// placement of Segments.h), and a mask retires lanes whose ray has ended, become opaque or reached
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
// It serves the common case: composite, front to back, trilinear, post-classification by a transfer
// function without gradient opacity, unshaded. Everything else takes the scalar path. Each lane
// walks its segments with ForwardSegmentWalk (SegmentWalk.h), so empty-space skipping passes over
// the same segments as in the scalar path.
#pragma once
#include <cstdint>
#include <vector>

#include "core/camera/Ray.h"
#include "core/integrate/Integrator.h"
#include "geometry/RayIntervals.h"

namespace volref {

class MacrocellGrid;

// Everything the kernel reads, as plain arrays.
struct PacketCompositeInputs {
    const double* voxels = nullptr;  // the volume's values, i fastest
    std::int64_t dims[3] = {1, 1, 1};
    double origin[3] = {0, 0, 0}, inv_spacing[3] = {1, 1, 1};
    bool normalized = false;  // transfer coordinate (v - lo) * inv_width, else v
    double lo = 0.0, inv_width = 1.0;
    const double* color_x = nullptr;  // color rows: x sorted, y = r, g, b per row
    const double* color_y = nullptr;
    int color_rows = 0;
    const double* opacity_x = nullptr;  // opacity rows
    const double* opacity_y = nullptr;
    int opacity_rows = 0;
    double unit_distance = 1.0;
    double step = 1.0;
    bool terminate = false;  // early termination at alpha > threshold
    double threshold = 1.0;
    const MacrocellGrid* macrocells = nullptr;  // empty-space skipping (SegmentWalk.h), or none
};

// Composites `count` (<= kMaxPacketRays) rays front to back into out[0 .. count).
void composite_packet(const PacketCompositeInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                      PixelValue* out, int count);

}  // namespace volref
