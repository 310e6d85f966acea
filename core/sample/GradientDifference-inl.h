// The gradient by differences (GradientField's "central" and "forward" schemes, conventions section 2)
// as a template over a lane type L (core/Lanes.h: ScalarLanes for GradientField, SimdLanes for the
// packet kernels, core/integrate/packet/PacketComposite.cpp): one formula for both.
// Included once inside namespace volref (GradientField.cpp) and once inside each Highway target's
// namespace; hence no include guard and no includes.

// d f / d x_a at X (an axis of more than one voxel), h the spacing, [lo, hi] the domain on axis a:
//   central:  (f(b) - f(c)) / (b - c), c = max(x - h, lo), b = min(x + h, hi);
//   forward:  (f(x + h) - f(x)) / h where x + h <= hi, else backward (f(x) - f(c)) / (x - c).
// f(P) evaluates the field at the point P[3]; fx() is f(X). A lane type evaluates only the branches
// some lane takes.
template <class L, class F, class FX>
inline typename L::V difference(bool central, const typename L::V X[3], int a, typename L::V h, typename L::V lo,
                                typename L::V hi, F&& f, FX&& fx) {
    using V = typename L::V;
    const V c = L::max(X[a] - h, lo);
    V P[3] = {X[0], X[1], X[2]};
    if (central) {
        const V b = L::min(X[a] + h, hi);
        P[a] = b;
        const V fb = f(P);
        P[a] = c;
        const V fc = f(P);
        return (fb - fc) / (b - c);
    }
    const V xh = X[a] + h;
    const auto forward_lanes = L::le(xh, hi);
    V forward = L::splat(0.0), backward = L::splat(0.0);
    if (!L::none(forward_lanes)) {
        P[a] = xh;
        forward = (f(P) - fx()) / h;
    }
    if (!L::none(L::and_not(forward_lanes, L::all_lanes()))) {
        P[a] = c;
        backward = (fx() - f(P)) / (X[a] - c);
    }
    return L::select(forward_lanes, forward, backward);
}
