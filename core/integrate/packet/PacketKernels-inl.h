// Pieces shared by the SIMD packet kernels (PacketComposite.cpp, PacketExtremum.cpp), compiled once
// per Highway target: the lane walk over intervals and segments (SamplePlacement.h placement) and the
// trilinear reconstruction of a packet of points, term by term as VolumeSampler::trilinear.
// Each is a template over the lane type T: double for the reference profile (the scalar path's
// arithmetic), float for the fast profile (FastProfile.h: twice the lanes, float rounding).
// Per-target include guard (Highway's pattern for -inl headers).
#if defined(VOLREF_PACKET_KERNELS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef VOLREF_PACKET_KERNELS_INL_H_
#undef VOLREF_PACKET_KERNELS_INL_H_
#else
#define VOLREF_PACKET_KERNELS_INL_H_
#endif

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <bit>
#include <new>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/camera/Ray.h"
#include "core/SimdLanes-inl.h"
#include "core/grid/VoxelArray.h"
#include "core/integrate/march/SegmentWalk.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/packet/PairFetch.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace packet {
namespace hn = hwy::HWY_NAMESPACE;

// The double lanes of the reference profile.
using D = hn::ScalableTag<double>;
using DI = hn::RebindToSigned<D>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// A vector of 32-bit values (float or int32, as many lanes as D) as D's lane type: exact for double
// and for float from float; int32 -> float rounds above 2^24 (the fast profile only).
template <class DT, class V32>
HWY_INLINE hn::Vec<DT> to_lanes(DT d, V32 v) {
    if constexpr (std::is_same_v<hn::TFromD<DT>, double>) return hn::PromoteTo(d, v);
    else if constexpr (std::is_same_v<hn::TFromV<V32>, float>) return v;
    else return hn::ConvertTo(d, v);
}

// The lane operations of core/Lanes.h on Highway vectors (core/SimdLanes-inl.h).
using ::volref::HWY_NAMESPACE::SimdLanes;

// Calls kernel.template operator()<T>() with T the packets' lane type: float for the fast profile
// (`fast`), double for the reference.
template <class Kernel>
HWY_INLINE void on_lanes(bool fast, const Kernel& kernel) {
    if (fast) kernel.template operator()<float>();
    else kernel.template operator()<double>();
}

// The optical model and the accumulators, compiled for this target.
#include "transfer/OpacityCorrection-inl.h"
#include "core/integrate/march/Accumulators-inl.h"
#include "core/sample/Trilinear-inl.h"
#include "core/sample/GradientDifference-inl.h"
#include "transfer/Shading-inl.h"
#include "transfer/PiecewiseLinear-inl.h"
#include "transfer/PreIntegration-inl.h"

// Empty-space skipping of the composite packets, decided for all lanes at once:
// what a packet needs of the macrocell grid (MacrocellGrid.h) to find the kernel's cell of a position.
struct VectorSkip {
    // Per octant o of ray directions and macrocell m, at o * (macrocells) + linear(m): the empty distance
    // ahead if m is empty, else minus the solid distance ahead (MacrocellGrid::octant_radii, held by
    // CompositeIntegrator).
    const std::int32_t* radius = nullptr;
    std::int64_t counts[3] = {1, 1, 1};    // macrocells per axis
    std::int64_t dims[3] = {1, 1, 1};      // voxels per axis
    double origin[3] = {0, 0, 0};          // the lanes' positions' origin of the grid (0: float lanes' local coordinates)
    double inv_spacing[3] = {1, 1, 1};
    double end_margin = 0.0;  // pre-integrated segments: h / 2 (a skipped segment's ends lie in the box too)
};

// The rays of a packet (SoA) and each lane's walk over its segments (ForwardSegmentWalk: the same
// segments as the scalar path, with empty-space skipping when `grid` is set); lanes beyond `count`
// never become active. The walk is in double; the lanes hold its values rounded to T.
//
// With a VectorSkip (composite, float or double lanes) the walks do not skip; instead, after every
// lane's segment k is placed, its position p = o + t d in T (the kernel's own arithmetic) gives the
// cell the kernel's trilinear read uses, cell = min(floor(clamp((p - origin) / s, 0, n - 1)), n - 2),
// (origin: the grid's on double lanes, 0 on float lanes, whose positions are local), and its macrocell
// m = cell / M (M = kMacrocellSize, 8); where the empty distance ahead of m for the lane's octant o of
// directions is r >= 1 (MacrocellGrid::octant_radii: the macrocells m + (i s0, j s1, k s2),
// 0 <= i, j, k < r, s the direction's signs, are all empty), the ray stays in that cube B for dt = the
// distance to B's exit face along the ray (index space, per axis: B spans cells [m M, (m + r) M) where
// the ray moves up (or not at all), [(m - r + 1) M, (m + 1) M) where it moves down), less 0.01 cell
// and, for pre-integrated segments, less h / 2. The lane then moves on to the first segment whose midpoint lies at or after t + dt:
// every segment passed over samples inside B (positions within dt of p), so it reads voxels of
// empty macrocells only and its opacity is 0 exactly; the image is the image without skipping. The
// lane's new segment is placed in the same step (and checked again), replacing the empty sample; with
// pre-integrated segments the segment at p is kept (its ends may lie outside B) and the lane moves on
// after it. Lanes whose p lies outside the grid's index range (clamped) are not moved. A lane in a
// non-empty m whose solid distance ahead is r (octant_radii: the cube of r^3 macrocells ahead of m,
// as above, all non-empty) is not checked again before it leaves that cube (the same exit, with r),
// since no empty macrocell lies in it.
template <typename T>
struct RayPacketT {
    static constexpr std::size_t kLanes = HWY_LANES(T);
    static constexpr bool kFloatLanes = std::is_same_v<T, float>;
    // Float lanes place segment k of an interval from the start of its block of 2^23 segments (next()).
    static constexpr std::int64_t kFloatRunBlock = std::int64_t(1) << 23;
    using V_ = hn::Vec<hn::ScalableTag<T>>;
    HWY_ALIGN T ox[kLanes], oy[kLanes], oz[kLanes], dx[kLanes], dy[kLanes], dz[kLanes];
    HWY_ALIGN T tm[kLanes], len[kLanes], live[kLanes];
    // Local coordinates (float lanes, the fast profile): each lane's ray starts at its first entry
    // point t_ref, relative to `local_origin` (the volume's origin), both in double before rounding,
    // and tm holds t - t_ref; so a volume far from the world origin loses no float precision
    // (in float world coordinates a volume at 5e5 from the origin is 0.235 off). t_ref = 0 and world
    // coordinates otherwise.
    HWY_ALIGN double t_ref[kLanes] = {};
    HWY_ALIGN T t_ref_lane[kLanes] = {};
    // Each real lane's walk, constructed in place for the lanes < count (the others are never read:
    // inactive from the start), so that no walk is built twice (a default and then the real one).
    static_assert(std::is_trivially_destructible_v<ForwardSegmentWalk>, "the union below never destroys a walk");
    union {
        ForwardSegmentWalk walk[kLanes];
    };
    // Each lane's current run (ForwardSegmentWalk::next_run) in T (next(): double lanes count from the
    // interval's start, float lanes from their block's): its next segment k, the end of the run, the
    // interval's last segment, the base t0 (double: the interval's start; float: the block's start,
    // local) and the interval's end t1.
    HWY_ALIGN T run_k[kLanes] = {}, run_end[kLanes] = {}, run_last[kLanes] = {}, run_t0[kLanes] = {},
                run_t1[kLanes] = {}, run_live[kLanes] = {};
    double step = 1.0;
    bool active[kLanes];
    std::size_t lanes = 0;

