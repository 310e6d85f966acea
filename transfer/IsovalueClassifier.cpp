#include "transfer/IsovalueClassifier.h"

#include <cmath>

namespace volref {

double IsovalueClassifier::contour_opacity(const IsovalueContour& c, double f, double g) {
    const double d = std::fabs(c.value - f);
    if (g == 0.0) return f == c.value ? c.opacity : 0.0;
    if (d <= c.thickness * g) return c.opacity * (1.0 - d / (c.thickness * g));
    return 0.0;
}

Classified IsovalueClassifier::classify(double f, double g) const {
    double transparency = 1.0, weight = 0.0;
    glm::dvec3 weighted(0.0);
    for (const IsovalueContour& c : contours_) {
        const double a = contour_opacity(c, f, g);
        transparency *= 1.0 - a;
        weight += a;
        weighted += a * c.color;
    }
    Classified out;
    out.opacity = 1.0 - transparency;
    if (weight > 0.0) out.color = weighted / weight;
    return out;
}

}  // namespace volref
