// ProfileIntegrator::for_each_sample, the profile's sample placement (midpoints, from the entry, from
// the exit: conventions section 9), shared by ProfileIntegrator.cpp and the texture band
// (ProfileTextureBand.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "core/Cancellation.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/integrate/profiles/ProfileIntegrator.h"

namespace volref {

template <class Fn>
void ProfileIntegrator::for_each_sample(const std::vector<Interval>& intervals, Fn&& fn) const {
    const double h = step_;
    if (p_.placement == Profile::Placement::Midpoints) {
        for_each_segment(intervals, h, [&](const Segment& s) { return fn(s.midpoint(), s.length()); });
        return;
    }
    if (p_.placement == Profile::Placement::FromExit) {  // seed 001: s = outAbs, outAbs - h, ... >= inAbs
        if (intervals.empty()) return;
        Interval span = intervals.front();
        span.t1 = intervals.back().t1;
        const double n = sample_count(span, h, 0.0, p_.step_count);
        for (double k = 0.0; k < n; k += 1.0)
            if (cancel_polled(std::int64_t(k)) || !fn(span.t1 - k * h, h)) return;
        return;
    }
    for (const Interval& iv : intervals) {
        const double n = sample_count(iv, h, p_.first, p_.step_count);
        for (double k = 0.0; k < n; k += 1.0)
            if (cancel_polled(std::int64_t(k)) || !fn(from_entry_sample(iv, h, p_.first, k), h)) return;
    }
}

}  // namespace volref