    // `extremum` (mip / minip skipping, SegmentWalk.h's extremum mode): each lane's running extremum,
    // kLanes values the caller keeps up to date (NaN before a lane's first sample).
    RayPacketT(const Ray* rays, const std::vector<Interval>* intervals, int count, double step,
               const MacrocellGrid* grid = nullptr, const double* extremum = nullptr, bool maximum = true,
               const double* local_origin = nullptr, const RaySpan* spans = nullptr,
               const VectorSkip* vector_skip = nullptr) {
        lanes = hn::Lanes(hn::ScalableTag<T>());
        this->step = step;
        vskip_ = grid && !extremum ? vector_skip : nullptr;
        if (vskip_) grid = nullptr;  // the walks place every segment; next() skips
        for (std::size_t l = 0; l < lanes; ++l) {
            const bool real = int(l) < count;
            const Ray& r = rays[real ? l : 0];
            if (local_origin) {
                const double t0 = real && !intervals[l].empty() ? intervals[l].front().t0 : 0.0;
                t_ref[l] = t0;
                t_ref_lane[l] = T(t0);
                ox[l] = T(r.origin.x + t0 * r.direction.x - local_origin[0]);
                oy[l] = T(r.origin.y + t0 * r.direction.y - local_origin[1]);
                oz[l] = T(r.origin.z + t0 * r.direction.z - local_origin[2]);
            } else {
                ox[l] = T(r.origin.x);
                oy[l] = T(r.origin.y);
                oz[l] = T(r.origin.z);
            }
            dx[l] = T(r.direction.x);
            dy[l] = T(r.direction.y);
            dz[l] = T(r.direction.z);
            active[l] = real;
            const RaySpan span = spans && real ? spans[l] : RaySpan{};  // (march/RaySpan.h)
            if (real && vskip_ && intervals[l].size() == 1) {
                // One interval, skipping on the lanes (the walk places every segment): the walk would hand
                // out one run, the segments [k0, k1) of the n whose midpoints the span owns ([0, n) for the
                // whole ray: owned_segments, as the walk's own start), when k1 - k0 <= kMaxRun, and no more;
                // taken here (take_run), no walk built. (k0 = k1: the lane takes no sample, as with a walk.)
                const Interval& iv = intervals[l].front();
                const std::int64_t n = segment_count(iv, step);
                const auto [k0, k1] = owned_segments(iv, step, n, span);
                if (k1 - k0 <= ForwardSegmentWalk::kMaxRun) {
                    single_run_[l] = true;
                    take_run(l, ForwardSegmentWalk::Run{&iv, k0, k1, n});
                    continue;
                }
            }
            if (real) {
                if (extremum) new (&walk[l]) ForwardSegmentWalk(grid, rays[l], intervals[l], step, extremum + l, maximum, span);
                else new (&walk[l]) ForwardSegmentWalk(grid, rays[l], intervals[l], step, span);
            }
        }
        for (std::size_t l = 0; l < kLanes; ++l) recheck_[l] = -std::numeric_limits<T>::infinity();
        if (vskip_) {
            // The grid's constants in T (and the macrocell counts in int32), converted once per packet
            // (skip_empty is not inlined: converting there cost 1.5% of the fast kernel's instructions).
            for (int a = 0; a < 3; ++a) {
                skip_origin_[a] = T(vskip_->origin[a]);
                skip_inv_[a] = T(vskip_->inv_spacing[a]);
                skip_hi_[a] = T(vskip_->dims[a] - 1);
                skip_top_[a] = T(vskip_->dims[a] - 2);
                skip_counts_[a] = std::int32_t(vskip_->counts[a]);
            }
            // Per lane: index units per unit of t along each axis (rounded from double), then on the
            // vectors (the same correctly rounded divisions) 1 / |rate| and the margin.
            const std::int64_t macrocells = vskip_->counts[0] * vskip_->counts[1] * vskip_->counts[2];
            for (std::size_t l = 0; l < lanes; ++l) {
                rate_[0][l] = T(double(dx[l]) * vskip_->inv_spacing[0]);
                rate_[1][l] = T(double(dy[l]) * vskip_->inv_spacing[1]);
                rate_[2][l] = T(double(dz[l]) * vskip_->inv_spacing[2]);
                // The lane's octant of directions (VectorSkip::radius): its radii's offset.
                const int octant = (rate_[0][l] < T(0) ? 1 : 0) + (rate_[1][l] < T(0) ? 2 : 0) + (rate_[2][l] < T(0) ? 4 : 0);
                octant_offset_[l] = std::int32_t(octant * macrocells);
            }
            const hn::ScalableTag<T> d;
            const auto zero = hn::Zero(d), one = hn::Set(d, T(1)), inf = hn::Set(d, std::numeric_limits<T>::infinity());
            for (std::size_t i = 0; i < kLanes; i += hn::Lanes(d)) {
                auto fastest = zero;
                for (int a = 0; a < 3; ++a) {
                    const auto speed = hn::Abs(hn::Load(d, rate_[a] + i));
                    hn::Store(hn::IfThenElse(hn::Gt(speed, zero), hn::Div(one, speed), inf), d, inv_speed_[a] + i);
                    fastest = hn::Max(fastest, speed);
                }
                // dt's margin: 0.01 cell at the fastest axis' rate, and the pre-integrated segments' h / 2.
                hn::Store(hn::Add(hn::Div(hn::Set(d, T(0.01)), fastest), hn::Set(d, T(vskip_->end_margin))), d, margin_ + i);
            }
        }
    }
    // Moves every active lane to its next segment and fills tm (midpoints), len (lengths) and live
    // (1/0); false when no lane is active any more. A lane whose run is used up takes the next one from
    // its walk (ForwardSegmentWalk::next_run); then every lane's segment is placed at once, on vectors
    // of T, with segment()'s arithmetic (SamplePlacement.h) from the lane's base t0: a = t0 + k h, b = t1
    // for the interval's last segment, else t0 + (k + 1) h; midpoint (a + b) / 2, length b - a.
    // Double lanes: t0 is the interval's start and k the segment's index in it, so every value is the
    // scalar path's. Float lanes (the fast profile, conventions section 9b): t0 is the start of the
    // segment's block, t0 + k_b h with k_b = the largest multiple of 2^23 <= its index (0 below 2^23
    // segments), computed in double and rounded to float in the lane's local t (t - t_ref), and k
    // counts from k_b (exact in float); so a float lane's a = float(t0 + k_b h - t_ref) + k h in float.
    bool next() {
        const hn::ScalableTag<T> d;
        const std::size_t nv = hn::Lanes(d);
        const auto zero = hn::Zero(d);
        // Lanes whose run is used up (k >= end) go back to their walk; the check is on vectors, the
        // refill lane by lane (one lane in a run's length of steps).
        bool refill = !started_;
        started_ = true;
        for (std::size_t i = 0; i < lanes && !refill; i += nv)
            refill = !hn::AllFalse(d, hn::And(hn::Gt(hn::Load(d, run_live + i), zero),
                                              hn::Ge(hn::Load(d, run_k + i), hn::Load(d, run_end + i))));
        if (refill) {
            live_count_ = 0;
            for (std::size_t l = 0; l < lanes; ++l) {
                if (active[l] && run_k[l] >= run_end[l]) {
                    ForwardSegmentWalk::Run r;
                    if (!single_run_[l] && walk[l].next_run(r)) {
                        take_run(l, r);
                    } else {
                        active[l] = false;
                    }
                }
                run_live[l] = active[l] ? T(1) : T(0);
                live_count_ += active[l] ? 1 : 0;
            }
        }
        if (live_count_ == 0) return false;
        const auto one = hn::Set(d, T(1));
        for (std::size_t i = 0; i < lanes; i += nv) {
            const auto k = hn::Load(d, run_k + i);
            const auto on = hn::Gt(hn::Load(d, run_live + i), zero);
            V_ mid, length;
            place(i, k, mid, length);
            hn::Store(hn::IfThenElse(on, hn::Add(k, one), k), d, run_k + i);
            hn::Store(hn::IfThenElseZero(on, mid), d, tm + i);
            hn::Store(hn::IfThenElseZero(on, length), d, len + i);
            hn::Store(hn::IfThenElseZero(on, one), d, live + i);
        }
        // A lane moved on takes its new segment in this same step (checked again: it may land in
        // another empty box), so that no step is spent on a sample known to be empty.
        if (vskip_ && any_due())
            for (int pass = 0; pass < 8 && skip_empty(); ++pass) {
            }
        return true;
    }
    // Ends lane l's ray (opaque or terminated early): the lane is inactive from the next step on.
    void retire(std::size_t l) {
        if (!active[l]) return;
        active[l] = false;
        run_live[l] = T(0);
        --live_count_;
    }

private:
    // Lane l's run r (ForwardSegmentWalk::next_run) in T: next k, end, last segment, base t0 and t1 (the
    // comment above run_k); the lane is due for skip_empty's check.
    void take_run(std::size_t l, const ForwardSegmentWalk::Run& r) {
        recheck_[l] = -std::numeric_limits<T>::infinity();
        if constexpr (kFloatLanes) {
            // The base is the start of the block of kFloatRunBlock segments holding the
            // run's first one: the same for every run in the block, so a span resumed
            // mid-ray (march/RaySpan.h) places its samples as the whole ray does.
            static_assert(kFloatRunBlock + ForwardSegmentWalk::kMaxRun <= (std::int64_t(1) << 24),
                          "indices within a block exact in float");
            const std::int64_t kb = r.k / kFloatRunBlock * kFloatRunBlock;
            run_k[l] = T(r.k - kb);
            run_end[l] = T(r.end - kb);
            // Only equality with k < end matters: a last segment beyond the run is never reached.
            run_last[l] = T(std::min<std::int64_t>(r.n - 1, r.end) - kb);
            run_t0[l] = T(r.iv->t0 + double(kb) * step - t_ref[l]);
            run_t1[l] = T(r.iv->t1 - t_ref[l]);
        } else {
            run_k[l] = double(r.k);
            run_end[l] = double(r.end);
            run_last[l] = double(r.n - 1);
            run_t0[l] = r.iv->t0;
            run_t1[l] = r.iv->t1;
        }
    }
    // The live lanes of [i, i + lanes of T) due for skip_empty's check: their t at or past recheck_.
    HWY_INLINE hn::Mask<hn::ScalableTag<T>> due(std::size_t i) const {
        const hn::ScalableTag<T> d;
        return hn::And(hn::Gt(hn::Load(d, live + i), hn::Zero(d)), hn::Ge(hn::Load(d, tm + i), hn::Load(d, recheck_ + i)));
    }
    // Whether any lane is due: inline, so that a step where none is costs no call.
    HWY_INLINE bool any_due() const {
        const hn::ScalableTag<T> d;
        for (std::size_t i = 0; i < lanes; i += hn::Lanes(d))
            if (!hn::AllFalse(d, due(i))) return true;
        return false;
    }
    // VectorSkip (the comment above RayPacketT): moves each lane whose sample lies in an empty macrocell
    // past the samples that stay in its empty box, placing its new segment on the vectors (place(), as
    // next() does; a lane at the end of its run takes no sample this step). True when a lane was moved.
    bool skip_empty() {
        const hn::ScalableTag<T> d;
        const hn::Rebind<std::int32_t, decltype(d)> di;  // int32 lanes, as many as d's
        const std::size_t nf = hn::Lanes(d);
        const VectorSkip& s = *vskip_;
        const auto zero = hn::Zero(d);
        constexpr int kM = conventions::kMacrocellSize;
        static_assert(std::has_single_bit(unsigned(kM)), "the shift below is the division by kMacrocellSize");
        constexpr int kShift = std::countr_zero(unsigned(kM));
        const auto h = hn::Set(d, T(step)), half = hn::Set(d, T(0.5)), one = hn::Set(d, T(1));
        bool any = false;
        for (std::size_t i = 0; i < lanes; i += nf) {
            const auto t = hn::Load(d, tm + i);
            // A lane found in a non-empty macrocell is not checked again before it can have left it.
            if (hn::AllFalse(d, due(i))) continue;
            const auto P0 = hn::Add(hn::Load(d, ox + i), hn::Mul(t, hn::Load(d, dx + i)));
            const auto P1 = hn::Add(hn::Load(d, oy + i), hn::Mul(t, hn::Load(d, dy + i)));
            const auto P2 = hn::Add(hn::Load(d, oz + i), hn::Mul(t, hn::Load(d, dz + i)));
            const hn::Vec<decltype(d)> P[3] = {P0, P1, P2};
            auto inside = hn::Gt(hn::Load(d, live + i), zero);
            hn::Vec<decltype(di)> mc[3];
            hn::Vec<decltype(d)> u[3];
            for (int a = 0; a < 3; ++a) {
                const auto hi = hn::Set(d, skip_hi_[a]);
                u[a] = hn::Mul(hn::Sub(P[a], hn::Set(d, skip_origin_[a])), hn::Set(d, skip_inv_[a]));
                inside = hn::And(inside, hn::And(hn::Ge(u[a], zero), hn::Le(u[a], hi)));
                const auto cell = s.dims[a] == 1 ? zero : hn::Min(hn::Floor(hn::Min(hn::Max(u[a], zero), hi)), hn::Set(d, skip_top_[a]));
                // the cell (an integer below 2^31) as int32 lanes
                if constexpr (std::is_same_v<T, float>) mc[a] = hn::ShiftRight<kShift>(hn::ConvertTo(di, cell));
                else mc[a] = hn::ShiftRight<kShift>(hn::DemoteTo(di, cell));
            }
            if (hn::AllFalse(d, inside)) {
                hn::Store(hn::Set(d, -std::numeric_limits<T>::infinity()), d, recheck_ + i);
                continue;
            }
            const auto idx = hn::Add(hn::Load(di, octant_offset_ + i),
                                     hn::Add(mc[0], hn::Mul(hn::Set(di, skip_counts_[0]), hn::Add(mc[1], hn::Mul(hn::Set(di, skip_counts_[1]), mc[2])))));
            hn::Mask<decltype(di)> inside32;  // `inside` on the int32 lanes
            if constexpr (std::is_same_v<T, float>) inside32 = hn::RebindMask(di, inside);
            else inside32 = hn::Ne(hn::DemoteTo(di, hn::IfThenElseZero(inside, hn::Set(d, T(1)))), hn::Zero(di));
            const auto safe = hn::IfThenElseZero(inside32, idx);
            const auto r = hn::IfThenElseZero(inside32, hn::GatherIndex(di, s.radius, safe));
            const auto radius = to_lanes(d, r);  // exact
            const auto empty = hn::Gt(radius, zero);
            // The exit of the cube ahead of m whose macrocells are all empty (r = the empty distance
            // ahead) or all non-empty (r = the solid distance ahead; m itself where r = 0): per axis
            // [m, m + r) up, (m - r, m] down, so the face ahead is m M + r M up, m M - (r - 1) M down, in
            // index units.
            const auto rf = hn::Max(hn::Abs(radius), hn::Set(d, T(1)));
            auto dt = hn::Set(d, std::numeric_limits<T>::infinity());
            for (int a = 0; a < 3; ++a) {
                const auto rate = hn::Load(d, rate_[a] + i);
                const auto low = hn::Mul(to_lanes(d, mc[a]), hn::Set(d, T(kM)));  // m's first cell
                const auto lo = hn::Sub(low, hn::Mul(hn::Sub(rf, hn::Set(d, T(1))), hn::Set(d, T(kM))));
                const auto hi = hn::Add(low, hn::Mul(rf, hn::Set(d, T(kM))));
                const auto face = hn::IfThenElse(hn::Lt(rate, zero), lo, hi);
                dt = hn::Min(dt, hn::Mul(hn::Abs(hn::Sub(face, u[a])), hn::Load(d, inv_speed_[a] + i)));
            }
            // Non-empty lanes inside the grid: the next check where they leave the box of non-empty
            // macrocells around m (no empty space before it); the others every step.
            const auto solid = hn::AndNot(empty, inside);
            hn::Store(hn::IfThenElse(solid, hn::Add(t, dt), hn::Set(d, -std::numeric_limits<T>::infinity())), d, recheck_ + i);
            if (hn::AllFalse(d, empty)) continue;
            dt = hn::Sub(dt, hn::Load(d, margin_ + i));
            const auto jump = hn::And(empty, hn::Gt(dt, zero));
            if (hn::AllFalse(d, jump)) continue;
            // The first segment of the run whose midpoint is at or after t + dt: k = ceil((t + dt - t0) / h
            // - 1/2) (in T: on float lanes the 0.01-cell margin covers its rounding); a lane moves only past
            // the segment just placed (k > its next k - 1).
            const auto kk = hn::Load(d, run_k + i);
            const auto k = hn::Ceil(hn::Sub(hn::Div(hn::Sub(hn::Add(t, dt), hn::Load(d, run_t0 + i)), h), half));
            const auto go = hn::And(jump, hn::Gt(k, hn::Sub(kk, one)));
            if (hn::AllFalse(d, go)) continue;
            const auto end = hn::Load(d, run_end + i);
            if (s.end_margin > 0.0) {
                // Pre-integrated segments: the segment just placed stays (its ends may lie outside the
                // box although its midpoint is inside); the lane moves on after it.
                hn::Store(hn::IfThenElse(go, hn::Min(k, end), kk), d, run_k + i);
                continue;
            }
            any = true;
            // At the end of its run a lane takes no sample this step (the walk refills it next step);
            // otherwise it takes segment k now (and is checked again).
            const auto used_up = hn::And(go, hn::Ge(k, end));
            const auto placed = hn::AndNot(used_up, go);
            V_ mid, length;
            place(i, k, mid, length);
            hn::Store(hn::IfThenElse(placed, mid, hn::IfThenElseZero(hn::Not(used_up), t)), d, tm + i);
            hn::Store(hn::IfThenElse(placed, length, hn::IfThenElseZero(hn::Not(used_up), hn::Load(d, len + i))), d, len + i);
            hn::Store(hn::IfThenElseZero(hn::Not(used_up), hn::Load(d, live + i)), d, live + i);
            hn::Store(hn::IfThenElse(used_up, end, hn::IfThenElse(placed, hn::Add(k, one), kk)), d, run_k + i);
        }
        return any;
    }
    // The segment k of the run of the lanes [i, i + lanes of T) (next()'s arithmetic): its midpoint and length.
    HWY_INLINE void place(std::size_t i, V_ k, V_& mid, V_& length) const {
        const hn::ScalableTag<T> d;
        const auto h = hn::Set(d, T(step)), half = hn::Set(d, T(0.5)), one = hn::Set(d, T(1));
        const auto t0 = hn::Load(d, run_t0 + i);
        const auto a = hn::Add(t0, hn::Mul(k, h));
        const auto b = hn::IfThenElse(hn::Eq(k, hn::Load(d, run_last + i)), hn::Load(d, run_t1 + i),
                                      hn::Add(t0, hn::Mul(hn::Add(k, one), h)));
        mid = hn::Mul(half, hn::Add(a, b));
        length = hn::Sub(b, a);
    }

