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

#include <limits>
#include <type_traits>

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// log1p and expm1 on float lanes for the opacity correction alpha = -expm1((d / l) log1p(-a))
// (transfer/OpacityCorrection-inl.h), the fast profile's two transcendental functions per sample
// (conventions section 9b). Each is one polynomial after a range reduction, with no division (Highway's
// Log1p divides twice), within 2 ulp of the correctly rounded value (measured 1.49 and 1.64 ulp; tests/unit/test_simd.cpp,
// Simd.FloatLog1pAndExpm1WithinTwoUlp, against the C library in double). The polynomials' coefficients
// are float minimax fits (Lawson-weighted Chebyshev, scripts/fit_float_polynomials.py) of
// h(f) = (log1p(f) - f + f^2 / 2) / f^3 on [sqrt(1/2) - 1, sqrt(2) - 1] (degree 7, 9e-9 relative in
// double) and h(r) = (expm1(r) - r - r^2 / 2) / r^3 on [-ln 2 / 2, ln 2 / 2] (degree 3, 1.6e-8).
//
// float_log1p(x), -1 <= x <= 1: u = 1 + x rounded and e = x - (u - 1) its error, exactly (Dekker's
// Fast2Sum, |x| <= 1), so 1 + x = u + e; u = 2^k m with m in [sqrt(1/2), sqrt(2)) from u's bits (its
// exponent read after subtracting sqrt(1/2)'s); f = m - 1 (exact); then
//   log1p(x) = k ln2_hi + (f + f^2 (-1/2 + f h(f)) + (k ln2_lo + e (2 - u)))
// with ln 2 = ln2_hi + ln2_lo (ln2_hi of 16 bits: k ln2_hi exact) and e (2 - u) for log(1 + e / u)
// (e is nonzero only for u in [1/2, 2], where 2 - u is 1 / u to (1 - u)^2 / u, on an e of half an ulp).
// x = -1: -inf. NaN: NaN.
template <class D>
HWY_INLINE hn::Vec<D> float_log1p(D d, hn::Vec<D> x) {
    using V = hn::Vec<D>;
    const hn::RebindToSigned<D> di;
    const V one = hn::Set(d, 1.0f);
    const V u = hn::Add(one, x);
    const V e = hn::Sub(x, hn::Sub(u, one));
    const auto kSqrtHalfBits = hn::Set(di, 0x3f3504f3);
    const auto bits = hn::Sub(hn::BitCast(di, u), kSqrtHalfBits);
    const V k = hn::ConvertTo(d, hn::ShiftRight<23>(bits));  // arithmetic: the floor
    const V f = hn::Sub(hn::BitCast(d, hn::Add(hn::And(bits, hn::Set(di, 0x007fffff)), kSqrtHalfBits)), one);
    V h = hn::Set(d, -0x1.41e4b4p-4f);
    h = hn::MulAdd(h, f, hn::Set(d, 0x1.07cabep-3f));
    h = hn::MulAdd(h, f, hn::Set(d, -0x1.0cdf72p-3f));
    h = hn::MulAdd(h, f, hn::Set(d, 0x1.226f1ep-3f));
    h = hn::MulAdd(h, f, hn::Set(d, -0x1.5478b8p-3f));
    h = hn::MulAdd(h, f, hn::Set(d, 0x1.99a58ep-3f));
    h = hn::MulAdd(h, f, hn::Set(d, -0x1.00022p-2f));
    h = hn::MulAdd(h, f, hn::Set(d, 0x1.55554ap-2f));
    const V log1p_f = hn::MulAdd(hn::Mul(f, f), hn::MulAdd(f, h, hn::Set(d, -0.5f)), f);
    const V lo = hn::MulAdd(k, hn::Set(d, 0x1.7f7d1cp-20f), hn::Mul(e, hn::Sub(hn::Set(d, 2.0f), u)));
    const V r = hn::MulAdd(k, hn::Set(d, 0x1.62e4p-1f), hn::Add(log1p_f, lo));
    return hn::IfThenElse(hn::Eq(u, hn::Zero(d)), hn::Set(d, -std::numeric_limits<float>::infinity()), r);
}

// float_expm1(x), x <= 88: n = round(x / ln 2) (of the product x (1 / ln 2), fused: rounded once) and
// r = x - n ln2_hi - n ln2_lo (both products exact or fused) in [-ln 2 / 2, ln 2 / 2]; expm1(r) = r + r^2 (1/2 + r h(r)); then
//   expm1(x) = 2^n expm1(r) + (2^n - 1)   (one fused multiply-add; n = 0: expm1(r) itself)
// with 2^n from its bits. x < -87: -1 (e^x below 2^-125, rounded away). NaN: NaN.
template <class D>
HWY_INLINE hn::Vec<D> float_expm1(D d, hn::Vec<D> x) {
    using V = hn::Vec<D>;
    const hn::RebindToSigned<D> di;
    const V lower = hn::Set(d, -87.0f), one = hn::Set(d, 1.0f);
    const auto below = hn::Lt(x, lower);
    const V xc = hn::IfThenElse(below, lower, x);
    // n = round(x / ln 2) by the shifter 1.5 2^23 (ulp 1 there: the sum rounds to an integer, ties to
    // even), so that n's integer is the sum's low bits: 2^n's bits are (bits(t) - bits(1.5 2^23) + 127) << 23.
    const V shifter = hn::Set(d, 0x1.8p23f);
    const V t = hn::MulAdd(xc, hn::Set(d, 0x1.715476p+0f), shifter);
    const V n = hn::Sub(t, shifter);
    V r = hn::NegMulAdd(n, hn::Set(d, 0x1.62e4p-1f), xc);
    r = hn::NegMulAdd(n, hn::Set(d, 0x1.7f7d1cp-20f), r);
    V h = hn::Set(d, 0x1.6d678ap-10f);
    h = hn::MulAdd(h, r, hn::Set(d, 0x1.1226bap-7f));
    h = hn::MulAdd(h, r, hn::Set(d, 0x1.5554d2p-5f));
    h = hn::MulAdd(h, r, hn::Set(d, 0x1.5554b2p-3f));
    const V expm1_r = hn::MulAdd(hn::Mul(r, r), hn::MulAdd(r, h, hn::Set(d, 0.5f)), r);
    const V two_n = hn::BitCast(d, hn::ShiftLeft<23>(hn::Add(hn::BitCast(di, t), hn::Set(di, 127 - 0x4b400000))));
    return hn::IfThenElse(below, hn::Neg(one), hn::MulAdd(two_n, expm1_r, hn::Sub(two_n, one)));
}

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
    // Float lanes: float_expm1 (x <= 88) and float_log1p (-1 <= x <= 1), above; double lanes: Highway's.
    static HWY_INLINE V expm1(V a) {
        if constexpr (std::is_same_v<T, float>) return float_expm1(D(), a);
        else return hn::Expm1(D(), a);
    }
    static HWY_INLINE V log1p(V a) {
        if constexpr (std::is_same_v<T, float>) return float_log1p(D(), a);
        else return hn::Log1p(D(), a);
    }
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
