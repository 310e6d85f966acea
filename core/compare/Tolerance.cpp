#include "core/compare/Tolerance.h"

#include <cmath>
#include <cstdio>

#include "core/Error.h"
#include "core/compare/CompareConstants.h"

namespace volref::compare {

double quantisation_bound(const ComparedImage& image, std::size_t pixel, std::size_t channel) {
    if (image.bits <= 0) return 0.0;
    const double q = kQuantisationHalfStep / (std::ldexp(1.0, image.bits) - 1.0);
    if (image.stored.empty() || channel == 3) return q;
    const double u = image.stored[pixel * 4 + channel];  // stored unassociated colour u_s
    const double a = image.stored[pixel * 4 + 3];        // stored alpha a_s
    return q * (a + u) + q * q;                           // |u_s a_s - u a| with |e1|, |e2| <= q
}

std::vector<double> tolerance_map(const ComparedImage& a, const ComparedImage& b, const ToleranceSpec& spec) {
    if (!std::isfinite(spec.absolute) || spec.absolute < 0.0)
        throw Error("--tolerance: expected a number >= 0, got " + std::to_string(spec.absolute));
    if (spec.from_error && a.error.empty() && b.error.empty())
        throw Error("--tolerance-from-error: neither " + a.path.string() + " nor " + b.path.string() +
                    " has an `error` channel");
    const std::size_t pixels = std::size_t(a.rgba.width) * std::size_t(a.rgba.height);
    std::vector<double> tol(pixels * 4, spec.absolute);
    for (std::size_t p = 0; p < pixels; ++p) {
        double e = 0.0;
        if (spec.from_error) {
            if (!a.error.empty()) e += std::abs(a.error[p]);
            if (!b.error.empty()) e += std::abs(b.error[p]);
        }
        for (std::size_t c = 0; c < 4; ++c)
            tol[p * 4 + c] += e + quantisation_bound(a, p, c) + quantisation_bound(b, p, c);
    }
    return tol;
}

std::string describe_tolerance(const ComparedImage& a, const ComparedImage& b, const ToleranceSpec& spec) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", spec.absolute);
    std::string s = buf;
    if (spec.from_error) {
        if (!a.error.empty()) s += " + error channel of A";
        if (!b.error.empty()) s += " + error channel of B";
    }
    if (a.bits > 0) s += " + " + std::to_string(a.bits) + "-bit quantisation of A";
    if (b.bits > 0) s += " + " + std::to_string(b.bits) + "-bit quantisation of B";
    return s;
}

}  // namespace volref::compare