    const VectorSkip* vskip_ = nullptr;
    T skip_origin_[3] = {}, skip_inv_[3] = {}, skip_hi_[3] = {}, skip_top_[3] = {};
    std::int32_t skip_counts_[3] = {};
    HWY_ALIGN T rate_[3][kLanes] = {};
    HWY_ALIGN T inv_speed_[3][kLanes] = {};  // 1 / |rate| (+inf where the ray is parallel to the axis' planes)
    HWY_ALIGN T margin_[kLanes] = {};
    HWY_ALIGN std::int32_t octant_offset_[kLanes] = {};  // o * (macrocells): the lane's radii (VectorSkip::radius)
    // Where each lane's next check is due (local t): the exit of the non-empty macrocell it was last
    // found in, -inf when due now (a new run, a moved lane, outside the grid).
    HWY_ALIGN T recheck_[kLanes];
    bool started_ = false;
    bool single_run_[kLanes] = {};  // the lane's one run set by the constructor (no walk built)
    std::size_t live_count_ = 0;
};
using RayPacket = RayPacketT<double>;

// Trilinear reconstruction of a regular grid for packets of world points (VolumeSampler::trilinear:
// u = clamp((x - origin) inv_spacing, 0, n - 1), cell min(floor(u), n - 2), Levoy's sum in order).
// The voxels are read in their storage type (VoxelArray) and converted to double exactly, so the sum
// is the same whatever the type. One switch on the type per packet sample, then per type:
//   f64: each x-neighbour pair as one 128-bit load per lane (four rows, split into even and odd lanes),
//     64-bit index gathers on a grid one voxel wide in x or the one-lane target;
//   f32: each x-neighbour pair f(i, j, k), f(i + 1, j, k) as one 64-bit load (x_pair), promoted;
//   i32, u32: 32-bit gathers with int32 indices, promoted to double (u32: read as i32, plus 2^32
//     where negative, exact);
//   u16, i16, u8, i8: a 32-bit gather of the word that ends with the sample (VoxelArray pads the
//     buffer, so the bytes before the first sample are inside the allocation; little-endian hosts),
//     shifted right by 16 or 24 bits (logical for unsigned, arithmetic for signed types);
//   anything else (a volume of 2^31 samples or bytes or more, or a big-endian host): lane by lane.
// With float lanes (the fast profile) the position, weights and sum are float, the corner index is
// computed in int32, and the storage must be one of the 32-bit-gathered kinds (f32, i32, u32, u16,
// i16, u8, i8: FastProfile.h converts anything else to f32 first).
template <typename T>
struct PacketTrilinearT {
    using D = hn::ScalableTag<T>;
    using DI = hn::RebindToSigned<D>;
    using V = hn::Vec<D>;
    using DI32 = hn::Rebind<std::int32_t, D>;
    using DU32 = hn::Rebind<std::uint32_t, D>;
    using DF32 = hn::Rebind<float, D>;
    static constexpr bool kFloat = std::is_same_v<T, float>;
    enum class Kind { F64, F32, I32, U32, U16, I16, U8, I8, Lanes };

