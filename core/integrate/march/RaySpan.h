// Resumable integration: a ray integrated in parts, each part a span of the ray with the
// accumulator's state handed in and out. volref-mpi's ranks each own the span of a ray inside their
// brick (cli/mpi/); the single-process render integrates the whole ray as one span.
//
//   span      [t0, t1): the samples it owns are those whose position t (a segment's midpoint,
//             SamplePlacement.h) satisfies t0 <= t < t1; the whole ray is [-inf, +inf). The
//             placement is the whole ray's: a span never moves a sample, it only selects samples.
//   state     the accumulator after the spans integrated so far, in RayState's kValues doubles; the
//             layout is the integrator's (composite: FrontToBack's state, see composite_state below).
//   resume    Integrator::integrate_span(ray, intervals, span, state) continues `state` over the
//             span's samples, front to back, exactly as the whole-ray loop would at those samples: a
//             ray cut into spans and integrated span after span gives the whole-ray pixel bit for bit.
//   merge     Integrator::merge_spans(front, back): `back` integrated from a fresh state over a span
//             behind `front`'s; for independent parts (no early termination), equal to resuming up to
//             rounding (composite: C = C_f + exp(-tau_f) C_b, tau = tau_f + tau_b).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/integrate/march/SamplePlacement.h"

namespace volref {

struct RaySpan {
    double t0 = -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    bool whole() const { return t0 == -std::numeric_limits<double>::infinity() && t1 == std::numeric_limits<double>::infinity(); }
    bool owns(double t) const { return t0 <= t && t < t1; }
};

// The segments [first, end) of interval `iv` (n segments at `step`) whose midpoints `span` owns: the
// midpoints increase with k (a + b with a = t0 + k h, b = t0 + (k + 1) h or t1, each monotone in k in
// floating point), so they are one run. Its ends are found from the closed form m_k ~ t0 + (k + 1/2) h:
// k = ceil((t - t0) / h - 1/2), clamped to [0, n], then moved one segment at a time until
// midpoint(k - 1) < t <= midpoint(k) holds with the midpoints computed exactly as the march computes
// them (segment().midpoint()). The monotone predicate has one boundary, so this is the k a bisection
// on k finds (tested against it: RaySpans.OwnedSegmentsAsBisection), in O(1) steps instead of
// log2(n) dependent ones (a span's packet lanes start with it: volref-mpi's ranks).
inline std::pair<std::int64_t, std::int64_t> owned_segments(const Interval& iv, double step, std::int64_t n,
                                                             const RaySpan& span) {
    if (span.whole()) return {0, n};
    // The first k in [0, n] whose midpoint is >= t (n: none).
    auto first_at_or_after = [&](double t) {
        const double x = (t - iv.t0) / step - 0.5;
        std::int64_t k = n;  // (also t NaN: no midpoint is >= it)
        if (x <= 0.0) k = 0;
        else if (x < double(n)) k = std::int64_t(std::ceil(x));
        while (k > 0 && segment(iv, step, k - 1, n).midpoint() >= t) --k;
        while (k < n && segment(iv, step, k, n).midpoint() < t) ++k;
        return k;
    };
    const std::int64_t first = first_at_or_after(span.t0);
    return {first, std::max(first, first_at_or_after(span.t1))};
}

// A ray's integration state between spans: kValues doubles in the integrator's own layout, and
// whether the ray has ended (opaque, terminated early, hit): later spans change nothing then.
// Plain doubles, so that volref-mpi sends states as MPI_DOUBLE arrays (kDoubles per ray).
struct RayState {
    static constexpr int kValues = 10;
    static constexpr int kDoubles = kValues + 1;
    double stopped = 0.0;  // 1: the ray has ended
    double v[kValues] = {};
    // As kDoubles plain doubles (volref-mpi's messages): stopped, then v.
    void write(double* out) const {
        out[0] = stopped;
        std::copy(v, v + kValues, out + 1);
    }
    static RayState read(const double* in) {
        RayState s;
        s.stopped = in[0];
        std::copy(in + 1, in + 1 + kValues, s.v);
        return s;
    }
};

}  // namespace volref
