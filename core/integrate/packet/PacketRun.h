// What one integrator's packets run with beside the volume's description (core/sample/VolumeView.h):
// the step, the termination, the skipping grid and the lanes.
#pragma once
#include "core/integrate/march/Accumulators.h"

namespace volref {

class MacrocellGrid;

struct PacketRun {
    double step = 1.0;
    Termination termination;  // early termination (and the fast profile's cutoff: march/Accumulators.h)
    // Empty-space skipping (SegmentWalk.h; composite: with the view's skip radii), or none.
    const MacrocellGrid* macrocells = nullptr;
    bool fast = false;  // the fast profile: float lanes (VolumeView's _float members)
};

}  // namespace volref
