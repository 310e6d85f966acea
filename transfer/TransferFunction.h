// TransferFunction: data value -> colour (RGB, not premultiplied) and opacity per unit distance
// (conventions sections 1 and 3; scene key volume.transfer).
//
// The function's argument is the data value v (domain "data") or t = (v - lo) / (hi - lo) over the
// window [lo, hi] (domain "normalized"; default window: the type's range for integer data, the
// data's [min, max] for float data). Defaults when rows are absent: colour white; opacity a ramp
// from 0 at the window's low end to 1 at its high end (in the function's own coordinate: [lo, hi]
// for "data", [0, 1] for "normalized").
// Gradient opacity (`gradient_opacity` rows [|grad f|, factor]): the opacity is multiplied by the
// piecewise-linear factor of |grad f| and clamped to [0, 1] (as VTK's gradient opacity).
#pragma once
#include <array>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"
#include "core/scene/Scene.h"
#include "transfer/Classifier.h"
#include "transfer/PiecewiseLinear.h"

namespace volref {

class TransferFunction final : public Classifier {
public:
    TransferFunction(const TransferSpec& spec, const Volume& volume);

    Classified classify(double value, double gradient_magnitude) const override;
    bool needs_gradient() const override { return has_gradient_opacity_; }
    double unit_distance() const override { return unit_distance_; }
    // The transfer function's coordinate for data value v.
    double coordinate(double v) const override { return normalized_ ? (v - lo_) * inv_width_ : v; }
    glm::dvec3 color(double v) const {
        const auto c = color_(coordinate(v));
        return {c[0], c[1], c[2]};
    }
    double opacity(double v) const { return opacity_(coordinate(v))[0]; }
    // False when every opacity row that classify() can interpolate for a value in [lo, hi] is 0: rows
    // k-1 .. k' for [a, b] = [coordinate(lo), coordinate(hi)] (coordinate() is monotone in floating
    // point), k and k' the first rows with x > a and x > b; row k' is left out when b is exactly on
    // row k'-1 (w = 0 there). Then the opacity is 0 + w (0 - 0) = 0 exactly, and the gradient-opacity
    // factor (finite for any |grad f|) keeps it 0.
    bool may_have_opacity(double lo, double hi) const override;
    // The window [lo, hi] used for the normalised domain and the default rows.
    std::array<double, 2> window() const { return {lo_, hi_}; }
    // The pieces the SIMD path reads (PacketComposite.h).
    bool normalized() const { return normalized_; }
    double inverse_window_width() const { return inv_width_; }
    const PiecewiseLinear<3>& color_function() const { return color_; }
    const PiecewiseLinear<1>& opacity_function() const { return opacity_; }
    const PiecewiseLinear<1>& gradient_opacity_function() const { return gradient_opacity_; }

private:
    bool normalized_ = false;
    double lo_ = 0.0, hi_ = 1.0, inv_width_ = 1.0;
    double unit_distance_ = 1.0;
    PiecewiseLinear<3> color_;
    PiecewiseLinear<1> opacity_;
    bool has_gradient_opacity_ = false;
    PiecewiseLinear<1> gradient_opacity_;
};

}  // namespace volref
