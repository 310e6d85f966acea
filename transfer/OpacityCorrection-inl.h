// The optical model's per-sample formulas over a lane type L (core/Lanes.h), written once: included
// by OpacityCorrection.h in namespace volref (scalar lanes) and by the SIMD kernels inside each
// Highway target's namespace (core/integrate/packet/PacketKernels-inl.h); hence no include guard.
//
// A segment's optical depth tau = -(d / l) log1p(-a) (a: the transfer function's opacity per unit
// distance l; +inf for a = 1) and its opacity alpha = -expm1(-tau) = 1 - (1 - a)^(d / l).
template <class L>
inline typename L::V optical_depth(typename L::V a, typename L::V d, typename L::V l) {
    return L::neg(d / l) * L::log1p(L::neg(a));
}
template <class L>
inline typename L::V segment_alpha(typename L::V tau) {
    return L::neg(L::expm1(L::neg(tau)));
}
