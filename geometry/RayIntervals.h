// RayIntervals: the parts of a ray inside a volume's bounding geometry and domain, as sorted,
// disjoint [t0, t1] pairs (t in world units along the unit ray direction, t >= 0).
#pragma once
#include <algorithm>
#include <vector>

namespace volref {

struct Interval {
    double t0 = 0.0, t1 = 0.0;
    double length() const { return t1 - t0; }
};

// Sorts `intervals` by t0 and merges those that overlap or touch, so that every point of the ray is
// counted once; intervals of length <= 0 are dropped.
inline void normalize_intervals(std::vector<Interval>& intervals) {
    std::erase_if(intervals, [](const Interval& i) { return !(i.t1 > i.t0); });
    std::sort(intervals.begin(), intervals.end(), [](const Interval& a, const Interval& b) {
        return a.t0 < b.t0 || (a.t0 == b.t0 && a.t1 < b.t1);
    });
    std::size_t out = 0;
    for (std::size_t k = 0; k < intervals.size(); ++k) {
        if (out > 0 && intervals[k].t0 <= intervals[out - 1].t1)
            intervals[out - 1].t1 = std::max(intervals[out - 1].t1, intervals[k].t1);
        else
            intervals[out++] = intervals[k];
    }
    intervals.resize(out);
}

}  // namespace volref
