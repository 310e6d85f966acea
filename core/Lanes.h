// Lanes: the arithmetic the ray-marching accumulators are written in (core/integrate/march/
// Accumulators.h), so that each formula is written once and instantiated for every lane type the
// renderer uses: ScalarLanes<double> (the scalar reference path, traces, the adaptive integrator, the
// mirror profiles) here, and SimdLanes<double> / SimdLanes<float> (Highway vectors: the packet path
// and the fast profile) in core/SimdLanes-inl.h, which supply the same names.
//
// A lane type L provides V (a value per lane), M (a mask per lane) and, on them:
//   splat(x), all_lanes(), no_lanes(), select(m, a, b), select_zero(m, a), and_(a, b), or_(a, b), and_not(a, b) = !a && b,
//   none(m), gt/ge/lt/le/eq(a, b), is_finite(a), neg(a), abs(a), exp(a), expm1(a), log1p(a), min(a, b),
//   max(a, b), floor(a), sqrt(a), pow(a, n) (a >= 0, n a double);
// and V's own +, -, *, /. The scalar lanes call the C library (glibc: < 1 ulp); the SIMD lanes call
// Highway's vector functions (exp, expm1 and log1p within 1, 4 and 2 ulp; conventions section 12),
// except float lanes' expm1 and log1p, volref's own (core/SimdLanes-inl.h; within 2 ulp; section 9b).
// No operation fuses a multiply and an add (-ffp-contract=off).
#pragma once
#include <algorithm>
#include <cmath>

namespace volref {

template <typename T>
struct ScalarLanes {
    using V = T;
    using M = bool;
    static V splat(double x) { return T(x); }
    static M all_lanes() { return true; }
    static M no_lanes() { return false; }
    static V select(M m, V a, V b) { return m ? a : b; }
    static V select_zero(M m, V a) { return m ? a : T(0); }
    static M and_(M a, M b) { return a && b; }
    static M or_(M a, M b) { return a || b; }
    static M and_not(M a, M b) { return !a && b; }
    static bool none(M m) { return !m; }
    static M gt(V a, V b) { return a > b; }
    static M ge(V a, V b) { return a >= b; }
    static M lt(V a, V b) { return a < b; }
    static M le(V a, V b) { return a <= b; }
    static M eq(V a, V b) { return a == b; }
    static M is_finite(V a) { return std::isfinite(a); }
    static V neg(V a) { return -a; }
    static V abs(V a) { return std::fabs(a); }
    static V exp(V a) { return std::exp(a); }
    static V expm1(V a) { return std::expm1(a); }
    static V log1p(V a) { return std::log1p(a); }
    // std::min / std::max (NaN in a comes through: the comparisons are false) and floor.
    static V min(V a, V b) { return std::min(a, b); }
    static V max(V a, V b) { return std::max(a, b); }
    static V floor(V a) { return std::floor(a); }
    static V sqrt(V a) { return std::sqrt(a); }
    // a^n for a >= 0 (the C library's pow).
    static V pow(V a, double n) { return std::pow(a, T(n)); }
};

using Scalar = ScalarLanes<double>;

}  // namespace volref
