// Highway's per-target compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/SimdMath.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include <algorithm>

#include "core/SimdLanes-inl.h"
#include "core/SimdMath.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {

// One function of float lanes over an array: whole vectors, then the tail through a padded buffer.
template <class F>
HWY_INLINE void over_lanes(const float* x, float* out, std::size_t n, F f) {
    const hn::ScalableTag<float> d;
    const std::size_t L = hn::Lanes(d);
    HWY_ALIGN float buf[hn::MaxLanes(d)];
    for (std::size_t i = 0; i < n; i += L) {
        const std::size_t m = std::min(L, n - i);
        for (std::size_t k = 0; k < L; ++k) buf[k] = k < m ? x[i + k] : 0.0f;
        hn::Store(f(d, hn::Load(d, buf)), d, buf);
        for (std::size_t k = 0; k < m; ++k) out[i + k] = buf[k];
    }
}

void FloatLanesLog1p(const float* x, float* out, std::size_t n) {
    over_lanes(x, out, n, [](auto d, auto v) HWY_ATTR { return float_log1p(d, v); });
}
void FloatLanesExpm1(const float* x, float* out, std::size_t n) {
    over_lanes(x, out, n, [](auto d, auto v) HWY_ATTR { return float_expm1(d, v); });
}

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace volref {
HWY_EXPORT(FloatLanesLog1p);
HWY_EXPORT(FloatLanesExpm1);

void float_lanes_log1p(const float* x, float* out, std::size_t n) { HWY_DYNAMIC_DISPATCH(FloatLanesLog1p)(x, out, n); }
void float_lanes_expm1(const float* x, float* out, std::size_t n) { HWY_DYNAMIC_DISPATCH(FloatLanesExpm1)(x, out, n); }
}  // namespace volref
#endif
