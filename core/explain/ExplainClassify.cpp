// explain classify-isovalue / classify-boundary: Levoy's two classifications (conventions section
// 7), every term from IsovalueClassifier / BoundaryClassifier themselves.
#include <cmath>
#include <string>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "transfer/BoundaryClassifier.h"
#include "transfer/IsovalueClassifier.h"

namespace volref::explain {

namespace {

void check_inputs(double f, double g) {
    if (!std::isfinite(f)) throw Error("--value: must be a finite number");
    if (!(g >= 0.0 && std::isfinite(g))) throw Error("--gradient: |grad f| must be a finite number >= 0");
}

std::vector<double> rgb(const glm::dvec3& c) { return {c.r, c.g, c.b}; }

}  // namespace

Explanation classify_isovalue(double f, double g, const std::vector<IsovalueContour>& contours) {
    check_inputs(f, g);
    if (contours.empty()) throw Error("--contour: at least one contour fv,av,r[,R,G,B] is needed");
    Explanation e;
    e.topic = "classify-isovalue";
    Section& in = e.section("inputs");
    add(in, "f", f, "the sample's value");
    add(in, "g", g, "|grad f| (value per world unit)");
    double transparency = 1.0;
    for (std::size_t n = 0; n < contours.size(); ++n) {
        const IsovalueContour& c = contours[n];
        Section& s = e.section("contour " + std::to_string(n + 1));
        add(s, "fv", c.value, "isovalue");
        add(s, "av", c.opacity, "opacity at the isovalue");
        add(s, "r", c.thickness, "half-width in world units");
        add(s, "colour", rgb(c.color));
        const double d = std::fabs(c.value - f);
        add(s, "|f - fv|", d);
        add(s, "r g", c.thickness * g);
        const double a = IsovalueClassifier::contour_opacity(c, f, g);
        std::string why;
        if (g == 0.0)
            why = f == c.value ? "g = 0 and f = fv: a_n = av" : "g = 0 and f != fv: a_n = 0";
        else if (d <= c.thickness * g)
            why = "|f - fv| <= r g: a_n = av (1 - |f - fv| / (r g))";
        else
            why = "|f - fv| > r g: a_n = 0";
        if (g > 0.0) add(s, "|f - fv| / (r g)", d / (c.thickness * g));
        add(s, "a_n", a, why);
        transparency *= 1.0 - a;
    }
    const IsovalueClassifier classifier(contours, 1.0);
    const Classified out = classifier.classify(f, g);
    Section& r = e.section("result (IsovalueClassifier::classify)");
    add(r, "prod (1 - a_n)", transparency);
    add(r, "a", out.opacity, "1 - prod (1 - a_n)");
    add(r, "colour", rgb(out.color), "sum a_n c_n / sum a_n (black where every a_n = 0)");
    return e;
}

Explanation classify_boundary(double f, double g, const std::vector<BoundaryRegion>& regions) {
    check_inputs(f, g);
    if (regions.size() < 2) throw Error("--region: at least two regions fv,av[,R,G,B] are needed");
    for (std::size_t n = 1; n < regions.size(); ++n)
        if (!(regions[n].value > regions[n - 1].value))
            throw Error("--region: values must be strictly increasing (region " + std::to_string(n + 1) + ")");
    Explanation e;
    e.topic = "classify-boundary";
    Section& in = e.section("inputs");
    add(in, "f", f, "the sample's value");
    add(in, "g", g, "|grad f| (value per world unit)");
    for (std::size_t n = 0; n < regions.size(); ++n) {
        const std::string k = std::to_string(n + 1);
        add(in, "fv_" + k, regions[n].value, "region " + k);
        add(in, "av_" + k, regions[n].opacity);
        add(in, "c_" + k, rgb(regions[n].color));
    }
    const BoundaryClassifier classifier(regions, 1.0);
    const BoundaryClassifier::Terms t = classifier.terms(f, g);
    const Classified out = classifier.classify(f, g);
    Section& s = e.section("terms (BoundaryClassifier)");
    if (!t.inside) {
        s.notes.push_back("f is outside [fv_1, fv_N]: a = 0");
    } else {
        const std::string lo = std::to_string(t.n + 1), hi = std::to_string(t.n + 2);
        add(s, "n", double(t.n + 1), "fv_" + lo + " <= f <= fv_" + hi);
        add(s, "w", t.w, "(f - fv_" + lo + ") / (fv_" + hi + " - fv_" + lo + ")");
        add(s, "av_" + lo + " (1 - w)", t.low);
        add(s, "av_" + hi + " w", t.high);
        add(s, "g (sum)", t.unclamped, "Levoy's opacity before the clamp");
    }
    Section& r = e.section("result (BoundaryClassifier::classify)");
    add(r, "a", out.opacity, "clamp(g (av_n+1 w + av_n (1 - w)), 0, 1)");
    add(r, "colour", rgb(out.color), "(av_n+1 w c_n+1 + av_n (1 - w) c_n) / (av_n+1 w + av_n (1 - w))");
    return e;
}

}  // namespace volref::explain
