// Walking a ray's segments (SamplePlacement.h) with empty-space skipping (conventions section 4): the
// segments whose midpoints lie in an empty macrocell (MacrocellGrid.h) are passed over, every other
// segment is visited exactly as without skipping, in the same order. Shared by the scalar
// CompositeIntegrator and the SIMD packet path, so both visit the same segments.
//
// Extremum mode (mip / minip): instead of the empty flag, a macrocell is passed over when no value it
// can reconstruct beats the ray's extremum so far, *extremum (read each time the walk enters a
// macrocell; NaN, before the first sample, beats nothing): value_bounds(m).hi <= *extremum for the
// maximum, value_bounds(m).lo >= *extremum for the minimum. The extremum only takes strictly better
// values (the first of equal ones wins), so the skipped segments could not have changed it, nor
// where it was first reached.
//
// Per interval, per run: the macrocell m of segment k's midpoint (macrocell_of, the sampler's own
// placement); the segments up to where the ray leaves m (exit_distance, an estimate); if m is empty
// the estimate's last segment is checked (bisected back when it is outside; a short estimate leaves the
// rest to the next check) and the run is skipped: each axis' macrocell index is monotone in k (ray.at,
// the index map, floor and the midpoints are monotone in floating point), so every segment between two
// in m is in m. A visited composite run is at least kMinVisitedRun segments long (empty segments in it
// have opacity 0 and change nothing), to save checks.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/Cancellation.h"
#include "core/Conventions.h"
#include "core/camera/Ray.h"
#include "core/integrate/march/RaySpan.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/sample/MacrocellGrid.h"

namespace volref {

namespace segment_walk {

// The smallest k in [0, n] whose midpoint t0 + (k + 1/2) h is >= t, estimated (rounded); the walks
// below check what they skip against macrocell_at.
inline std::int64_t segment_at_or_after(const Interval& iv, double step, double t, std::int64_t n) {
    const double k = std::ceil((t - iv.t0) / step - 0.5);
    if (!(k > 0.0)) return 0;  // also -inf and NaN
    if (k >= double(n)) return n;
    return std::int64_t(k);
}

// The macrocell in which the pipeline samples segment k (at ray.at(midpoint)).
inline MacrocellGrid::Index macrocell_of(const MacrocellGrid& grid, const Ray& ray, const Interval& iv, double step,
                                  std::int64_t k, std::int64_t n) {
    return grid.macrocell_at(ray.at(segment(iv, step, k, n).midpoint()));
}

// The segments j of one interval that lie in macrocell m form one run (the macrocell index of the
// midpoints is monotone in j); given `in` in it and `out` (> in) past it or n, the last one in it.
template <typename InM>
std::int64_t last_in_run(std::int64_t in, std::int64_t out, InM&& in_m) {
    while (out - in > 1) {
        const std::int64_t mid = in + (out - in) / 2;
        (in_m(mid) ? in : out) = mid;
    }
    return in;
}

}  // namespace segment_walk

// The segments of `intervals` front to back, without those in empty macrocells (all of them when
// `grid` is null). Usage: `Segment s; while (walk.next(s)) ...`.
class ForwardSegmentWalk {
public:
    ForwardSegmentWalk() = default;
    // `span` (march/RaySpan.h): only the segments whose midpoints it owns are visited, placed as on
    // the whole ray.
    ForwardSegmentWalk(const MacrocellGrid* grid, const Ray& ray, const std::vector<Interval>& intervals, double step,
                       const RaySpan& span = RaySpan{})
        : grid_(grid), ray_(&ray), intervals_(&intervals), step_(step), span_(span) {
        if (!intervals.empty()) enter();
    }
    // Extremum mode (see the header comment): `extremum` is the ray's running maximum (`maximum`) or
    // minimum, NaN until its first sample; the caller updates it between calls to next().
    ForwardSegmentWalk(const MacrocellGrid* grid, const Ray& ray, const std::vector<Interval>& intervals, double step,
                       const double* extremum, bool maximum, const RaySpan& span = RaySpan{})
        : ForwardSegmentWalk(grid, ray, intervals, step, span) {
        extremum_ = extremum;
        maximum_ = maximum;
    }

    // The next segment to visit; false after the last, or once SIGINT / SIGTERM is requested (polled every
    // conventions::kCancellationPollSamples segments: the render is then abandoned, Cancellation.h).
    bool next(Segment& s) { return next(s, nullptr, nullptr, nullptr); }
    // The same, with the segment's interval (its index in `intervals`), its index k and the interval's
    // segment count n (march(), March.h).
    bool next(Segment& s, std::size_t* interval, std::int64_t* k, std::int64_t* n) {
        if (++polled_ >= conventions::kCancellationPollSamples) {
            polled_ = 0;
            if (cancel_requested()) return false;
        }
        if (k_ >= end_ && !advance()) return false;
        s = segment((*intervals_)[iv_], step_, k_, n_);
        if (interval) *interval = iv_;
        if (k) *k = k_;
        if (n) *n = n_;
        ++k_;
        return true;
    }

