#include "core/integrate/mix/MultiVolumeIntegrator.h"

#include "core/integrate/march/SpanStates.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "core/Cancellation.h"
#include "core/integrate/adaptive/AdaptiveComposite.h"
#include "core/integrate/adaptive/AdaptiveIntegrator.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/integrate/march/March.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/march/Accumulators.h"

namespace volref {

namespace {

using Piece = MultiVolumeIntegrator::Piece;
using Term = MultiVolumeIntegrator::MixTerm;

}  // namespace

bool MultiVolumeIntegrator::MixTerm::operator<(const MixTerm& o) const {
    return std::tie(tau, c.r, c.g, c.b) < std::tie(o.tau, o.c.r, o.c.g, o.c.b);
}

std::vector<Piece> MultiVolumeIntegrator::pieces(const std::vector<Interval>* intervals, std::size_t n) {
    std::vector<double> cuts;
    for (std::size_t k = 0; k < n; ++k)
        for (const Interval& iv : intervals[k]) {
            cuts.push_back(iv.t0);
            cuts.push_back(iv.t1);
        }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    std::vector<Piece> out;
    std::vector<std::size_t> cursor(n, 0);  // each volume's first interval that may contain the piece
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        Piece p{{cuts[i], cuts[i + 1]}, {}};
        for (std::size_t k = 0; k < n; ++k) {
            const std::vector<Interval>& ivs = intervals[k];
            while (cursor[k] < ivs.size() && ivs[cursor[k]].t1 <= p.span.t0) ++cursor[k];
            // Interval ends are cuts, so an interval either covers the whole piece or misses it.
            if (cursor[k] < ivs.size() && ivs[cursor[k]].t0 <= p.span.t0) p.present.push_back(int(k));
        }
        if (!p.present.empty()) out.push_back(std::move(p));
    }
    return out;
}

MultiVolumeIntegrator::MixedSegment MultiVolumeIntegrator::mix(const Ray* rays, const std::vector<int>& present,
                                                               const Segment& s, MixScratch& scratch) const {
    std::vector<Term>& terms = scratch.terms;
    std::vector<Term>& opaque_terms = scratch.opaque_terms;
    terms.clear();
    opaque_terms.clear();
    for (int k : present) {
        const SamplePipeline& pipeline = *volumes_[std::size_t(k)].pipeline;
        const PipelineSample p = pipeline.sample(rays[k], s.midpoint(), SamplePipeline::Use::Composite);
        if (p.opacity <= 0.0) continue;
        if (p.opacity >= 1.0)
            opaque_terms.push_back({0.0, p.color});
        else
            terms.push_back({optical_depth(p.opacity, s.length(), pipeline.classifier().unit_distance()), p.color});
    }
    MixedSegment m;
    if (!opaque_terms.empty()) {
        std::sort(opaque_terms.begin(), opaque_terms.end());
        for (const Term& t : opaque_terms) m.color += t.c;
        m.color /= double(opaque_terms.size());
        m.opaque = true;
    } else if (terms.size() == 1) {
        m.tau = terms[0].tau;
        m.color = terms[0].c;
    } else if (!terms.empty()) {
        std::sort(terms.begin(), terms.end());
        glm::dvec3 weighted(0.0);
        for (const Term& t : terms) {
            m.tau += t.tau;
            weighted += t.tau * t.c;
        }
        if (m.tau > 0.0) m.color = weighted / m.tau;
    }
    return m;
}

MultiVolumeIntegrator::MultiVolumeIntegrator(std::vector<Member> volumes, const RenderSpec& render, double step)
    : volumes_(std::move(volumes)), render_(render), step_(step) {
    if (render_.integrator == IntegrationMethod::Adaptive && is_composite(render_.projection))
        for (const Member& m : volumes_) adaptive_.push_back(std::make_unique<AdaptiveIntegrator>(*m.context));
}

MultiVolumeIntegrator::~MultiVolumeIntegrator() = default;

