// explain composite: a list of samples composited by CompositeIntegrator itself. The samples become a
// ray along +x from the origin through one interval [0, n d] cut into n segments of length d
// (SamplePlacement.h); a field whose value at x is x / d and a classifier that returns sample floor(value)
// hand segment k's midpoint ((k + 1/2) d) sample k. Integrator::integrate_traced records every step
// (SampleRecorder.h), in the chosen order, and both orders are run to show that they agree.
#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/integrate/profiles/FrameBuffer.h"
#include "core/scene/SceneNames.h"
#include "transfer/OpacityCorrection.h"

namespace volref::explain {

namespace {

class SampleNumberField final : public FieldSampler {
public:
    explicit SampleNumberField(double step) : step_(step) {}
    double value(const glm::dvec3& world) const override { return world.x / step_; }

private:
    double step_;
};

class SampleListClassifier final : public Classifier {
public:
    SampleListClassifier(const std::vector<CompositeSample>& s, double l) : samples_(s), l_(l) {}
    Classified classify(double value, double) const override {
        const double k = std::clamp(std::floor(value), 0.0, double(samples_.size() - 1));
        const CompositeSample& s = samples_[std::size_t(k)];
        return {s.color, s.opacity};
    }
    bool needs_gradient() const override { return false; }
    double unit_distance() const override { return l_; }

private:
    const std::vector<CompositeSample>& samples_;
    double l_;
};

struct Run {
    PixelValue pixel;
    SampleList rows;
};

Run run(const std::vector<CompositeSample>& samples, CompositeOrder order, double l, double d) {
    SampleNumberField field(d);
    SampleListClassifier classifier(samples, l);
    SamplePipeline pipeline(field, classifier, nullptr, nullptr, nullptr);
    RenderSpec render;  // projection: composite, the default
    render.order = order;
    const IntegrationContext ctx{pipeline, d, render, nullptr};
    const CompositeIntegrator integrator(ctx);
    Ray ray;
    ray.origin = glm::dvec3(0.0);
    ray.direction = glm::dvec3(1.0, 0.0, 0.0);
    Run r;
    r.pixel = integrator.integrate_traced(ray, {Interval{0.0, double(samples.size()) * d}}, r.rows);
    return r;
}

}  // namespace

Explanation composite(const std::vector<CompositeSample>& samples, CompositeOrder order, double l, double d) {
    if (samples.empty()) throw Error("--samples: at least one sample r,g,b,a is needed");
    for (const CompositeSample& s : samples) {
        if (!(s.opacity >= 0.0 && s.opacity <= 1.0)) throw Error("--samples: an opacity a must be in [0, 1]");
        for (int c = 0; c < 3; ++c)
            if (!(s.color[c] >= 0.0 && std::isfinite(s.color[c])))
                throw Error("--samples: colours r, g, b must be finite and >= 0");
    }
    if (!(l > 0.0 && std::isfinite(l))) throw Error("--unit-distance: must be a finite number > 0");
    if (!(d > 0.0 && std::isfinite(d))) throw Error("--step: must be a finite number > 0");

    Explanation e;
    e.topic = "composite";
    const bool ftb = order == CompositeOrder::FrontToBack;
    Section& in = e.section("inputs");
    add(in, "samples", double(samples.size()), "listed front first: sample 1 is nearest the eye");
    add(in, "l", l, "opacity unit distance: a is the opacity over l");
    add(in, "d", d, "each sample's segment length");

    const Run main = run(samples, order, l, d);
    const Run other = run(samples, ftb ? CompositeOrder::BackToFront : CompositeOrder::FrontToBack, l, d);
    Section& t = e.section(ftb ? "front to back (CompositeIntegrator): C += T alpha c, tau += tau_k"
                               : "back to front (CompositeIntegrator): C = alpha c + (1 - alpha) C, from the far end");
    t.columns = {"sample", "r", "g", "b", "a", "d", "tau_k", "alpha", "T_before", "T_after", "C_r", "C_g", "C_b", "A"};
    for (const SampleRecord& r : main.rows.rows) {
        const std::size_t k = std::size_t(std::floor(r.t / d));  // which input sample (0 = front)
        const CompositeSample& s = samples[std::min(k, samples.size() - 1)];
        t.rows.push_back({double(k + 1), s.color.r, s.color.g, s.color.b, s.opacity, r.length, r.tau, r.alpha,
                          r.transmittance_before, r.transmittance_after, r.accumulated.r, r.accumulated.g,
                          r.accumulated.b, r.accumulated.a});
    }
    t.notes.push_back("tau_k = -(d / l) log1p(-a), alpha = -expm1(-tau_k) (1 for a = 1); T = exp(-tau), A = 1 - T");
    if (ftb)
        t.notes.push_back("T_before: transmittance from the eye to the sample; T_after: past it");
    else
        t.notes.push_back("T_before, T_after: transmittance of what is composited so far (behind the sample)");

    Section& both = e.section("both orders");
    const glm::dvec4 a = main.pixel.rgba, b = other.pixel.rgba;
    const glm::dvec4 f = ftb ? a : b, k = ftb ? b : a;
    add(both, "front to back", {f.r, f.g, f.b, f.a}, "(C, A), premultiplied");
    add(both, "back to front", {k.r, k.g, k.b, k.a});
    add(both, "difference", {f.r - k.r, f.g - k.g, f.b - k.b, f.a - k.a}, "front to back - back to front (rounding only)");
    double m = 0.0;
    for (int c = 0; c < 4; ++c) m = std::max(m, std::fabs(f[c] - k[c]));
    add(both, "max |difference|", m);
    return e;
}

Explanation composite_framebuffer(const std::vector<CompositeSample>& samples, CompositeOrder order, const FrameBufferRules& f) {
    namespace names = scene_names;
    if (samples.empty()) throw Error("--samples: at least one sample r,g,b,a is needed");
    for (const CompositeSample& s : samples) {
        if (!(s.opacity >= 0.0 && s.opacity <= 1.0)) throw Error("--samples: an opacity a must be in [0, 1]");
        for (int c = 0; c < 3; ++c)
            if (!(s.color[c] >= 0.0 && s.color[c] <= 1.0)) throw Error("--samples: with --framebuffer, colours r, g, b are in [0, 1]");
    }
    const bool under = order == CompositeOrder::FrontToBack;
    if (under && f.blend != ProfileRules::Blend::Premultiplied)
        throw Error("--order: front to back blends under the frame buffer, with --blend premultiplied");
    Explanation e;
    e.topic = "composite";
    Section& in = e.section("inputs");
    add(in, "samples", double(samples.size()), "listed front first: sample 1 is nearest the eye");
    in.notes.push_back(std::string("frame buffer ") + names::name_of(names::kFrameBuffers, f.format) + ", blend " +
                       names::name_of(names::kBlends, f.blend) + ", blend_alpha " + names::name_of(names::kBlendAlphas, f.blend_alpha) +
                       ", rounding " + names::name_of(names::kRoundings, f.rounding) + ", products " +
                       names::name_of(names::kBlendProducts, f.products) + " (core/integrate/profiles/FrameBuffer.h)");
    SliceFrameBuffer fb(f.format, f.rounding, f.products, f.blend, f.blend_alpha, under, true);
    const bool eight = f.format == ProfileRules::FrameBuffer::Rgba8;
    const double k = eight ? 255.0 : 1.0;  // rgba8: the table lists codes
    Section& t = e.section(std::string(under ? "front to back (under): C <- C + (1 - A) a c, A <- A + (1 - A) a"
                                             : "back to front, from the far end: C <- src + C (1 - a)") +
                           (eight ? "; codes q = R(255 x)" : ""));
    t.columns = {"sample", "r", "g", "b", "a", "exact_r", "exact_g", "exact_b", "exact_a", "C_r", "C_g", "C_b", "A", "lo_r", "hi_r", "lo_a", "hi_a"};
    for (std::size_t j = 0; j < samples.size(); ++j) {
        const std::size_t i = under ? j : samples.size() - 1 - j;
        const CompositeSample& s = samples[i];
        fb.blend(s.color, s.opacity);
        const glm::dvec4 x = fb.last_exact() * k, c = fb.pixel() * k, lo = fb.low() * k, hi = fb.high() * k;
        t.rows.push_back({double(i + 1), s.color.r, s.color.g, s.color.b, s.opacity, x.r, x.g, x.b, x.a, c.r, c.g, c.b, c.a, lo.r,
                          hi.r, lo.a, hi.a});
    }
    if (eight) {
        t.notes.push_back("a blend of source code q_s, factor f_s, stored Q and factor f_d: exact = (q_s f_s + Q f_d) / 255 (codes), "
                          "stored R(exact), or R(q_s f_s / 255) + R(Q f_d / 255) with rounded products; R(x) = floor(x + 1/2) or floor(x)");
        t.notes.push_back("src-alpha: colour q_s = R(255 c), f_s = q_a, f_d = 255 - q_a; alpha f_s = q_a (src-alpha) or 255 (one); "
                          "premultiplied: q_s = R(255 a c), f_s = 255");
    } else {
        t.notes.push_back("exact: the blend in double from the stored value; C: as the buffer stores it (float32 arithmetic, stored "
                          "float32 or binary16)");
    }
    t.notes.push_back("lo, hi: the band, what any rounding variant stores (FrameBuffer.h)");
    Section& r = e.section("pixel");
    const glm::dvec4 p = fb.pixel();
    add(r, "pixel", {p.r, p.g, p.b, p.a}, eight ? "(C, A) = codes / 255, as the frame buffer holds them" : "(C, A) as stored");
    add(r, "band", fb.band(), "max over R, G, B, A of the distance to the band's ends");
    return e;
}

Explanation opacity_correction(double a, double l, double d) {
    if (!(a >= 0.0 && a <= 1.0)) throw Error("--opacity: a must be in [0, 1]");
    if (!(l > 0.0 && std::isfinite(l))) throw Error("--unit-distance: must be a finite number > 0");
    if (!(d >= 0.0 && std::isfinite(d))) throw Error("--length: must be a finite number >= 0");
    Explanation e;
    e.topic = "opacity-correction";
    Section& in = e.section("inputs");
    add(in, "a", a, "opacity over the unit distance l");
    add(in, "l", l, "opacity unit distance");
    add(in, "d", d, "segment length");
    add(in, "d / l", d / l);
    Section& s = e.section("volref (transfer/OpacityCorrection.h)");
    add(s, "log1p(-a)", std::log1p(-a), "ln(1 - a)");
    add(s, "sigma", extinction(a, l), "extinction -log1p(-a) / l");
    add(s, "tau", optical_depth(a, d, l), "optical depth -(d / l) log1p(-a)");
    const double volref_alpha = opacity_for_length(a, d, l);
    add(s, "alpha", volref_alpha, "-expm1((d / l) log1p(-a)) (0 for d = 0, 1 for a = 1)");
    Section& t = e.section("textbook form");
    const double textbook = 1.0 - std::pow(1.0 - a, d / l);
    add(t, "alpha", textbook, "1 - (1 - a)^(d / l)");
    Section& r = e.section("difference");
    add(r, "textbook - volref", textbook - volref_alpha, "rounding: the expm1/log1p form keeps small a and d accurate");
    return e;
}

}  // namespace volref::explain
