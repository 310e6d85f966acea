// StepDoubling: the fixed-step integrator's error estimate (volref render --error).
//
// The midpoint rule has order 2: I_h = I + c h^2 + O(h^3), so I_{h/2} = I + c h^2 / 4 + O(h^3) and
//   I_h - I = (4 / 3) (I_h - I_{h/2}) + O(h^3).
// The estimate for the image at h (the one written) is, per pixel,
//   error = kStepDoublingSafety * (4 / 3) * max over R, G, B, A of |I_h - I_{h/2}|
// (core/Conventions.h: the safety factor covers pixels where c still changes with h).
#pragma once
#include "core/film/Image.h"

namespace volref {

// The estimate from one channel difference |I_h - I_{h/2}|.
double step_doubling_bound(double difference);

// `coarse` (rendered at h) with an "error" channel computed from `fine` (the same scene at h / 2):
// the step-doubling bound of the largest difference over R, G, B, A. Both images have the same size
// and the same first four channels; `coarse`'s other channels are kept.
Image with_step_doubling_error(const Image& coarse, const Image& fine);

}  // namespace volref