    const void* voxels;
    ScalarType type;
    Kind kind;
    V org[3], inv[3], maxi[3], top[3];
    bool flat[3];
    bool pairs = false;  // float lanes, F32 with x-neighbours: fetched as 64-bit pairs (x_pair)
    bool pair_gathers = false;  // the pairs by 64-bit gathers instead of loads (PairFetch.h; the same values)
    V nx, nxy;
    hn::Vec<DI> offx, offy, offz;
    hn::Vec<DI32> offx32, offy32, offz32, nx32, nxy32;
    std::int32_t row_y = 0, row_z = 0;  // offy32, offz32 as numbers: the pairs' rows (corners)

    PacketTrilinearT() = default;  // unset: assigned before use
    PacketTrilinearT(const void* data, ScalarType data_type, const std::int64_t dims[3], const double origin[3],
                     const double inv_spacing[3]) {
        const D d;
        const DI di;
        const DI32 di32;
        voxels = data;
        type = data_type;
        for (int a = 0; a < 3; ++a) {
            org[a] = hn::Set(d, T(origin[a]));
            inv[a] = hn::Set(d, T(inv_spacing[a]));
            maxi[a] = hn::Set(d, T(dims[a] - 1));
            top[a] = hn::Set(d, T(dims[a] - 2));
            flat[a] = dims[a] == 1;
        }
        nx = hn::Set(d, T(dims[0]));
        nxy = hn::Set(d, T(dims[0] * dims[1]));
        offx = hn::Set(di, flat[0] ? 0 : 1);
        offy = hn::Set(di, flat[1] ? 0 : hn::TFromD<DI>(dims[0]));
        offz = hn::Set(di, flat[2] ? 0 : hn::TFromD<DI>(dims[0] * dims[1]));
        const std::uint64_t count = std::uint64_t(dims[0]) * std::uint64_t(dims[1]) * std::uint64_t(dims[2]);
        const bool fits32 = count * scalar_type_size(type) < (std::uint64_t(1) << 31) - 64;
        const std::int64_t unit = std::int64_t(scalar_type_size(type) < 4 ? scalar_type_size(type) : 1);
        // 32-bit offsets: in elements for the 4-byte types, in bytes for the 1- and 2-byte ones.
        offx32 = hn::Set(di32, std::int32_t(fits32 ? (flat[0] ? 0 : 1) * unit : 0));
        offy32 = hn::Set(di32, std::int32_t(fits32 ? (flat[1] ? 0 : dims[0]) * unit : 0));
        offz32 = hn::Set(di32, std::int32_t(fits32 ? (flat[2] ? 0 : dims[0] * dims[1]) * unit : 0));
        row_y = hn::GetLane(offy32);
        row_z = hn::GetLane(offz32);
        nx32 = hn::Set(di32, std::int32_t(fits32 ? dims[0] : 0));
        nxy32 = hn::Set(di32, std::int32_t(fits32 ? dims[0] * dims[1] : 0));
        constexpr bool little = std::endian::native == std::endian::little;
        switch (type) {
            case ScalarType::F64: kind = Kind::F64; break;
            case ScalarType::F32: kind = fits32 ? Kind::F32 : Kind::Lanes; break;
            case ScalarType::I32: kind = fits32 ? Kind::I32 : Kind::Lanes; break;
            case ScalarType::U32: kind = fits32 ? Kind::U32 : Kind::Lanes; break;
            case ScalarType::U16: kind = fits32 && little ? Kind::U16 : Kind::Lanes; break;
            case ScalarType::I16: kind = fits32 && little ? Kind::I16 : Kind::Lanes; break;
            case ScalarType::U8: kind = fits32 && little ? Kind::U8 : Kind::Lanes; break;
            case ScalarType::I8: kind = fits32 && little ? Kind::I8 : Kind::Lanes; break;
            default: kind = Kind::Lanes; break;
        }
        // Pairs: f32 voxels on float and double lanes (loaded without a buffer),
        // where the reference's step-1 frame measured 18% faster than with 32-bit gathers on AVX-512;
        // not on Highway's one-lane scalar target.
        pairs = kind == Kind::F32 && !flat[0] && little && hn::MaxLanes(D()) >= 2 && HWY_TARGET != HWY_SCALAR;
        pair_gathers = pairs && pair_fetch_gathers();
    }

