// SimdLanes<T>: the lane operations of core/Lanes.h on Highway vectors of T (double: the reference;
// float: the fast profile), so that every lane template (march/Accumulators-inl.h, the samplers, the
// camera's rays, the box slab test) runs on SIMD vectors unchanged. Compiled once per Highway target.
// Per-target include guard (Highway's pattern for -inl headers).
#if defined(VOLREF_SIMD_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef VOLREF_SIMD_LANES_INL_H_
#undef VOLREF_SIMD_LANES_INL_H_
#else
#define VOLREF_SIMD_LANES_INL_H_
#endif

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lane operations of core/Lanes.h on Highway vectors of T (double: the reference; float: the
// fast profile), so that the accumulators of march/Accumulators.h run on packets unchanged.
template <typename T>
struct SimdLanes {
    using D = hn::ScalableTag<T>;
    using V = hn::Vec<D>;
    using M = hn::Mask<D>;
    static HWY_INLINE V splat(double x) { return hn::Set(D(), T(x)); }
    static HWY_INLINE M all_lanes() { return hn::Eq(hn::Zero(D()), hn::Zero(D())); }
    static HWY_INLINE M no_lanes() { return hn::Lt(hn::Zero(D()), hn::Zero(D())); }
    static HWY_INLINE V select(M m, V a, V b) { return hn::IfThenElse(m, a, b); }
    static HWY_INLINE V select_zero(M m, V a) { return hn::IfThenElseZero(m, a); }
    static HWY_INLINE M and_(M a, M b) { return hn::And(a, b); }
    static HWY_INLINE M or_(M a, M b) { return hn::Or(a, b); }
    static HWY_INLINE M and_not(M a, M b) { return hn::AndNot(a, b); }
    static HWY_INLINE bool none(M m) { return hn::AllFalse(D(), m); }
    static HWY_INLINE M gt(V a, V b) { return hn::Gt(a, b); }
    static HWY_INLINE M ge(V a, V b) { return hn::Ge(a, b); }
    static HWY_INLINE M lt(V a, V b) { return hn::Lt(a, b); }
    static HWY_INLINE M le(V a, V b) { return hn::Le(a, b); }
    static HWY_INLINE M eq(V a, V b) { return hn::Eq(a, b); }
    static HWY_INLINE M is_finite(V a) { return hn::IsFinite(a); }
    static HWY_INLINE V neg(V a) { return hn::Neg(a); }
    static HWY_INLINE V abs(V a) { return hn::Abs(a); }
    static HWY_INLINE V exp(V a) { return hn::Exp(D(), a); }
    static HWY_INLINE V expm1(V a) { return hn::Expm1(D(), a); }
    static HWY_INLINE V log1p(V a) { return hn::Log1p(D(), a); }
    static HWY_INLINE V min(V a, V b) { return hn::Min(a, b); }
    static HWY_INLINE V max(V a, V b) { return hn::Max(a, b); }
    static HWY_INLINE V floor(V a) { return hn::Floor(a); }
    static HWY_INLINE V sqrt(V a) { return hn::Sqrt(a); }
    // a^n for a >= 0: exp(n log a) where a > 0, 0 where a = 0 (n > 0), 1 for n = 0.
    static HWY_INLINE V pow(V a, double n) {
        if (n == 0.0) return splat(1.0);
        return hn::IfThenElseZero(hn::Gt(a, hn::Zero(D())), hn::Exp(D(), hn::Mul(splat(n), hn::Log(D(), a))));
    }
};

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
