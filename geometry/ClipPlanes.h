// Clip planes (scene key volume.clip_planes; conventions section 4): each plane keeps the half-space
// (x - point) . normal >= 0 of world space, as VTK's clipping planes do. Along a ray x(t) = o + t d
// the kept set is {t : f0 + t f1 >= 0} with f0 = (o - point) . normal and f1 = d . normal:
//   f1 > 0: t >= t* = -f0 / f1;   f1 < 0: t <= t*;   f1 = 0: every t when f0 >= 0, none otherwise.
// The ray's intervals are cut exactly at t* (no sample is discarded: the segments are placed in the
// cut intervals).
#pragma once
#include <vector>

#include "core/camera/Ray.h"
#include "core/scene/Scene.h"
#include "geometry/RayIntervals.h"

namespace volref {

// Intersects `intervals` (sorted, disjoint) with the kept side of every plane, in place.
void clip_intervals(const Ray& ray, const std::vector<ClipPlaneSpec>& planes, std::vector<Interval>& intervals);

}  // namespace volref