    // The eight corners f1..f8 (Levoy's order) of the cells at `idx` (i + nx j + nx ny k, any index
    // vector type), each fetched by g.
    template <class IV, class G>
    static HWY_INLINE void eight(IV idx, IV ox, IV oy, IV oz, const G& g, V f[8]) {
        f[0] = g(idx);
        f[1] = g(hn::Add(idx, ox));
        f[2] = g(hn::Add(hn::Add(idx, ox), oy));
        f[3] = g(hn::Add(idx, oy));
        const IV idz = hn::Add(idx, oz);
        f[4] = g(idz);
        f[5] = g(hn::Add(idz, ox));
        f[6] = g(hn::Add(hn::Add(idz, ox), oy));
        f[7] = g(hn::Add(idz, oy));
    }
    // The same eight corners as x-neighbour pairs, four rows from the cells' first voxels `row`
    // (Levoy's order: f1 f2, f4 f3, f5 f6, f8 f7): pair(row, first, second) reads the pairs of the rows
    // at row, row + ry (the next y), row + rz (the next z) and row + rz + ry.
    template <class E, class I, class G>
    static HWY_INLINE void four_pairs(const E* row, I ry, I rz, const G& pair, V f[8]) {
        pair(row, f[0], f[1]);
        pair(row + ry, f[3], f[2]);
        pair(row + rz, f[4], f[5]);
        pair(row + rz + ry, f[7], f[6]);
    }