    // The next run of segments to visit, all of one interval: segments [k, end) of `iv`'s n (the same
    // segments next() would return one by one, in the same order); false after the last. The SIMD
    // packets take runs and place the segments themselves (segment()'s arithmetic, inline).
    struct Run {
        const Interval* iv;
        std::int64_t k, end, n;
    };
    // A run is at most kMaxRun segments (a longer one comes as several, the same segments in the same
    // order), so that cancellation is polled between runs.
    bool next_run(Run& r) {
        if (cancel_requested()) return false;
        if (k_ >= end_ && !advance()) return false;
        const std::int64_t end = end_ - k_ > kMaxRun ? k_ + kMaxRun : end_;
        r = {&(*intervals_)[iv_], k_, end, n_};
        k_ = end;
        return true;
    }
    static constexpr std::int64_t kMaxRun = 16 * conventions::kCancellationPollSamples;

private:
    static constexpr std::int64_t kMinVisitedRun = 48;

    // Moves to the next non-empty run [k_, end_) of segments to visit; false when there is none.
    bool advance() {
        using namespace segment_walk;
        while (iv_ < intervals_->size()) {
            const Interval& iv = (*intervals_)[iv_];
            if (k_ < end_) return true;
            if (k_ >= lim_) {
                if (++iv_ < intervals_->size()) enter();
                continue;
            }
            if (!grid_) {
                end_ = lim_;
                continue;
            }
            const MacrocellGrid::Index m = macrocell_of(*grid_, *ray_, iv, step_, k_, n_);
            const bool skip = skippable(m);
            // Composite: an empty m with every macrocell within r - 1 of it empty (empty_radius) is
            // passed over with that whole box; the segments in the box form one run (each axis'
            // macrocell index is monotone in k), so the same segments are visited.
            const std::int64_t r = skip && !extremum_ ? std::max<std::int64_t>(1, grid_->empty_radius(m)) : 1;
            // The estimate: segments k .. end - 1 have their midpoints before the ray leaves the box.
            const std::int64_t end =
                std::clamp<std::int64_t>(segment_at_or_after(iv, step_, grid_->exit_distance(*ray_, m, r), n_), k_ + 1, lim_);
            if (!skip) {
                // Composite: a run that is visited is at least kMinVisitedRun segments long (it may
                // run on into empty macrocells, whose segments have opacity 0 and change nothing), so
                // a ray that grazes many small non-empty runs pays fewer checks.
                end_ = extremum_ ? end : std::max(end, std::min(lim_, k_ + kMinVisitedRun));
                if (extremum_) {
                    // Extremum mode backs off on rays where the checks keep failing (the ray's
                    // extremum is not yet beyond what the macrocells hold): after f failed checks in a
                    // row the run is stretched to 2^min(f, 3) times its length, so such a ray pays for
                    // one check per up to 8 macrocells. Visiting more segments never changes the result.
                    end_ = std::min(lim_, k_ + ((end - k_) << std::min(failed_checks_, 3)));
                    ++failed_checks_;
                }
                continue;
            }
            failed_checks_ = 0;
            auto in_m = [&](std::int64_t j) {
                const MacrocellGrid::Index c = macrocell_of(*grid_, *ray_, iv, step_, j, n_);
                for (int a = 0; a < 3; ++a)
                    if (c[a] < m[a] - (r - 1) || c[a] > m[a] + (r - 1)) return false;
                return true;
            };
            // Segments k .. end - 1 are passed over when the estimate's last one lies in the box (each
            // axis' index is monotone in k, so all before it do); else the run ends earlier and is found
            // by bisection. An estimate that is too short only leaves the rest of the box to the next
            // check, which passes over it in turn.
            std::int64_t last = end - 1;
            if (last > k_ && !in_m(last)) last = last_in_run(k_, last, in_m);
            k_ = end_ = last + 1;  // every segment up to there lies in the empty box: opacity 0
        }
        return false;
    }

    // The first segment and the end of the owned ones of interval iv_ (all of them for the whole ray).
    void enter() {
        n_ = segment_count((*intervals_)[iv_], step_);
        const auto owned = owned_segments((*intervals_)[iv_], step_, n_, span_);
        k_ = end_ = owned.first;
        lim_ = owned.second;
    }

    bool skippable(const MacrocellGrid::Index& m) const {
        if (!extremum_) return grid_->empty(m);
        const std::array<double, 2> b = grid_->value_bounds(m);
        return maximum_ ? b[1] <= *extremum_ : b[0] >= *extremum_;  // false for a NaN extremum
    }

    const MacrocellGrid* grid_ = nullptr;
    const double* extremum_ = nullptr;  // extremum mode
    bool maximum_ = true;
    int failed_checks_ = 0;  // extremum mode: failed checks in a row
    const Ray* ray_ = nullptr;
    const std::vector<Interval>* intervals_ = nullptr;
    double step_ = 1.0;
    RaySpan span_;
    std::size_t iv_ = 0;
    std::int64_t k_ = 0, n_ = 0, end_ = 0;  // segments [k_, end_) are to be visited
    std::int64_t lim_ = 0;                  // the end of the owned segments of interval iv_
    std::int64_t polled_ = 0;               // segments since cancellation was last polled
};

}  // namespace volref
