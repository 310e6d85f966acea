// The SIMD path of mip and minip (Google Highway, run-time dispatch): the extremum of the trilinear
// value over each ray's segment midpoints, a packet of rays at a time, with the same comparisons
// as ExtremumIntegrator (the first of equal extrema wins). Only reconstruction and comparison are
// vectorised, with the scalar path's arithmetic (no transcendental), so the result is bitwise the
// scalar one; the classification at the extremum stays scalar (one per ray).
#pragma once
#include <cstdint>
#include <vector>

#include "core/camera/Ray.h"
#include "core/grid/VoxelArray.h"
#include "core/integrate/march/RaySpan.h"
#include "core/integrate/packet/PacketGrid.h"
#include "geometry/RayIntervals.h"

namespace volref {

class MacrocellGrid;

struct PacketExtremumInputs {
    PacketGrid grid;  // the volume's values, dims, origin and 1 / spacing (PacketGrid.h)
    double step = 1.0;
    bool maximum = true;
    // Skipping (null: none): macrocells whose values cannot beat a ray's extremum so far are passed
    // over (SegmentWalk.h, extremum mode); the result is bitwise the same.
    const MacrocellGrid* macrocells = nullptr;
    // The fast profile (FastProfile.h): float lanes; the voxels a 32-bit-gathered type.
    bool fast = false;
};

struct RayExtremum {
    bool any = false;      // the ray had at least one sample
    double value = 0.0;    // the extremum
    double t = 0.0;        // the midpoint where it was first reached
};

// `spans` (march/RaySpan.h; null: the whole rays): each lane's extremum over the samples its span owns.
void extremum_packet(const PacketExtremumInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                     RayExtremum* out, int count, const RaySpan* spans = nullptr);

}  // namespace volref
