// PiecewiseLinear: a function of one variable given by rows (x_k, y_k) sorted by x (non-decreasing).
//   v < x_0:                 y_0
//   v >= x_last:             y_last
//   x_{k-1} <= v < x_k:      y_{k-1} + (v - x_{k-1}) / (x_k - x_{k-1}) * (y_k - y_{k-1})
// k is the first row with x_k > v, so at a jump (two rows with the same x) the function takes the
// later row's value: it is right-continuous.
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "core/Lanes.h"

namespace volref {

#include "transfer/PiecewiseLinear-inl.h"

template <std::size_t N>
class PiecewiseLinear {
public:
    using Value = std::array<double, N>;
    PiecewiseLinear() = default;
    PiecewiseLinear(std::vector<double> xs, std::vector<Value> ys) : x_(std::move(xs)), y_(std::move(ys)) {}

    Value operator()(double v) const {
        const auto it = std::upper_bound(x_.begin(), x_.end(), v);
        if (it == x_.begin()) return y_.front();
        if (it == x_.end()) return y_.back();
        const std::size_t k = std::size_t(it - x_.begin());
        const double w = row_weight<Scalar>(v, x_[k - 1], x_[k]);  // PiecewiseLinear-inl.h, shared with the packets
        Value out;
        for (std::size_t c = 0; c < N; ++c) out[c] = between_rows<Scalar>(w, y_[k - 1][c], y_[k][c]);
        return out;
    }
    const std::vector<double>& xs() const { return x_; }
    const std::vector<Value>& ys() const { return y_; }

private:
    std::vector<double> x_;
    std::vector<Value> y_;
};

}  // namespace volref
