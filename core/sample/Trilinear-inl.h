// Trilinear reconstruction's arithmetic as templates over a lane type L (core/Lanes.h: ScalarLanes for
// VolumeSampler and ShellSampler, SimdLanes for the packet kernels, packet/PacketKernels-inl.h), so
// that the scalar and SIMD samplers share one formula, as the accumulators do. Included once
// inside namespace volref (Trilinear.h) and once inside each Highway target's namespace; hence no
// include guard and no includes. Only the fetch of the eight corners is each sampler's own.

// One axis of a world point x: the continuous index u = clamp((x - origin) inv_spacing, 0, n - 1)
// (conventions section 2).
template <class L>
inline typename L::V clamped_index(typename L::V x, typename L::V origin, typename L::V inv_spacing, typename L::V max_index) {
    return L::min(L::max((x - origin) * inv_spacing, L::splat(0.0)), max_index);
}

// The cell of u on one axis (its lower corner: min(floor(u), n - 2)) and the fraction u - cell; an
// axis of one voxel (`flat`) has cell 0 and fraction 0 (the one voxel read twice).
template <class L>
inline void cell_of(typename L::V u, typename L::V top, bool flat, typename L::V& cell, typename L::V& frac) {
    if (flat) {
        cell = L::splat(0.0);
        frac = L::splat(0.0);
        return;
    }
    cell = L::min(L::floor(u), top);
    frac = u - cell;
}

// f at the fractions (p, q, r) from the corner values f1..f8 in Levoy's order, term by term:
// f1 (1-p)(1-q)(1-r) + f2 p(1-q)(1-r) + f3 p q (1-r) + f4 (1-p) q (1-r) + f5 (1-p)(1-q) r + f6 p(1-q) r
// + f7 p q r + f8 (1-p) q r, each weight ((a b) c), summed from 0 in this order.
template <class L>
inline typename L::V trilinear_sum(const typename L::V f[8], typename L::V p, typename L::V q, typename L::V r) {
    using V = typename L::V;
    const V one = L::splat(1.0);
    const V P = one - p, Q = one - q, R = one - r;
    const V w[8] = {P * Q * R, p * Q * R, p * q * R, P * q * R, P * Q * r, p * Q * r, p * q * r, P * q * r};
    V sum = L::splat(0.0);
    for (int n = 0; n < 8; ++n) sum = sum + f[n] * w[n];
    return sum;
}
