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

// One call's rays (count <= kMaxPacketRays), and what is asked of them:
//   whole rays:  out[i] = the pixel of rays[i] over intervals[i];
//   spans:       `spans` and `states` set: states[i] continued over the samples spans[i] owns
//                (march/RaySpan.h), front to back; `out` unused;
//   a trace:     `recorder` set (count 1, a whole ray): out[0] as for whole rays, every sample the loop
//                visits reported to the recorder (SampleRecorder.h), the pixel the render's bit for bit.
// `simd`: the SIMD packet path may serve these rays where the integrator has one (each ray's result
// then differs from the scalar loop's by at most that path's documented rounding); else each ray takes
// the scalar loop. An integrator whose lanes are float (the fast profile) has only its packet path.
struct RayBatch {
    const Ray* rays = nullptr;
    const std::vector<Interval>* intervals = nullptr;
    int count = 0;
    PixelValue* out = nullptr;
    const RaySpan* spans = nullptr;
    RayState* states = nullptr;
    SampleRecorder* recorder = nullptr;
    bool simd = false;
    bool resuming() const { return states != nullptr; }
};

// What an integrator can do and writes, fixed when it is built.
struct IntegratorTraits {
    // Its rays can be integrated in spans (RayBatch::spans), the states merged and finished.
    bool resumable = false;
    // A span's result depends on the state in front of it (early termination): the spans must then be
    // resumed in ray order, not merged.
    bool spans_in_order = false;
    bool writes_depth = false;  // the "Z" channel (first-hit)
    bool writes_error = false;  // PixelValue::error is this integrator's error estimate (the "error" channel)
    bool writes_fault = false;  // PixelValue::fault can be set (a mirrored program's loop that cannot end)
};

// Turns rays and their intervals into pixels. One virtual entry point, run(); the others are
// wrappers of it. `intervals` are sorted and disjoint; an empty list gives the background (all zero,
// depth inf).
class Integrator {
public:
    explicit Integrator(const IntegrationContext& ctx) : ctx_(ctx) {}
    virtual ~Integrator() = default;
    virtual void run(const RayBatch& batch) const = 0;
    // `back`, integrated from a fresh state over a span behind `front`'s, added to `front`: equal to
    // resuming `front` over that span up to rounding, where spans_in_order() is false.
    virtual void merge_spans(RayState& front, const RayState& back) const;
    // The pixel of a ray whose spans have all been integrated into `state`.
    virtual PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const;
    // Why the mirrored program does not finish `ray` (empty when it does), for trace and explain.
    virtual std::string fault_reason(const Ray& ray) const {
        (void)ray;
        return {};
    }

    // One ray by the scalar loop (the fast profile: its packet path).
    PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
        PixelValue out;
        run({.rays = &ray, .intervals = &intervals, .count = 1, .out = &out});
        return out;
    }
    // `count` rays at once (count <= kMaxPacketRays), by the SIMD path where there is one.
    void integrate_packet(const Ray* rays, const std::vector<Interval>* intervals, PixelValue* out, int count) const {
        run({.rays = rays, .intervals = intervals, .count = count, .out = out, .simd = true});
    }
    // integrate() by the same loop, reporting every sample it visits to `recorder`, for `volref trace`
    // and `volref explain`. The result is integrate()'s, bit for bit.
    PixelValue integrate_traced(const Ray& ray, const std::vector<Interval>& intervals, SampleRecorder& recorder) const {
        PixelValue out;
        run({.rays = &ray, .intervals = &intervals, .count = 1, .out = &out, .recorder = &recorder});
        return out;
    }
    // Continues `state` over the samples `span` owns: span after span, the whole ray's pixel (finish)
    // is integrate()'s bit for bit.
    void integrate_span(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, RayState& state) const {
        run({.rays = &ray, .intervals = &intervals, .count = 1, .spans = &span, .states = &state});
    }
    // `count` spans at once, by the SIMD path where there is one.
    void integrate_span_packet(const Ray* rays, const std::vector<Interval>* intervals, const RaySpan* spans,
                               RayState* states, int count) const {
        run({.rays = rays, .intervals = intervals, .count = count, .spans = spans, .states = states, .simd = true});
    }

    const IntegratorTraits& traits() const { return traits_; }
    bool resumable() const { return traits_.resumable; }
    bool spans_in_order() const { return traits_.spans_in_order; }
    bool writes_depth() const { return traits_.writes_depth; }
    bool writes_error() const { return traits_.writes_error; }
    bool writes_fault() const { return traits_.writes_fault; }

protected:
    // The error of a batch this integrator cannot serve (spans where it is not resumable, a trace where
    // it has no traced loop).
    [[noreturn]] static void not_resumable();
    [[noreturn]] static void not_traced();
    [[noreturn]] static void packets_not_traced();  // the fast profile's (its packets are its only path)

    const IntegrationContext& ctx_;
    IntegratorTraits traits_;
};

// The shape of every fixed-step integrator: one loop, Derived::integrate_impl(ray, intervals, rec),
// serves both the render (NoRecording) and `volref trace` (Recording, SampleRecorder.h): the same
// statements, so the traced pixel is the rendered one bit for bit. Derived may also have
//   integrate_impl for NoRecording only: there is no traced loop (a trace is an error);
//   integrate_span_impl(ray, intervals, span, state): resumable (else spans are an error);
//   integrate_packets(batch) and has_packet_path(): a SIMD path, taken for batches that ask for it
//   (RayBatch::simd) and, where packets_only_ (float lanes: the fast profile), for every batch.
// Derived befriends this class.
template <class Derived>
class OneLoopIntegrator : public Integrator {
public:
    using Integrator::Integrator;
    void run(const RayBatch& b) const override {
        const Derived& self = static_cast<const Derived&>(*this);
        if constexpr (requires { self.integrate_packets(b); }) {
            if (packets_only_ || (b.simd && !b.recorder && self.has_packet_path())) {
                if (b.recorder) packets_not_traced();
                return self.integrate_packets(b);
            }
        }
        for (int i = 0; i < b.count; ++i) {
            if (b.resuming()) {
                if constexpr (requires { self.integrate_span_impl(b.rays[i], b.intervals[i], b.spans[i], b.states[i]); })
                    self.integrate_span_impl(b.rays[i], b.intervals[i], b.spans[i], b.states[i]);
                else
                    not_resumable();
            } else if (b.recorder) {
                Recording rec{*b.recorder};
                if constexpr (requires { self.integrate_impl(b.rays[i], b.intervals[i], rec); })
                    b.out[i] = self.integrate_impl(b.rays[i], b.intervals[i], rec);
                else
                    not_traced();
            } else {
                NoRecording rec;
                b.out[i] = self.integrate_impl(b.rays[i], b.intervals[i], rec);
            }
        }
    }

protected:
    // The lanes are float (the fast profile): the packet path is the only one.
    bool packets_only_ = false;
};

std::unique_ptr<Integrator> make_integrator(const IntegrationContext& ctx);

}  // namespace volref
