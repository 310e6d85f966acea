// The one scalar ray march (pbrt-v4's SampleT_maj shape): every fixed-step integrator, the
// several-volume mix, the profiles and the texture band are callbacks of march(). It owns the sample
// placement (SamplePlacement.h: the reference's segment midpoints, or a profile's samples from the entry
// or from the exit), the span a caller integrates (RaySpan.h: the samples whose position lies in
// [t0, t1), placed as on the whole ray), the order (front to back, or back to front), empty-space
// skipping (SegmentWalk.h: segments in empty macrocells are passed over; they have opacity 0) and
// cancellation (polled every conventions::kCancellationPollSamples samples). The accumulator's state
// is the caller's: it lives in the callback, and resumes across spans through RayState (SpanStates.h).
//
// The callback gets one MarchSample per sample and returns true to go on, false to stop (opaque, a
// hit, early termination). Its SIMD form is the packet kernels' walk (packet/PacketKernels-inl.h:
// ForwardSegmentWalk::next_run, the same segments in the same order); the mirrored programs' loops are
// placements of it too (vtk.js's shader loop: HullPartialEnds; seed 001's float32 kernel: FromExitFloatSteps).
// Only the adaptive integrator and vtk-cpu's image-space renderer place their samples their own way
// (docs/architecture.md, "One march").
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/Cancellation.h"
#include "core/camera/Ray.h"
#include "core/integrate/march/RaySpan.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/integrate/march/SegmentWalk.h"
#include "core/sample/MacrocellGrid.h"

