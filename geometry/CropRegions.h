// Cropping with VTK's 27 regions (scene key volume.crop; conventions section 4). The planes
// x0 <= x1, y0 <= y1, z0 <= z1 (the volume's own coordinates) split each axis into three ranges,
// below (0), between inclusive (1) and above (2); region (ix, iy, iz) has number ix + 3 iy + 9 iz and
// is kept when bit number of the flags is set (vtkVolumeMapper::CroppingRegionFlags; VTK_CROP_SUBVOLUME
// = 0x0002000 keeps region 13, the box [x0, x1] x [y0, y1] x [z0, z1]).
//
// Along a (local) ray the crossings t = (c - o_a) / d_a of the six planes split each interval; each
// piece lies in one region (decided at its midpoint) and is kept or dropped whole, so the intervals
// are cut exactly at the planes. Adjacent kept pieces merge.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/scene/Scene.h"
#include "geometry/RayIntervals.h"

namespace volref {

// The region number (0 .. 26) of a point in the crop's coordinates.
int crop_region(const CropSpec& crop, const glm::dvec3& p);
// True when the point's region is kept.
inline bool crop_keeps(const CropSpec& crop, const glm::dvec3& p) { return (crop.regions >> crop_region(crop, p)) & 1u; }

// Cuts `intervals` (sorted, disjoint; of `ray`, in the crop's coordinates) to the kept regions, in place.
void crop_intervals(const Ray& ray, const CropSpec& crop, std::vector<Interval>& intervals);

}  // namespace volref
