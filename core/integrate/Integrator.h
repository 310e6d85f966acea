// Integrator: turns one ray's intervals into one pixel. One implementation per projection
// (conventions section 6); they share the sample placement of SamplePlacement.h and the optical model of
// transfer/OpacityCorrection.h.
#pragma once
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "core/Error.h"
#include "core/camera/Ray.h"
#include "core/integrate/march/RaySpan.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/scene/Scene.h"
#include "geometry/RayIntervals.h"

namespace volref {

class MacrocellGrid;
class SampleRecorder;

// The largest number of rays the renderer hands to Integrator::integrate_packet at once (a block of
// pixels, Renderer.h: two 16-lane packets, whose steps the composite kernel interleaves).
inline constexpr int kMaxPacketRays = 32;

struct PixelValue {
    glm::dvec4 rgba{0.0};  // premultiplied
    double depth = std::numeric_limits<double>::infinity();  // first-hit: distance of the hit (Z)
    double error = 0.0;  // the estimated bound on |error| over R, G, B, A (integrators that write "error")
    // The mirrored program cannot finish this ray (its loop cannot end); rgba is NaN.
    bool fault = false;
};

// What every integrator reads: the sample pipeline, the step in world units, the render settings.
struct IntegrationContext {
    const SamplePipeline& pipeline;
    double step;  // world units, > 0
    const RenderSpec& render;
    // Composite only: empty-space skipping (core/sample/MacrocellGrid.h); null: every segment is sampled.
    const MacrocellGrid* macrocells = nullptr;
    // The lanes the SIMD kernels run on: double (the reference) or float (render.profile "fast",
    // FastProfile.h: the packet path is then the only path). Decided once, where the integrator is
    // chosen (PreparedVolume); the integrators read this, not render.profile.
    enum class Lanes { Double, Float };
    Lanes lanes = Lanes::Double;
    double field(const Ray& ray, double t) const { return pipeline.value(ray, t); }
};

class Integrator {
public:
    explicit Integrator(const IntegrationContext& ctx) : ctx_(ctx) {}
    virtual ~Integrator() = default;
    // `intervals` are sorted and disjoint; an empty list gives the background (all zero, depth inf).
    virtual PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const = 0;
    // `count` rays at once (count <= kMaxPacketRays); the default integrates them one by one.
    // Integrators with a SIMD path override it; each out[i] must equal integrate(rays[i],
    // intervals[i]) up to the documented rounding of that path.
    virtual void integrate_packet(const Ray* rays, const std::vector<Interval>* intervals, PixelValue* out,
                                  int count) const {
        for (int i = 0; i < count; ++i) out[i] = integrate(rays[i], intervals[i]);
    }
    // integrate() by the same loop, reporting every sample it visits to `recorder` (SampleRecorder.h),
    // for `volref trace` and `volref explain`. The result is integrate()'s, bit for bit.
    virtual PixelValue integrate_traced(const Ray& ray, const std::vector<Interval>& intervals,
                                        SampleRecorder& recorder) const {
        (void)ray;
        (void)intervals;
        (void)recorder;
        throw Error("trace: this projection or integrator is not supported yet");
    }
    // Resumable integration (march/RaySpan.h): the ray in spans, the accumulator's state
    // handed from span to span; volref-mpi's ranks each integrate their span. An integrator that
    // cannot be resumed says so (resumable() false; the functions below then throw).
    virtual bool resumable() const { return false; }
    // Continues `state` over the samples `span` owns, front to back: span after span, the whole
    // ray's pixel (finish) is integrate()'s bit for bit.
    virtual void integrate_span(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                                RayState& state) const;
    // `count` rays at once (<= kMaxPacketRays); the default resumes them one by one. Each state must
    // equal integrate_span's up to the documented rounding of the SIMD path.
    virtual void integrate_span_packet(const Ray* rays, const std::vector<Interval>* intervals, const RaySpan* spans,
                                       RayState* states, int count) const {
        for (int i = 0; i < count; ++i) integrate_span(rays[i], intervals[i], spans[i], states[i]);
    }
    // `back`, integrated from a fresh state over a span behind `front`'s, added to `front`: equal to
    // resuming `front` over that span up to rounding, where spans_in_order() is false.
    virtual void merge_spans(RayState& front, const RayState& back) const;
    // The pixel of a ray whose spans have all been integrated into `state`.
    virtual PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const;
    // True when a span's result depends on the state in front of it (early termination): the spans
    // must then be resumed in ray order, not merged.
    virtual bool spans_in_order() const { return false; }

    // The extra channels this projection writes (e.g. "Z" for first-hit).
    virtual bool writes_depth() const { return false; }
    // True when PixelValue::error is this integrator's error estimate (the "error" channel).
    virtual bool writes_error() const { return false; }
    // True when PixelValue::fault can be set (the "fault" channel: a mirrored program's loop that cannot end).
    virtual bool writes_fault() const { return false; }
    // Why the mirrored program does not finish `ray` (empty when it does), for trace and explain.
    virtual std::string fault_reason(const Ray& ray) const {
        (void)ray;
        return {};
    }

protected:
    const IntegrationContext& ctx_;
};

// An integrator whose one loop, Derived::integrate_impl<Rec>(ray, intervals, rec), serves both the
// render (NoRecording) and `volref trace` (Recording, SampleRecorder.h): the same statements, so the
// traced pixel is the rendered one bit for bit. Derived befriends this class.
template <class Derived>
class OneLoopIntegrator : public Integrator {
public:
    using Integrator::Integrator;
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const override {
        NoRecording rec;
        return static_cast<const Derived&>(*this).integrate_impl(ray, intervals, rec);
    }
    PixelValue integrate_traced(const Ray& ray, const std::vector<Interval>& intervals,
                                SampleRecorder& recorder) const override {
        Recording rec{recorder};
        return static_cast<const Derived&>(*this).integrate_impl(ray, intervals, rec);
    }
};

std::unique_ptr<Integrator> make_integrator(const IntegrationContext& ctx);

}  // namespace volref
