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

std::unique_ptr<Classifier> make_classifier(const VolumeSpec& spec, const Volume& volume) {
    if (!spec.classification) return std::make_unique<TransferFunction>(spec.transfer, volume);
    const ClassificationSpec& c = *spec.classification;
    if (c.type == ClassificationSpec::Type::Isovalue)
        return std::make_unique<IsovalueClassifier>(c.isovalues, c.opacity_unit_distance);
    return std::make_unique<BoundaryClassifier>(c.regions, c.opacity_unit_distance);
}

}  // namespace volref
