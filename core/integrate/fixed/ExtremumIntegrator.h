// ExtremumIntegrator: maximum (mip) or minimum (minip) intensity projection (conventions section 6).
// The extremum of the reconstructed value over the ray's sample points (the segment midpoints of
// SamplePlacement.h); the pixel is the classification's colour and opacity at that sample (the first of
// equal extrema), premultiplied: (a c, a), unshaded. A ray with no interval is (0, 0, 0, 0).
#pragma once
#include <memory>
#include <optional>

#include "core/integrate/Integrator.h"
#include "core/integrate/packet/PacketExtremum.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/SampleRecorder.h"

namespace volref {

class ExtremumIntegrator final : public OneLoopIntegrator<ExtremumIntegrator> {
public:
    ExtremumIntegrator(const IntegrationContext& ctx, bool maximum);
    ~ExtremumIntegrator() override;
    // Whole rays, spans and traces (RayBatch, OneLoopIntegrator): the SIMD path (PacketExtremum.h,
    // bitwise the scalar result) for trilinear volumes where the batch asks for it, else the scalar loop;
    // resuming, each span's extremum, classified by the span that took it.
    bool has_packet_path() const { return packet_.has_value(); }
    void merge_spans(RayState& front, const RayState& back) const override;
    PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const override;

private:
    friend class OneLoopIntegrator<ExtremumIntegrator>;
    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    template <class Rec>
    Extremum<Scalar> extremum(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, Rec& rec) const;
    void integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, RayState& state) const;
    void integrate_packets(const RayBatch& batch) const;
    void merge_extremum(const Ray& ray, double value, double t, RayState& state) const;
    PixelValue pixel(const Ray& ray, bool any, double t_best) const;
    bool maximum_;
    std::optional<PacketRun> packet_;  // set when the SIMD path applies (the volume: ctx.pipeline.view())
};

}  // namespace volref
