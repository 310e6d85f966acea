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
#include "core/integrate/packet/PacketRun.h"
#include "core/sample/VolumeView.h"
#include "geometry/RayIntervals.h"

namespace volref {

struct RayExtremum {
    bool any = false;      // the ray had at least one sample
    double value = 0.0;    // the extremum
    double t = 0.0;        // the midpoint where it was first reached
};

// The maximum (mip) or minimum (minip) of the volume `view` describes (VolumeView.h) along each ray, with
// `run`'s step, skipping (null: none; macrocells whose values cannot beat a ray's extremum so far are
// passed over, SegmentWalk.h's extremum mode: the result is bitwise the same) and lanes (the fast
// profile's float lanes read the view's float voxels). `spans` (march/RaySpan.h; null: the whole rays):
// each lane's extremum over the samples its span owns.
void extremum_packet(const VolumeView& view, const PacketRun& run, bool maximum, const Ray* rays, const std::vector<Interval>* intervals,
                     RayExtremum* out, int count, const RaySpan* spans = nullptr);

}  // namespace volref
