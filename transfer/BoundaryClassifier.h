// BoundaryClassifier: Levoy's region boundaries (conventions section 7).
// Regions fv_1 < ... < fv_N with opacities av_n and colours c_n; for fv_n <= f <= fv_n+1 with
// w = (f - fv_n) / (fv_n+1 - fv_n) and g = |grad f|:
//   a = g (av_n+1 w + av_n (1 - w))                         (clamped to [0, 1])
//   colour = (av_n+1 w c_n+1 + av_n (1 - w) c_n) / (av_n+1 w + av_n (1 - w))
//            (the opacity-weighted mix, as for isovalues; the linear mix (1 - w) c_n + w c_n+1 where
//             both weights are 0)
// and a = 0 outside [fv_1, fv_N]. At f = fv_n exactly, the lower of the two intervals is used
// (both give the same a). The opacity is per unit distance like any other; a = g (...) can exceed 1
// for steep gradients, and is clamped to 1 (opaque), a choice Levoy's formula leaves open.
#pragma once
#include <vector>

#include "transfer/Classifier.h"

namespace volref {

class BoundaryClassifier final : public Classifier {
public:
    BoundaryClassifier(std::vector<BoundaryRegion> regions, double unit_distance)
        : regions_(std::move(regions)), unit_distance_(unit_distance) {}
    Classified classify(double value, double gradient_magnitude) const override;
    // The terms classify() computes (for `volref explain classify-boundary`): the interval n
    // [fv_n, fv_n+1] holding f, w, the weights av_n (1 - w) and av_n+1 w, g (sum) before the clamp.
    struct Terms {
        bool inside = false;  // fv_1 <= f <= fv_N (and N >= 2)
        std::size_t n = 0;
        double w = 0.0, low = 0.0, high = 0.0, unclamped = 0.0;
    };
    Terms terms(double value, double gradient_magnitude) const;
    bool needs_gradient() const override { return true; }
    double unit_distance() const override { return unit_distance_; }
    // False when [lo, hi] does not meet [fv_1, fv_N] (a = 0 there whatever g), or when every region
    // whose opacity the values of [lo, hi] within [fv_1, fv_N] interpolate has av = 0 (then a = g * 0 = 0
    // for a finite g; an infinite g would give NaN, which is why the contract asks for finite g).
    bool may_have_opacity(double lo, double hi) const override;

private:
    std::vector<BoundaryRegion> regions_;
    double unit_distance_;
};

}  // namespace volref
