// A piecewise-linear table's interpolation (PiecewiseLinear.h states the rule) as templates over a
// lane type L (core/Lanes.h: ScalarLanes for PiecewiseLinear, SimdLanes for the packet kernels'
// tables, core/integrate/packet/PacketComposite.cpp): one formula for both. Finding the
// rows is each form's own (a binary search; a count of the rows at or below v). Included once inside
// namespace volref (PiecewiseLinear.h) and once inside each Highway target's namespace; hence no
// include guard and no includes.

// The weight of v between rows lo and hi (x_lo <= v < x_hi): (v - x_lo) / (x_hi - x_lo).
template <class L>
inline typename L::V row_weight(typename L::V v, typename L::V x_lo, typename L::V x_hi) {
    return (v - x_lo) / (x_hi - x_lo);
}

// One channel between the rows: y_lo + w (y_hi - y_lo).
template <class L>
inline typename L::V between_rows(typename L::V w, typename L::V y_lo, typename L::V y_hi) {
    return y_lo + w * (y_hi - y_lo);
}
