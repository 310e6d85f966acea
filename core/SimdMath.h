// The float lanes' log1p and expm1 (core/SimdLanes-inl.h: float_log1p, float_expm1; the fast profile's
// opacity correction, conventions section 9b) over arrays, on the instruction set Highway picks (tests
// choose one with hwy::SetSupportedTargetsForTest). For tests: the kernels call the lane functions inline.
#pragma once
#include <cstddef>

namespace volref {

// out[i] = log1p(x[i]) for -1 <= x[i] <= 1.
void float_lanes_log1p(const float* x, float* out, std::size_t n);
// out[i] = expm1(x[i]) for x[i] <= 88.
void float_lanes_expm1(const float* x, float* out, std::size_t n);

}  // namespace volref
