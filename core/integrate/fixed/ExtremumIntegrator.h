// ExtremumIntegrator: maximum (mip) or minimum (minip) intensity projection (conventions section 6).
// The extremum of the reconstructed value over the ray's sample points (the segment midpoints of
// SamplePlacement.h); the pixel is the classification's colour and opacity at that sample (the first of
// equal extrema), premultiplied: (a c, a), unshaded. A ray with no interval is (0, 0, 0, 0).
#pragma once
#include <memory>
#include <optional>

#include "core/integrate/Integrator.h"
#include "core/integrate/packet/PacketExtremum.h"
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

private:
    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    PixelValue pixel(const Ray& ray, bool any, double t_best) const;
    bool maximum_;
    std::optional<PacketExtremumInputs> packet_;
    std::unique_ptr<FloatCopies> fast_copies_;  // the fast profile's float voxels, when needed
};

}  // namespace volref
