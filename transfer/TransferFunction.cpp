#include "transfer/TransferFunction.h"

#include <algorithm>
#include <sstream>

#include "core/Error.h"
#include "transfer/BoundaryClassifier.h"
#include "transfer/IsovalueClassifier.h"

namespace volref {

namespace {

std::array<double, 2> default_window(const Volume& volume) {
    return scalar_type_is_integer(volume.type) ? scalar_type_range(volume.type) : volume.value_range();
}

}  // namespace

TransferFunction::TransferFunction(const TransferSpec& spec, const Volume& volume) {
    normalized_ = spec.domain == TransferSpec::Domain::Normalized;
    unit_distance_ = spec.opacity_unit_distance;
    const std::array<double, 2> w = spec.window ? *spec.window : default_window(volume);
    lo_ = w[0];
    hi_ = w[1];
    if (normalized_) {
        if (!(hi_ > lo_)) {
            std::ostringstream msg;
            msg << "volume.transfer.window: the data's range [" << lo_ << ", " << hi_
                << "] is empty, so the normalised domain is undefined; give a window [lo, hi]";
            throw Error(msg.str());
        }
        inv_width_ = 1.0 / (hi_ - lo_);
    }
    // Coordinates of the window's ends in the function's own domain.
    const double x0 = normalized_ ? 0.0 : lo_, x1 = normalized_ ? 1.0 : hi_;

    std::vector<double> cx;
    std::vector<std::array<double, 3>> cy;
    for (const auto& row : spec.color) {
        cx.push_back(row[0]);
        cy.push_back({row[1], row[2], row[3]});
    }
    if (cx.empty()) {
        cx = {x0};
        cy = {{1.0, 1.0, 1.0}};
    }
    color_ = PiecewiseLinear<3>(std::move(cx), std::move(cy));

    std::vector<double> ox;
    std::vector<std::array<double, 1>> oy;
    for (const auto& row : spec.opacity) {
        ox.push_back(row[0]);
        oy.push_back({row[1]});
    }
    if (ox.empty()) {
        ox = {x0, x1};
        oy = {{0.0}, {1.0}};
    }
    opacity_ = PiecewiseLinear<1>(std::move(ox), std::move(oy));

    if (!spec.gradient_opacity.empty()) {
        has_gradient_opacity_ = true;
        std::vector<double> gx;
        std::vector<std::array<double, 1>> gy;
        for (const auto& row : spec.gradient_opacity) {
            gx.push_back(row[0]);
            gy.push_back({row[1]});
        }
        gradient_opacity_ = PiecewiseLinear<1>(std::move(gx), std::move(gy));
    }
}

Classified TransferFunction::classify(double value, double gradient_magnitude) const {
    Classified out;
    out.color = color(value);
    out.opacity = opacity(value);
    if (has_gradient_opacity_) out.opacity = std::clamp(out.opacity * gradient_opacity_(gradient_magnitude)[0], 0.0, 1.0);
    return out;
}

bool TransferFunction::may_have_opacity(double lo, double hi) const {
    if (!(lo <= hi)) return true;  // empty or NaN: unsure
    const double a = coordinate(lo), b = coordinate(hi);
    if (!(a <= b)) return true;
    const std::vector<double>& xs = opacity_.xs();
    const auto& ys = opacity_.ys();
    if (xs.empty()) return true;
    // A coordinate c uses row 0 (c < x_0), the last row (c >= x_last), or rows k-1 and k with k the
    // first row with x_k > c; over [a, b], k runs from upper_bound(a) to upper_bound(b).
    const std::size_t ka = std::size_t(std::upper_bound(xs.begin(), xs.end(), a) - xs.begin());
    const std::size_t kb = std::size_t(std::upper_bound(xs.begin(), xs.end(), b) - xs.begin());
    std::size_t first = ka > 0 ? ka - 1 : 0, last = std::min(kb, xs.size() - 1);
    // b exactly on row kb - 1 takes that row's value (w = 0): row kb is not reached.
    if (kb > 0 && kb < xs.size() && b == xs[kb - 1]) last = kb - 1;
    for (std::size_t k = first; k <= last; ++k)
        if (ys[k][0] != 0.0) return true;
    return false;
}

std::unique_ptr<Classifier> make_classifier(const VolumeSpec& spec, const Volume& volume) {
    if (!spec.classification) return std::make_unique<TransferFunction>(spec.transfer, volume);
    const ClassificationSpec& c = *spec.classification;
    if (c.type == ClassificationSpec::Type::Isovalue)
        return std::make_unique<IsovalueClassifier>(c.isovalues, c.opacity_unit_distance);
    return std::make_unique<BoundaryClassifier>(c.regions, c.opacity_unit_distance);
}

}  // namespace volref