void MultiVolumeIntegrator::AdaptiveMix::sample(double t, double& sigma, glm::dvec3& c) const {
    terms.clear();
    for (int k : *present) {
        double s;
        glm::dvec3 ck;
        (*parts)[std::size_t(k)]->medium(rays[k], t, s, ck);
        if (s > 0.0) terms.push_back({s, ck});
    }
    sigma = 0.0;
    c = glm::dvec3(0.0);
    if (terms.size() == 1) {
        sigma = terms[0].tau;
        c = terms[0].c;
        return;
    }
    std::sort(terms.begin(), terms.end());  // canonical order: the volumes' listing changes no bit
    glm::dvec3 weighted(0.0);
    for (const Term& term : terms) {
        sigma += term.tau;
        weighted += term.tau * term.c;
    }
    if (sigma > 0.0) c = weighted / sigma;
}

double MultiVolumeIntegrator::adaptive_safety() const {
    double safety = 1.0;
    for (const auto& part : adaptive_) safety = std::max(safety, part->safety());
    return safety;
}

void MultiVolumeIntegrator::adaptive_cuts(const Ray* rays, const Piece& p, std::vector<double>& all, std::vector<double>& cut) const {
    all.clear();
    for (int k : p.present) {
        adaptive_[std::size_t(k)]->cuts(rays[k], p.span, cut);
        all.insert(all.end(), cut.begin(), cut.end());
    }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
}

void MultiVolumeIntegrator::adaptive_piece(const Ray* rays, const std::vector<int>& present, double a, double b,
                                           AdaptiveComposite<AdaptiveMix>& st, std::vector<MixTerm>& opaque) const {
    if (!(b > a)) return;
    // Where the first present volume becomes opaque (AdaptiveIntegrator::opaque_from), and which.
    bool empty = true;
    double ts = std::numeric_limits<double>::infinity();
    for (int k : present) {
        const AdaptiveIntegrator& part = *adaptive_[std::size_t(k)];
        if (!part.empty_piece(rays[k], a, b)) empty = false;
        const double from = part.opaque_from(rays[k], a, b);
        if (from < ts) opaque.clear();
        if (from <= ts && from < b) {
            ts = from;
            opaque.push_back({0.0, part.opaque_colour(rays[k], ts, b)});
        }
    }
    if (ts < b) {  // the mean of the opaque volumes' colours, in canonical order
        if (ts > a) st.integrate(a, ts);
        std::sort(opaque.begin(), opaque.end());
        glm::dvec3 c(0.0);
        for (const Term& o : opaque) c += o.c;
        st.opaque(c / double(opaque.size()));
    } else if (!empty) {
        st.integrate(a, b);
    }
    opaque.clear();
}

PixelValue MultiVolumeIntegrator::adaptive_composite(const Ray* rays, const std::vector<Interval>* intervals) const {
    const std::vector<Piece> ps = pieces(intervals, volumes_.size());
    double total = 0.0;
    for (const Piece& p : ps) total += p.span.length();
    if (!(total > 0.0)) return PixelValue{};
    AdaptiveMix mixed = adaptive_mix(rays);
    AdaptiveComposite<AdaptiveMix> st(mixed, render_.tolerance, adaptive_safety(), total);
    std::vector<double> cut, all;
    std::vector<Term> opaque;
    for (const Piece& p : ps) {
        adaptive_cuts(rays, p, all, cut);
        mixed.present = &p.present;
        for (std::size_t i = 0; i + 1 < all.size() && !st.is_opaque(); ++i) adaptive_piece(rays, p.present, all[i], all[i + 1], st, opaque);
        if (st.is_opaque()) break;
    }
    return st.result();
}

PixelValue MultiVolumeIntegrator::composite(const Ray* rays, const std::vector<Interval>* intervals) const {
    if (!adaptive_.empty()) return adaptive_composite(rays, intervals);
    RayState state;
    composite_span(rays, intervals, RaySpan{}, state);
    PixelValue out;
    out.rgba = composite_state::rgba(state);
    return out;
}