    // A 32-bit word ending with each 1- or 2-byte sample, shifted down to the sample.
    template <int kShift, bool kSigned>
    HWY_INLINE V narrow(hn::Vec<DI32> byte_offset) const {
        const D d;
        const DI32 di32;
        const DU32 du32;
        const auto* base = reinterpret_cast<const std::int32_t*>(static_cast<const char*>(voxels) - (4 - (32 - kShift) / 8));
        const auto word = hn::GatherOffset(di32, base, byte_offset);
        if constexpr (kSigned) return to_lanes(d, hn::ShiftRight<kShift>(word));
        else return to_lanes(d, hn::BitCast(di32, hn::ShiftRight<kShift>(hn::BitCast(du32, word))));
    }

    HWY_INLINE void corners(V cell0, V cell1, V cell2, V f[8]) const {
        const D d;
        const DI di;
        const DI32 di32;
        const DF32 df32;
        if constexpr (kFloat) {
            if (kind == Kind::F64 || kind == Kind::Lanes) {  // excluded by FastProfile.h
                for (int c = 0; c < 8; ++c) f[c] = hn::Zero(d);
                return;
            }
        } else if (kind == Kind::F64 || kind == Kind::Lanes) {
            // i + nx j + nx ny k, exact in double.
            const auto idx = hn::Add(hn::ConvertTo(di, hn::Add(cell0, hn::Mul(nx, cell1))), hn::ConvertTo(di, hn::Mul(nxy, cell2)));
            if (kind == Kind::F64) {
                const auto* p = static_cast<const double*>(voxels);
#if HWY_TARGET != HWY_SCALAR
                if (!flat[0]) {
                    // x-neighbours f(i, j, k), f(i + 1, j, k) as one 128-bit load per lane, four rows (as
                    // x_pair for f32): the same doubles as the eight gathers below, half the loads.
                    HWY_ALIGN std::int64_t ix[RayPacketT<T>::kLanes];
                    hn::Store(idx, di, ix);
                    const std::int64_t ry = hn::GetLane(offy), rz = hn::GetLane(offz);
                    const std::size_t half = hn::Lanes(d) / 2;
                    four_pairs(p, ry, rz, [&](const double* row, V& first, V& second) HWY_ATTR {
                        split_pairs(load_pairs(d, row, ix), load_pairs(d, row, ix + half), first, second);
                    }, f);
                    return;
                }
#endif
                eight(idx, offx, offy, offz, [&](hn::Vec<DI> i) HWY_ATTR { return hn::GatherIndex(d, p, i); }, f);
            } else {
                eight(idx, offx, offy, offz, [&](hn::Vec<DI> i) HWY_ATTR { return lanes(i); }, f);
            }
            return;
        }
        // The same index, exact in double and < 2^31, as int32 (in bytes for the 1- and 2-byte types);
        // float lanes compute it in int32 (a float holds integers exactly only up to 2^24).
        hn::Vec<DI32> idx;
        if constexpr (kFloat) {
            idx = index32(cell0, cell1, cell2);
            if (kind == Kind::U16 || kind == Kind::I16) idx = hn::Add(idx, idx);
        } else {
            V index = hn::Add(hn::Add(cell0, hn::Mul(nx, cell1)), hn::Mul(nxy, cell2));
            if (kind == Kind::U16 || kind == Kind::I16) index = hn::Add(index, index);
            idx = hn::DemoteTo(di32, index);
        }
        switch (kind) {
            case Kind::F32: {
                const auto* p = static_cast<const float*>(voxels);
                if (pair_gathers) {  // the same pairs, gathered (PairFetch.h)
                    four_pairs(p, row_y, row_z, [&](const float* row, V& first, V& second) HWY_ATTR {
                        x_pair_gathered(row, idx, first, second);
                    }, f);
                    break;
                }
                if (pairs) {
                    // x-neighbours f(i, j, k), f(i + 1, j, k) as one 64-bit load: four fetches of
                    // pairs instead of eight gathers (four_pairs).
                    // The lanes' indices stored once (as unsigned: they are >= 0, so a 32-bit move
                    // zero-extends them); the four rows of a cell are the same indices from four base
                    // pointers (p, p + n_x, p + n_x n_y, p + n_x + n_x n_y), so each lane's index is
                    // read once, not once per row.
                    HWY_ALIGN std::uint32_t ix[RayPacketT<T>::kLanes];
                    hn::Store(hn::BitCast(DU32(), idx), DU32(), ix);
                    four_pairs(p, row_y, row_z, [&](const float* row, V& first, V& second) HWY_ATTR { x_pair(row, ix, first, second); }, f);
                    break;
                }
                eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR { return to_lanes(d, hn::GatherIndex(df32, p, i)); }, f);
                break;
            }
            case Kind::I32: {
                const auto* p = static_cast<const std::int32_t*>(voxels);
                eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR { return to_lanes(d, hn::GatherIndex(di32, p, i)); }, f);
                break;
            }
            case Kind::U32: {
                const auto* p = static_cast<const std::int32_t*>(voxels);
                const V two32 = hn::Set(d, T(4294967296.0)), zero = hn::Zero(d);
                eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR {
                    const V s = to_lanes(d, hn::GatherIndex(di32, p, i));
                    return hn::IfThenElse(hn::Lt(s, zero), hn::Add(s, two32), s);
                }, f);
                break;
            }
            case Kind::U16: eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR { return narrow<16, false>(i); }, f); break;
            case Kind::I16: eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR { return narrow<16, true>(i); }, f); break;
            case Kind::U8: eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR { return narrow<24, false>(i); }, f); break;
            case Kind::I8: eight(idx, offx32, offy32, offz32, [&](hn::Vec<DI32> i) HWY_ATTR { return narrow<24, true>(i); }, f); break;
            default: break;
        }
    }

    // f32 voxels: the floats p[i] and p[i + 1] for each lane l's index i = ix[l] (in floats), each pair read as
    // one 64-bit load (little-endian: the lower half is p[i]) straight into a vector's 64-bit part
    // (load_pairs: the halves joined by Combine, no round trip through memory), then split into even
    // and odd floats (promoted on double lanes). Plain loads, not gather instructions, except where
    // PairFetch.h chooses gathers (x_pair_gathered): gathers are microcoded on AMD's CPUs (the speed-limit
    // note; on the EPYC 5% to 25% faster than 64-bit gathers), and faster on Intel's.
    HWY_INLINE void x_pair(const float* p, const std::uint32_t* ix, V& first, V& second) const {
        const D d;
#if HWY_TARGET == HWY_SCALAR
        (void)p, (void)ix, (void)d;  // pairs is false on the scalar target
        first = second = V();
#else
        if constexpr (kFloat) {
            split_pairs(load_pairs(d, p, ix), load_pairs(d, p, ix + hn::Lanes(d) / 2), first, second);  // p[i0] p[i0 + 1] p[i1] ...
        } else {
            split_pairs(load_pairs(hn::Repartition<float, D>(), p, ix), first, second);
        }
#endif
    }
    // x_pair's values from 64-bit gathers at the byte offsets 4 idx (PairFetch.h): each 64-bit word read is
    // the pair p[i], p[i + 1] (any alignment), so the words in lane order are load_pairs' vector.
    HWY_INLINE void x_pair_gathered(const float* p, hn::Vec<DI32> idx, V& first, V& second) const {
        const D d;
#if HWY_TARGET == HWY_SCALAR
        (void)p, (void)idx, (void)d;  // pairs is false on the scalar target
        first = second = V();
#else
        const auto* words = reinterpret_cast<const std::int64_t*>(p);
        if constexpr (kFloat) {
            // n float lanes: two gathers of n / 2 words, the lanes' lower and upper halves.
            const hn::Repartition<std::int64_t, D> d64;
            const hn::Half<DI32> dh32;
            split_pairs(hn::BitCast(d, hn::GatherOffset(d64, words, hn::ShiftLeft<2>(hn::PromoteTo(d64, hn::LowerHalf(dh32, idx))))),
                        hn::BitCast(d, hn::GatherOffset(d64, words, hn::ShiftLeft<2>(hn::PromoteTo(d64, hn::UpperHalf(dh32, idx))))),
                        first, second);
        } else {
            // n double lanes: one gather of n words.
            const hn::RebindToSigned<D> d64;
            split_pairs(hn::BitCast(hn::Repartition<float, D>(), hn::GatherOffset(d64, words, hn::ShiftLeft<2>(hn::PromoteTo(d64, idx)))),
                        first, second);
        }
#endif
    }
