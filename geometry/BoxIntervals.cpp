// The intervals of a packet of rays in a box shape (BoundingGeometry's boxes): BoxIntersection-inl.h's
// formula on SIMD lanes (SimdLanes<double>), the same intervals as box_interval ray by ray. Highway's
// per-target compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "geometry/BoxIntervals.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include <algorithm>
#include <limits>
#include <vector>

#include "core/SimdLanes-inl.h"
#include "geometry/BoxIntervals.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {

#include "geometry/BoxIntersection-inl.h"

void BoxShapeIntervals(const BoxShapeBounds& box, const Ray* rays, int count, std::vector<Interval>* out) {
    using L = SimdLanes<double>;
    const L::D d;
    const std::size_t n = hn::Lanes(d);
    HWY_ALIGN double o[3][hn::MaxLanes(L::D())], dir[3][hn::MaxLanes(L::D())], t0[hn::MaxLanes(L::D())],
        t1[hn::MaxLanes(L::D())];
    for (int first = 0; first < count; first += int(n)) {
        const int m = std::min(int(n), count - first);
        for (std::size_t l = 0; l < n; ++l) {  // the last ray repeated past the end
            const Ray& r = rays[first + std::min(int(l), m - 1)];
            for (int a = 0; a < 3; ++a) {
                o[a][l] = r.origin[a];
                dir[a][l] = r.direction[a];
            }
        }
        const L::V O[3] = {hn::Load(d, o[0]), hn::Load(d, o[1]), hn::Load(d, o[2])};
        const L::V Dir[3] = {hn::Load(d, dir[0]), hn::Load(d, dir[1]), hn::Load(d, dir[2])};
        L::V T0, T1;
        const L::M hit = box_shape_lanes<L>(O, Dir, box.lo, box.hi, box.is_domain ? nullptr : box.domain_lo,
                                            box.is_domain ? nullptr : box.domain_hi, T0, T1);
        hn::Store(T0, d, t0);
        hn::Store(hn::IfThenElse(hit, T1, hn::Set(d, -std::numeric_limits<double>::infinity())), d, t1);
        for (int l = 0; l < m; ++l)
            if (t1[l] != -std::numeric_limits<double>::infinity()) out[first + l].push_back(Interval{t0[l], t1[l]});
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace volref {
HWY_EXPORT(BoxShapeIntervals);

void box_shape_intervals(const BoxShapeBounds& box, const Ray* rays, int count, std::vector<Interval>* out) {
    HWY_DYNAMIC_DISPATCH(BoxShapeIntervals)(box, rays, count, out);
}
}  // namespace volref
#endif
