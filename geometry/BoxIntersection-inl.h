// The slab test's arithmetic as templates over a lane type L (core/Lanes.h), so that one ray
// (BoxIntersection.h, scalar lanes) and a packet of rays (BoxIntervals.cpp, SIMD lanes) share one
// formula. Where the scalar test returns early (an empty slab) the lanes compute on and drop the lane;
// every value of a lane that hits is the scalar one (selects, not min/max instructions, so that NaN and
// -0 go as std::min / std::max take them). Included inside namespace volref (BoxIntersection.h) and
// inside each Highway target's namespace; hence no include guard and no includes (<limits> first).

// One axis' slab lo <= o + t d <= hi: [ta, tb] = the sorted pair (lo - o) / d, (hi - o) / d; where d
// = 0 the whole line (ta = -inf, tb = +inf) if lo <= o <= hi (not o < lo or o > hi), else nothing. The
// lanes where the slab is not empty.
template <class L>
inline typename L::M slab_lanes(typename L::V o, typename L::V d, typename L::V lo, typename L::V hi, typename L::V& ta,
                                typename L::V& tb) {
    using V = typename L::V;
    using M = typename L::M;
    const V inf = L::splat(std::numeric_limits<double>::infinity());
    const M parallel = L::eq(d, L::splat(0.0));
    const V divisor = L::select(parallel, L::splat(1.0), d);  // no division by 0 on the parallel lanes
    const V a = (lo - o) / divisor, b = (hi - o) / divisor;
    const M swap = L::gt(a, b);
    ta = L::select(parallel, L::neg(inf), L::select(swap, b, a));
    tb = L::select(parallel, inf, L::select(swap, a, b));
    return L::and_not(L::and_(parallel, L::or_(L::lt(o, lo), L::gt(o, hi))), L::all_lanes());
}

// The closed box [lo, hi]: [t0, t1] = the intersection of the three slabs, t0 = max(-inf, ta_x, ta_y,
// ta_z), t1 = min(+inf, tb_x, tb_y, tb_z) (std::max(t0, ta) = t0 < ta ? ta : t0, std::min(t1, tb) =
// tb < t1 ? tb : t1); the lanes where it is not empty (t0 <= t1).
template <class L>
inline typename L::M box_lanes(const typename L::V o[3], const typename L::V d[3], const double* lo, const double* hi,
                               typename L::V& t0, typename L::V& t1) {
    using V = typename L::V;
    using M = typename L::M;
    t0 = L::splat(-std::numeric_limits<double>::infinity());
    t1 = L::splat(std::numeric_limits<double>::infinity());
    M hit = L::all_lanes();
    for (int a = 0; a < 3; ++a) {
        V ta, tb;
        hit = L::and_(hit, slab_lanes<L>(o[a], d[a], L::splat(lo[a]), L::splat(hi[a]), ta, tb));
        t0 = L::select(L::lt(t0, ta), ta, t0);
        t1 = L::select(L::lt(tb, t1), tb, t1);
    }
    return L::and_(hit, L::le(t0, t1));
}

// A box shape's interval (BoundingGeometry's boxes): the box [lo, hi] AND the volume's domain
// [domain_lo, domain_hi] (null when the box is the domain: one slab test) AND t >= 0:
// t0 = max(box t0, domain t0, 0), t1 = min(box t1, domain t1), in that order; the lanes where t1 > t0.
template <class L>
inline typename L::M box_shape_lanes(const typename L::V o[3], const typename L::V d[3], const double* lo, const double* hi,
                                     const double* domain_lo, const double* domain_hi, typename L::V& t0, typename L::V& t1) {
    using V = typename L::V;
    using M = typename L::M;
    V s0, s1;
    M hit = box_lanes<L>(o, d, lo, hi, s0, s1);
    V e0 = s0, e1 = s1;
    if (domain_lo) hit = L::and_(hit, box_lanes<L>(o, d, domain_lo, domain_hi, e0, e1));
    const V zero = L::splat(0.0);
    t0 = L::select(L::lt(s0, e0), e0, s0);
    t0 = L::select(L::lt(t0, zero), zero, t0);
    t1 = L::select(L::lt(e1, s1), e1, s1);
    return L::and_(hit, L::gt(t1, t0));
}
