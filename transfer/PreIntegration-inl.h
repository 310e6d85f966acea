// The pre-integration table's read (PreIntegration.h) as templates over a lane type L (core/Lanes.h:
// ScalarLanes for lookup_preintegration, SimdLanes for the fast profile's packets,
// core/integrate/packet/PacketComposite.cpp): one formula for both, so the tests of the scalar read
// check the kernel's arithmetic. Fetching the four entries is each form's own (an index; gathers).
// Included once inside namespace volref (PreIntegration.cpp) and once inside each Highway target's
// namespace (PacketKernels-inl.h); hence no include guard and no includes.

// One axis of the table at coordinate x: f = clamp((x - x0) inv_dx, 0, n), the node i = min(floor(f),
// n - 1) and the weight w = f - i (so f = n reads between nodes n - 1 and n with w = 1).
template <class L>
inline void preintegration_axis(typename L::V x, typename L::V x0, typename L::V inv_dx, typename L::V n,
                                typename L::V& i, typename L::V& w) {
    const typename L::V f = L::min(L::max((x - x0) * inv_dx, L::splat(0.0)), n);
    i = L::min(L::floor(f), n - L::splat(1.0));
    w = f - i;
}

// The bilinear blend of the entries at (i, j), (i, j + 1), (i + 1, j), (i + 1, j + 1): along the back
// end's axis first, top = e00 + wj (e01 - e00), bottom = e10 + wj (e11 - e10), then top + wi (bottom - top).
template <class L>
inline typename L::V preintegration_blend(typename L::V e00, typename L::V e01, typename L::V e10, typename L::V e11,
                                          typename L::V wi, typename L::V wj) {
    const typename L::V top = e00 + wj * (e01 - e00), bottom = e10 + wj * (e11 - e10);
    return top + wi * (bottom - top);
}
