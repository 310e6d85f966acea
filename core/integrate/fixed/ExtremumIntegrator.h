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

struct FloatCopies;

class ExtremumIntegrator final : public Integrator {
public:
    ExtremumIntegrator(const IntegrationContext& ctx, bool maximum);
    ~ExtremumIntegrator() override;
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const override;
    PixelValue integrate_traced(const Ray& ray, const std::vector<Interval>& intervals,
                                SampleRecorder& recorder) const override;
    // The SIMD path (PacketExtremum.h) for trilinear volumes, bitwise the scalar result.
    void integrate_packet(const Ray* rays, const std::vector<Interval>* intervals, PixelValue* out,
                          int count) const override;

    // Resumable (march/RaySpan.h): each span's extremum, classified by the span that took it.
    bool resumable() const override { return true; }
    void integrate_span(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                        RayState& state) const override;
    void integrate_span_packet(const Ray* rays, const std::vector<Interval>* intervals, const RaySpan* spans,
                               RayState* states, int count) const override;
    void merge_spans(RayState& front, const RayState& back) const override;
    PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const override;

private:
    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    template <class Rec>
    Extremum<Scalar> extremum(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, Rec& rec) const;
    PixelValue pixel(const Ray& ray, bool any, double t_best) const;
    bool maximum_;
    std::optional<PacketExtremumInputs> packet_;
    std::unique_ptr<FloatCopies> fast_copies_;  // the fast profile's float voxels, when needed
};

}  // namespace volref
