// CompositeIntegrator: emission-absorption compositing (conventions sections 3 to 5).
//
// Segment k (midpoint value v_k, length d_k) has opacity a_k = a(v_k), colour c_k = c(v_k), optical
// depth tau_k = -(d_k / l) log1p(-a_k) and opacity alpha_k = -expm1(-tau_k).
//   front to back: C += T alpha_k c_k with T = exp(-tau), tau = the compensated sum of the tau_j in
//                  front of k (never a product of (1 - alpha));
//   back to front: C = alpha_k c_k + (1 - alpha_k) C, visiting the same segments from the far end.
// Both give A = -expm1(-tau_total) (1 where a segment has a = 1, which makes everything behind it
// invisible). The pixel is (C, A), premultiplied, accumulated in double.
// Early termination (front to back only): stop after the segment where A first exceeds the threshold.
//
// Empty-space skipping (ctx.macrocells set): runs of segments whose midpoints lie in an empty macrocell
// are not sampled. Such a segment has opacity exactly 0, which both orders ignore, so every pixel is
// bitwise the one without skipping: the other segments are sampled at the same t, with the same length,
// in the same order. The walk, per interval: the macrocell m of segment k's midpoint (macrocell_at, the
// sampler's own placement); the segments up to where the ray leaves m (exit_distance, an estimate);
// if m is empty, the last of them is checked to lie in m too (if not, the last one in m is found by
// bisection; if so, by galloping on and bisecting, as the estimate may also be short) and the run is
// skipped: each axis' macrocell index is monotone in k (ray.at, the index map, floor and the midpoints
// are monotone in floating point), so every segment between two in m is in m. Otherwise the run is
// sampled. Back to front walks the same way from the far end (entry_distance).
#pragma once
#include <memory>
#include <optional>
#include <vector>

#include "core/integrate/Integrator.h"
#include "core/integrate/packet/PacketComposite.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/integrate/march/Accumulators.h"

namespace volref {

// The termination the scene asks for (render.early_termination: stop once A > threshold), as every
// front-to-back integrator of the reference applies it (the composite and the several-volume mix).
Termination early_termination(const RenderSpec& render);

class CompositeIntegrator final : public OneLoopIntegrator<CompositeIntegrator> {
public:
    explicit CompositeIntegrator(const IntegrationContext& ctx);
    ~CompositeIntegrator() override;
    // Whole rays, spans and traces (RayBatch, OneLoopIntegrator): the SIMD path (PacketComposite.h)
    // where the scene allows it and the batch asks for it, else the scalar loops below; the fast
    // profile (FastProfile.h) has only its packet path. Resuming: front to back continues FrontToBack's
    // state (composite_state, SpanStates.h); back to front puts each span's part behind the state; the
    // fast profile continues its float transmittance product (product_state).
    bool has_packet_path() const { return packet_.has_value(); }
    void merge_spans(RayState& front, const RayState& back) const override;
    PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const override;

private:
    friend class OneLoopIntegrator<CompositeIntegrator>;
    // Rec: NoRecording (the render) or Recording (trace); SampleRecorder.h. The one loop of each
    // order, over the samples `span` owns, continuing `acc`; front_to_back returns true once the ray
    // stops (opaque or terminated early).
    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    void integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, RayState& state) const;
    void integrate_packets(const RayBatch& batch) const;
    template <class Rec>
    bool front_to_back(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                       FrontToBack<Scalar>& acc, Rec& rec) const;
    template <class Rec>
    void back_to_front(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                       BackToFront<Scalar>& acc, Rec& rec) const;
    Termination termination_;  // early_termination(render)
    std::optional<PacketRun> packet_;  // set when the SIMD path applies (the volume: ctx.pipeline.view())
};

}  // namespace volref