namespace volref {

// One sample of the march: its position t and the length d it stands for; for the segment placement
// also its segment (t = s.midpoint(), d = s.length()), the interval it lies in and its index k of the
// interval's n segments. A profile's sample from the entry or the exit has s = {t, t}, k and n its count.
// HullPartialEnds also says which sample it is (`end`) and the part of a step it stands for (`steps`).
struct MarchSample {
    enum class End { None, Entry, Exit, Only };
    double t = 0.0, d = 0.0;
    Segment s{0.0, 0.0};
    std::size_t interval = 0;
    std::int64_t k = 0, n = 0;
    End end = End::None;
    double steps = 1.0;
};

enum class MarchOrder { FrontToBack, BackToFront };

// Where the samples lie (SamplePlacement.h; conventions sections 4 and 9).
// HullPartialEnds (vtk.js's vtkVolumeFS.glsl, over the hull [t0, t1] of the intervals, R = (t1 - t0) / h):
// where R <= 1 the entry alone (End::Only, standing for R steps); else the entry (End::Entry, standing
// for `first` steps), then t0 + c h for c = first, first + 1, ... (the shader's float counter, c += 1)
// while c + 1 < R, then where R - c > 0 the exit t1 (End::Exit, standing for R - c steps).
// FromExitFloatSteps (seed 001's CUDA kernel, `for (float s = outAbs; s >= inAbs; s -= step)`): s = t1,
// then s - h, ..., in float32 (t1, t0 and h are floats the caller gives as doubles), while s >= t0;
// the caller checks first that s - h moves s (else the program does not end).
struct MarchPlacement {
    enum class Kind { Midpoints, FromEntry, FromExit, HullPartialEnds, FromExitFloatSteps };
    Kind kind = Kind::Midpoints;
    double first = 0.0;  // FromEntry, HullPartialEnds: the first (inner) sample's distance from the entry, in steps
    bool through_exit = true;  // FromEntry / FromExit: sample_count's rule (ThroughExit, else BeforeExit)
};

struct MarchOptions {
    double step = 1.0;
    MarchPlacement placement{};
    // Midpoints only: the span owned, the order and the skipping grid (null: every segment); `ray`
    // places the segments in the grid's macrocells.
    RaySpan span{};
    MarchOrder order = MarchOrder::FrontToBack;
    const MacrocellGrid* skip = nullptr;
    const Ray* ray = nullptr;
};

namespace march_detail {

enum class StepCountRule { ThroughExit, BeforeExit };

inline MarchSample at_segment(const Segment& s, std::size_t interval, std::int64_t k, std::int64_t n) {
    return {s.midpoint(), s.length(), s, interval, k, n};
}

// The segments `span` owns back to front, without those in empty macrocells (SegmentWalk.h's rule,
// mirrored: each run of one macrocell found from its far end).
template <class Fn>
void reversed(const MacrocellGrid* grid, const Ray& ray, const std::vector<Interval>& intervals, double step,
              const RaySpan& span, Fn&& fn) {
    using namespace segment_walk;
    std::int64_t polled = 0;
    for (std::size_t i = intervals.size(); i-- > 0;) {
        const Interval& iv = intervals[i];
        const std::int64_t n = segment_count(iv, step);
        const auto [first, end] = owned_segments(iv, step, n, span);
        auto visit = [&](std::int64_t k) { return !cancel_polled(polled++) && fn(at_segment(segment(iv, step, k, n), i, k, n)); };
        std::int64_t k = end - 1;
        if (!grid) {
            for (; k >= first; --k)
                if (!visit(k)) return;
            continue;
        }
        while (k >= first) {
            const MacrocellGrid::Index m = macrocell_of(*grid, ray, iv, step, k, n);
            // The estimate: segments begin .. k have their midpoints after the ray enters m.
            const std::int64_t begin =
                std::clamp<std::int64_t>(segment_at_or_after(iv, step, grid->entry_distance(ray, m), n), first, k);
            if (grid->empty(m)) {
                // Indices mirrored (j -> k - j) so that the run again starts at 0 and grows.
                auto in_m = [&](std::int64_t j) { return macrocell_of(*grid, ray, iv, step, k - j, n) == m; };
                std::int64_t in = k - begin, out = k - first + 1;
                if (in > 0 && !in_m(in)) {
                    out = in;  // the estimate is too long
                    in = 0;
                } else {  // too short? gallop backward
                    for (std::int64_t d = 1; in + d <= k - first; d *= 2) {
                        if (!in_m(in + d)) {
                            out = in + d;
                            break;
                        }
                        in += d;
                    }
                }
                k -= last_in_run(in, out, in_m) + 1;  // every segment down to there lies in m: opacity 0
                continue;
            }
            for (; k >= begin; --k)
                if (!visit(k)) return;
        }
    }
}

}  // namespace march_detail

// Calls on_sample(const MarchSample&) for every sample of `intervals` the options select, in order,
// until it returns false.
template <class Fn>
void march(const std::vector<Interval>& intervals, const MarchOptions& o, Fn&& on_sample) {
    const double h = o.step;
    using Kind = MarchPlacement::Kind;
    // The shaders' placements cast one segment through the hull [first t0, last t1] of the intervals.
    const bool over_hull = o.placement.kind == Kind::FromExit || o.placement.kind == Kind::FromExitFloatSteps ||
                           o.placement.kind == Kind::HullPartialEnds;
    if (over_hull && intervals.empty()) return;
    const Interval hull = over_hull ? Interval{intervals.front().t0, intervals.back().t1} : Interval{};
    if (o.placement.kind == Kind::FromExitFloatSteps) {  // seed 001's kernel: float32 s = t1, s - h, ... >= t0
        const float in = float(hull.t0), step = float(h);
        std::int64_t k = 0;
        for (float s = float(hull.t1); s >= in; s -= step, ++k)
            if (cancel_polled(k) || !on_sample(MarchSample{double(s), h, {double(s), double(s)}, 0, k, 0})) return;
        return;
    }
    if (o.placement.kind == Kind::HullPartialEnds) {  // vtk.js's shader loop
        using End = MarchSample::End;
        auto at = [&](double t, std::int64_t k, End end, double steps) {
            MarchSample m{t, h, {t, t}, 0, k, 0};
            m.end = end;
            m.steps = steps;
            return m;
        };
        const double R = (hull.t1 - hull.t0) / h;  // raySteps
        if (R <= 1.0) {  // "handle very thin volumes"
            on_sample(at(hull.t0, 0, End::Only, R));
            return;
        }
        if (!on_sample(at(hull.t0, 0, End::Entry, o.placement.first))) return;
        double travelled = o.placement.first;
        std::int64_t k = 1;
        while (travelled + 1.0 < R) {
            if (cancel_polled(std::int64_t(travelled))) return;
            const double t = hull.t0 + travelled * h;
            travelled += 1.0;
            if (!on_sample(at(t, k++, End::None, 1.0))) return;
        }
        if (R - travelled > 0.0) on_sample(at(hull.t1, k, End::Exit, R - travelled));
        return;
    }
    if (o.placement.kind == Kind::FromExit) {  // seed 001 in double: s = outAbs, outAbs - h, ... >= inAbs
        using R = march_detail::StepCountRule;
        const double n = sample_count(hull, h, 0.0, o.placement.through_exit ? R::ThroughExit : R::BeforeExit);
        for (double k = 0.0; k < n; k += 1.0) {
            const double t = hull.t1 - k * h;
            if (cancel_polled(std::int64_t(k)) || !on_sample(MarchSample{t, h, {t, t}, 0, std::int64_t(k), std::int64_t(n)})) return;
        }
        return;
    }
    if (o.placement.kind == Kind::FromEntry) {
        using R = march_detail::StepCountRule;
        for (std::size_t i = 0; i < intervals.size(); ++i) {
            const Interval& iv = intervals[i];
            const double n = sample_count(iv, h, o.placement.first, o.placement.through_exit ? R::ThroughExit : R::BeforeExit);
            for (double k = 0.0; k < n; k += 1.0) {
                const double t = from_entry_sample(iv, h, o.placement.first, k);
                if (cancel_polled(std::int64_t(k)) || !on_sample(MarchSample{t, h, {t, t}, i, std::int64_t(k), std::int64_t(n)}))
                    return;
            }
        }
        return;
    }
    static const Ray kNoRay{};
    const Ray& ray = o.ray ? *o.ray : kNoRay;  // read only with a skipping grid
    if (o.order == MarchOrder::BackToFront) {
        march_detail::reversed(o.skip, ray, intervals, h, o.span, on_sample);
        return;
    }
    ForwardSegmentWalk walk(o.skip, ray, intervals, h, o.span);
    MarchSample m;
    while (walk.next(m.s, &m.interval, &m.k, &m.n)) {
        m.t = m.s.midpoint();
        m.d = m.s.length();
        if (!on_sample(m)) return;
    }
}

}  // namespace volref
