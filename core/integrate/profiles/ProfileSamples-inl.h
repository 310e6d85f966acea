// ProfileIntegrator::for_each_sample: the profile's sample placement (midpoints, from the entry, from
// the exit: conventions section 9) as march()'s (march/March.h), shared by ProfileIntegrator.cpp and the
// texture band (ProfileTextureBand.cpp).
#pragma once
#include <vector>

#include "core/integrate/march/March.h"
#include "core/integrate/profiles/ProfileIntegrator.h"

namespace volref {

// fn(t, d): a sample at t standing for the length d; false stops the ray.
template <class Fn>
void ProfileIntegrator::for_each_sample(const std::vector<Interval>& intervals, Fn&& fn) const {
    using Kind = MarchPlacement::Kind;
    MarchOptions o;
    o.step = step_;
    o.placement.kind = p_.placement == Profile::Placement::Midpoints  ? Kind::Midpoints
                       : p_.placement == Profile::Placement::FromExit ? Kind::FromExit
                                                                      : Kind::FromEntry;
    o.placement.first = p_.first;
    o.placement.through_exit = p_.step_count == Profile::StepCount::ThroughExit;
    march(intervals, o, [&](const MarchSample& m) { return fn(m.t, m.d); });
}

}  // namespace volref
