// Sample placement on a ray's interval list, every rule in one place (conventions sections 4 and 9).
// The reference: an interval [t0, t1] of length L is cut into n = max(1, ceil(L / h - kSegmentSlack))
// segments of length h, the last one shorter (L - (n - 1) h); each segment is sampled at its midpoint
// and weighted by its own length (segment_count, segment; SegmentWalk.h walks them with skipping).
// From the entry (GPU shaders, Profile::Placement::FromEntry): t0 + (first + k) h for k = 0 .. n - 1,
// n = max(1, floor(L / h + 1 - first)), each standing for h (from_entry_count, from_entry_sample).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/Conventions.h"
#include "geometry/RayIntervals.h"

namespace volref {

struct Segment {
    double t0, t1;
    double midpoint() const { return 0.5 * (t0 + t1); }
    double length() const { return t1 - t0; }
};

inline std::int64_t segment_count(const Interval& iv, double step) {
    const double n = std::ceil(iv.length() / step - conventions::kSegmentSlack);
    return std::max<std::int64_t>(1, std::int64_t(n));
}

// Segment k of n: [t0 + k h, t0 + (k + 1) h], the last ending exactly at t1.
inline Segment segment(const Interval& iv, double step, std::int64_t k, std::int64_t n) {
    const double a = iv.t0 + double(k) * step;
    const double b = k + 1 == n ? iv.t1 : iv.t0 + double(k + 1) * step;
    return {a, b};
}

// From the entry: the number of samples of `iv` and sample k's position (k and n are doubles, as a
// shader's float loop counts them).
inline double from_entry_count(const Interval& iv, double step, double first) {
    return std::max(1.0, std::floor(iv.length() / step + 1.0 - first));
}
// From the entry or the exit, by the step-count rule (Profile::StepCount): ThroughExit is
// from_entry_count; BeforeExit: n = max(0, ceil(L / h - first)), the samples with t < t1 (a shader's
// `while (t < t_exit)`).
template <class StepCount>
double sample_count(const Interval& iv, double step, double first, StepCount rule) {
    if (rule == StepCount::ThroughExit) return from_entry_count(iv, step, first);
    return std::max(0.0, std::ceil(iv.length() / step - first));
}
inline double from_entry_sample(const Interval& iv, double step, double first, double k) {
    return iv.t0 + (first + k) * step;
}

// Calls fn(segment) front to back over every interval; fn returns false to stop early. The plain
// enumeration the tests check march() (March.h) against; the integrators march.
template <typename Fn>
void for_each_segment(const std::vector<Interval>& intervals, double step, Fn&& fn) {
    for (const Interval& iv : intervals) {
        const std::int64_t n = segment_count(iv, step);
        for (std::int64_t k = 0; k < n; ++k)
            if (!fn(segment(iv, step, k, n))) return;
    }
}

}  // namespace volref