#if HWY_TARGET != HWY_SCALAR
    // The lanes' pairs in lane order (float lanes: `lo` the lower half's lanes, `hi` the upper's) split into
    // the even floats p[i] (first) and the odd p[i + 1] (second).
    static HWY_INLINE void split_pairs(V lo, V hi, V& first, V& second) {
        const D d;
        first = hn::ConcatEven(d, hi, lo);
        second = hn::ConcatOdd(d, hi, lo);
    }
    // Double lanes: the n pairs fill a float vector of 2n lanes; its even and odd floats, promoted exactly.
    template <class VF>
    static HWY_INLINE void split_pairs(VF pairs, V& first, V& second) {
        const D d;
        const hn::Repartition<float, D> df2;
        first = hn::PromoteTo(d, hn::LowerHalf(hn::ConcatEven(df2, pairs, pairs)));
        second = hn::PromoteTo(d, hn::LowerHalf(hn::ConcatOdd(df2, pairs, pairs)));
    }
#endif
#if HWY_TARGET != HWY_SCALAR
    // The pairs p[ix[j]], p[ix[j] + 1] for j < (lanes of DP) / 2, in order: a load of two elements per pair
    // (64 bits of f32, 128 of f64), the halves of a wider vector built the same way and joined.
    template <class DP, typename E, typename I>
    static HWY_INLINE hn::Vec<DP> load_pairs(DP dp, const E* p, const I* ix) {
        if constexpr (hn::MaxLanes(DP()) <= 2) {
            return hn::LoadU(dp, p + ix[0]);
        } else {
            const hn::Half<DP> dh;
            constexpr std::size_t kHalfPairs = hn::MaxLanes(DP()) / 4;
            return hn::Combine(dp, load_pairs(dh, p, ix + kHalfPairs), load_pairs(dh, p, ix));
        }
    }
