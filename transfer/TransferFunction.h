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
    // The window [lo, hi] used for the normalised domain and the default rows.
    std::array<double, 2> window() const { return {lo_, hi_}; }

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
