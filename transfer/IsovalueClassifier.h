// IsovalueClassifier: Levoy's isovalue contours (conventions section 7).
// For contour n (isovalue fv, opacity av, thickness r in world units) and g = |grad f|:
//   a_n = av                                 if g = 0 and f = fv
//   a_n = av (1 - |fv - f| / (r g))          if g > 0 and |f - fv| <= r g
//   a_n = 0                                  otherwise
// so along a line across the contour the opacity is a tent of half-width r (world units).
// Combined: a = 1 - prod_n (1 - a_n); colour = sum_n a_n c_n / sum_n a_n (the opacity-weighted mix of
// the contours' colours; black where every a_n is 0, which has no effect since a = 0 there).
#pragma once
#include <vector>

#include "transfer/Classifier.h"

namespace volref {

class IsovalueClassifier final : public Classifier {
public:
    IsovalueClassifier(std::vector<IsovalueContour> contours, double unit_distance)
        : contours_(std::move(contours)), unit_distance_(unit_distance) {}
    Classified classify(double value, double gradient_magnitude) const override;
    bool needs_gradient() const override { return true; }
    double unit_distance() const override { return unit_distance_; }
    // One contour's opacity a_n, the formula above.
    static double contour_opacity(const IsovalueContour& c, double value, double gradient_magnitude);

private:
    std::vector<IsovalueContour> contours_;
    double unit_distance_;
};

}  // namespace volref