#endif

    // Lane by lane (64-bit indices), any storage type (double lanes).
    HWY_INLINE V lanes(hn::Vec<DI> idx) const {
        const D d;
        const DI di;
        HWY_ALIGN hn::TFromD<DI> ix[RayPacketT<T>::kLanes];
        HWY_ALIGN T out[RayPacketT<T>::kLanes];
        hn::Store(idx, di, ix);
        const std::size_t n = hn::Lanes(d);
        dispatch_scalar_type(type, [&](auto tag) {
            using S = decltype(tag);
            const S* p = static_cast<const S*>(voxels);
            for (std::size_t l = 0; l < n; ++l) out[l] = T(p[ix[l]]);
        });
        return hn::Load(d, out);
    }

    // The cells and fractions of the points (x, y, z) (Trilinear-inl.h: clamped_index, cell_of).
    HWY_INLINE void cells(V x, V y, V z, V cell[3], V frac[3]) const {
        using L = SimdLanes<T>;
        const V X[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) cell_of<L>(clamped_index<L>(X[a], org[a], inv[a], maxi[a]), top[a], flat[a], cell[a], frac[a]);
    }
    // Float lanes: the cells' index i + n_x j + n_x n_y k in int32 (exact: the grid fits 32 bits where
    // it is read by index, `fits32`).
    HWY_INLINE hn::Vec<DI32> index32(V cell0, V cell1, V cell2) const {
        const DI32 di32;
        return hn::Add(hn::Add(hn::ConvertTo(di32, cell0), hn::Mul(nx32, hn::ConvertTo(di32, cell1))),
                       hn::Mul(nxy32, hn::ConvertTo(di32, cell2)));
    }

    // A hint: the four x-rows of the cells at (x, y, z) of every kLaneStride-th lane requested (f32
    // pairs only; nothing is read).
    template <int kLaneStride>
    HWY_INLINE void prefetch(V x, V y, V z) const {
        if (!pairs) return;
        V cell[3], frac[3];
        cells(x, y, z, cell, frac);
        HWY_ALIGN std::int32_t ix[RayPacketT<T>::kLanes];
        hn::Store(index32(cell[0], cell[1], cell[2]), DI32(), ix);
        const auto* p = static_cast<const float*>(voxels);
        for (std::size_t l = 0; l < hn::Lanes(D()); l += kLaneStride) {
            const float* q = p + ix[l];
            __builtin_prefetch(q);
            __builtin_prefetch(q + row_y);
            __builtin_prefetch(q + row_z);
            __builtin_prefetch(q + row_z + row_y);
        }
    }

    // VolumeSampler::trilinear on lanes: the same templates (Trilinear-inl.h), the corners gathered.
    HWY_INLINE V operator()(V x, V y, V z) const {
        using L = SimdLanes<T>;
        V cell[3], frac[3];
        cells(x, y, z, cell, frac);
        V f[8];
        corners(cell[0], cell[1], cell[2], f);
        return trilinear_sum<L>(f, frac[0], frac[1], frac[2]);
    }
};
using PacketTrilinear = PacketTrilinearT<double>;

}  // namespace packet
}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
