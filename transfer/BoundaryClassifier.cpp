#include "transfer/BoundaryClassifier.h"

#include <algorithm>

namespace volref {

Classified BoundaryClassifier::classify(double f, double g) const {
    Classified out;
    if (regions_.size() < 2 || f < regions_.front().value || f > regions_.back().value) return out;
    std::size_t n = 0;
    while (n + 2 < regions_.size() && f > regions_[n + 1].value) ++n;
    const BoundaryRegion& lo = regions_[n];
    const BoundaryRegion& hi = regions_[n + 1];
    const double w = (f - lo.value) / (hi.value - lo.value);
    const double wl = lo.opacity * (1.0 - w), wh = hi.opacity * w;
    out.opacity = std::clamp(g * (wh + wl), 0.0, 1.0);
    out.color = wl + wh > 0.0 ? (wl * lo.color + wh * hi.color) / (wl + wh) : (1.0 - w) * lo.color + w * hi.color;
    return out;
}

}  // namespace volref
