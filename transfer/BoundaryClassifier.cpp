#include "transfer/BoundaryClassifier.h"

#include <algorithm>

namespace volref {

BoundaryClassifier::Terms BoundaryClassifier::terms(double f, double g) const {
    Terms t;
    if (regions_.size() < 2 || f < regions_.front().value || f > regions_.back().value) return t;
    t.inside = true;
    std::size_t n = 0;
    while (n + 2 < regions_.size() && f > regions_[n + 1].value) ++n;
    t.n = n;
    const BoundaryRegion& lo = regions_[n];
    const BoundaryRegion& hi = regions_[n + 1];
    t.w = (f - lo.value) / (hi.value - lo.value);
    t.low = lo.opacity * (1.0 - t.w);
    t.high = hi.opacity * t.w;
    t.unclamped = g * (t.high + t.low);
    return t;
}

Classified BoundaryClassifier::classify(double f, double g) const {
    Classified out;
    const Terms t = terms(f, g);
    if (!t.inside) return out;
    const BoundaryRegion& lo = regions_[t.n];
    const BoundaryRegion& hi = regions_[t.n + 1];
    const double w = t.w, wl = t.low, wh = t.high;
    out.opacity = std::clamp(t.unclamped, 0.0, 1.0);
    out.color = wl + wh > 0.0 ? (wl * lo.color + wh * hi.color) / (wl + wh) : (1.0 - w) * lo.color + w * hi.color;
    return out;
}

bool BoundaryClassifier::may_have_opacity(double lo, double hi) const {
    if (!(lo <= hi)) return true;  // empty or NaN: unsure
    if (regions_.size() < 2) return false;  // classify() gives a = 0 everywhere
    for (std::size_t n = 1; n < regions_.size(); ++n)
        if (!(regions_[n].value > regions_[n - 1].value)) return true;  // not strictly increasing: unsure
    if (hi < regions_.front().value || lo > regions_.back().value) return false;
    // The interval n that classify() picks for f (the first n with f <= fv_n+1, at most N - 2) is
    // non-decreasing in f, so [lo, hi] uses the intervals n(max(lo, fv_1)) .. n(min(hi, fv_N)).
    auto interval_of = [&](double f) {
        std::size_t n = 0;
        while (n + 2 < regions_.size() && f > regions_[n + 1].value) ++n;
        return n;
    };
    const std::size_t n0 = interval_of(std::max(lo, regions_.front().value));
    const std::size_t n1 = interval_of(std::min(hi, regions_.back().value));
    for (std::size_t n = n0; n <= n1 + 1; ++n)
        if (regions_[n].opacity != 0.0) return true;
    return false;
}

}  // namespace volref