// The one loop of the fixed mix, over the segments `span` owns of every piece: front to back resumes
// FrontToBack's state; back to front puts the span's part behind it (composite_state, SpanStates.h).
void MultiVolumeIntegrator::composite_span(const Ray* rays, const std::vector<Interval>* intervals, const RaySpan& span,
                                           RayState& state) const {
    if (state.stopped != 0.0) return;
    const std::vector<Piece> ps = pieces(intervals, volumes_.size());
    std::vector<Interval> spans(ps.size());  // the pieces' spans: what march() walks
    for (std::size_t i = 0; i < ps.size(); ++i) spans[i] = ps[i].span;
    MixScratch scratch;
    auto mix = [&](const std::vector<int>& present, const Segment& s) { return this->mix(rays, present, s, scratch); };

    // The mixed segments composite as one medium's (march/Accumulators.h): opaque, or optical depth
    // m.tau with alpha = -expm1(-m.tau).
    auto add = [](auto& acc, const MixedSegment& m) {
        const double c[3] = {m.color.r, m.color.g, m.color.b};
        acc.add(true, m.opaque, m.tau, m.opaque ? 1.0 : segment_alpha<Scalar>(m.tau), c);
    };
    if (render_.order == CompositeOrder::FrontToBack) {
        const Termination stop = early_termination(render_);
        FrontToBack<Scalar> acc;
        composite_state::load(acc, state);
        bool done = false;
        march(spans, {.step = step_, .span = span}, [&](const MarchSample& s) {
            const MixedSegment m = mix(ps[s.interval].present, s.s);
            if (!m.opaque && !(m.tau > 0.0)) return true;
            add(acc, m);
            done = m.opaque || acc.stops(true, stop);
            return !done;
        });
        composite_state::save(acc, state);
        state.stopped = done ? 1.0 : 0.0;
    } else {
        BackToFront<Scalar> acc;
        march(spans, {.step = step_, .span = span, .order = MarchOrder::BackToFront}, [&](const MarchSample& s) {
            const MixedSegment m = mix(ps[s.interval].present, s.s);
            if (m.opaque || m.tau > 0.0) add(acc, m);
            return true;
        });
        RayState part;
        composite_state::save_part(glm::dvec3(acc.color(0), acc.color(1), acc.color(2)), acc.optical_depth(), acc.opaque(),
                                   part);
        composite_state::merge(state, part);
    }
}

bool MultiVolumeIntegrator::composite_spans_in_order() const {
    return render_.order == CompositeOrder::FrontToBack && render_.early_termination.has_value();
}

PixelValue MultiVolumeIntegrator::combine(const PixelValue* values, const std::vector<Interval>* intervals) const {
    PixelValue out;
    bool any = false;
    CompensatedSum weighted[4], length, error;
    for (std::size_t k = 0; k < volumes_.size(); ++k) {
        if (intervals[k].empty()) continue;
        const PixelValue& v = values[k];
        switch (accumulation(render_.projection)) {
            case Accumulation::Extremum:
                if (!any) {
                    out.rgba = v.rgba;
                } else {
                    for (int c = 0; c < 4; ++c)
                        out.rgba[c] = takes_maximum(render_.projection) ? std::max(out.rgba[c], v.rgba[c])
                                                                        : std::min(out.rgba[c], v.rgba[c]);
                }
                out.error = std::max(out.error, v.error);
                break;
            case Accumulation::LineIntegral:
                if (takes_mean(render_.projection)) {  // length-weighted
                    double L = 0.0;
                    for (const Interval& iv : intervals[k]) L += iv.length();
                    for (int c = 0; c < 4; ++c) weighted[c].add(L * v.rgba[c]);
                    length.add(L);
                    error.add(L * v.error);
                } else {
                    for (int c = 0; c < 3; ++c) weighted[c].add(v.rgba[c]);
                    error.add(v.error);
                }
                break;
            case Accumulation::FirstHit: {
                const bool nearer = v.depth < out.depth ||
                                    (v.depth == out.depth && std::tie(v.rgba.r, v.rgba.g, v.rgba.b, v.rgba.a) <
                                                                 std::tie(out.rgba.r, out.rgba.g, out.rgba.b, out.rgba.a));
                if (std::isfinite(v.depth) && (!any || nearer)) {
                    out = v;
                    any = true;
                }
                if (!std::isfinite(out.depth)) out.error = std::max(out.error, v.error);
                continue;  // `any` means "a hit" here
            }
            case Accumulation::Composite: break;  // composite() mixes instead
        }
        any = true;
    }
    if (!any) return out;
    if (!is_line_integral(render_.projection)) return out;
    if (takes_mean(render_.projection)) {
        const double g = weighted[0].value() / length.value();
        out.rgba = glm::dvec4(g, g, g, 1.0);
        out.error = error.value() / length.value();
    } else {
        out.rgba = glm::dvec4(weighted[0].value(), weighted[1].value(), weighted[2].value(), 1.0);
        out.error = error.value();
    }
    return out;
}

}  // namespace volref
