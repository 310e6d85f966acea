// The one scalar march (core/integrate/march/March.h) against the plain enumeration of the segments
// (for_each_segment, SamplePlacement.h) and against the placements' formulas worked by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/integrate/march/March.h"

namespace volref {
namespace {

std::vector<MarchSample> marched(const std::vector<Interval>& iv, const MarchOptions& o, int stop_after = -1) {
    std::vector<MarchSample> out;
    march(iv, o, [&](const MarchSample& m) {
        out.push_back(m);
        return stop_after < 0 || int(out.size()) < stop_after;
    });
    return out;
}

const std::vector<Interval> kIntervals{{-1.25, 0.4}, {0.9, 3.0}, {3.5, 3.5001}};

TEST(March, MidpointsAreTheSegmentsInOrderBothWays) {
    std::vector<Segment> every;
    for_each_segment(kIntervals, 0.3, [&](const Segment& s) {
        every.push_back(s);
        return true;
    });
    const std::vector<MarchSample> f = marched(kIntervals, {.step = 0.3});
    const std::vector<MarchSample> b = marched(kIntervals, {.step = 0.3, .order = MarchOrder::BackToFront});
    ASSERT_EQ(f.size(), every.size());
    ASSERT_EQ(b.size(), every.size());
    std::size_t k = 0, interval = 0;
    for (std::size_t i = 0; i < every.size(); ++i) {
        EXPECT_EQ(f[i].s.t0, every[i].t0);
        EXPECT_EQ(f[i].s.t1, every[i].t1);
        EXPECT_EQ(f[i].t, every[i].midpoint());
        EXPECT_EQ(f[i].d, every[i].length());
        if (i > 0 && f[i].interval != f[i - 1].interval) {
            ++interval;
            k = 0;
        }
        EXPECT_EQ(f[i].interval, interval);
        EXPECT_EQ(f[i].k, std::int64_t(k++));
        EXPECT_EQ(f[i].n, segment_count(kIntervals[interval], 0.3));
        const MarchSample& r = b[every.size() - 1 - i];
        EXPECT_EQ(r.s.t0, every[i].t0);
        EXPECT_EQ(r.s.t1, every[i].t1);
        EXPECT_EQ(r.interval, f[i].interval);
        EXPECT_EQ(r.k, f[i].k);
    }
    // 1.65 / 0.3 -> 6 segments, 2.1 / 0.3 -> 7, 0.0001 -> 1.
    EXPECT_EQ(every.size(), 14u);
}

TEST(March, ASpanOwnsTheMidpointsInIt) {
    const RaySpan span{0.1, 1.5};
    for (MarchOrder order : {MarchOrder::FrontToBack, MarchOrder::BackToFront}) {
        std::vector<double> expected;
        for_each_segment(kIntervals, 0.3, [&](const Segment& s) {
            if (s.midpoint() >= span.t0 && s.midpoint() < span.t1) expected.push_back(s.midpoint());
            return true;
        });
        if (order == MarchOrder::BackToFront) std::reverse(expected.begin(), expected.end());
        std::vector<double> got;
        for (const MarchSample& m : marched(kIntervals, {.step = 0.3, .span = span, .order = order})) got.push_back(m.t);
        EXPECT_EQ(got, expected);
        EXPECT_GE(got.size(), 3u);  // 0.325 (the first interval's last), 1.05, 1.35, and 0.1 where it rounds up
    }
}

TEST(March, FromTheEntryAndFromTheExitByHand) {
    using Kind = MarchPlacement::Kind;
    const std::vector<Interval> one{{0.0, 1.0}};
    // L / h = 4 exactly: through the exit n = floor(4 + 1 - 0) = 5 samples at 0, 0.25, ..., 1; before
    // the exit n = ceil(4 - 0) = 4.
    MarchOptions o{.step = 0.25, .placement = {Kind::FromEntry, 0.0, true}};
    std::vector<double> t;
    for (const MarchSample& m : marched(one, o)) {
        t.push_back(m.t);
        EXPECT_EQ(m.d, 0.25);
    }
    EXPECT_EQ(t, (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
    o.placement.through_exit = false;
    EXPECT_EQ(marched(one, o).size(), 4u);
    // first = 0.5: through the exit n = floor(4 + 1 - 0.5) = 4 at 0.125, 0.375, 0.625, 0.875.
    o.placement = {Kind::FromEntry, 0.5, true};
    t.clear();
    for (const MarchSample& m : marched(one, o)) t.push_back(m.t);
    EXPECT_EQ(t, (std::vector<double>{0.125, 0.375, 0.625, 0.875}));
    // From the exit, over the hull [0.5, 1.5] of two intervals: 1.5, 1.25, 1.0, 0.75, 0.5.
    o.placement = {Kind::FromExit, 0.0, true};
    t.clear();
    for (const MarchSample& m : marched({{0.5, 0.7}, {1.1, 1.5}}, o)) t.push_back(m.t);
    EXPECT_EQ(t, (std::vector<double>{1.5, 1.25, 1.0, 0.75, 0.5}));
}

// vtk.js's shader loop (HullPartialEnds), by hand. Hull [0, 3.5], h = 1, first (the jitter) 0.5: R = 3.5;
// the entry at 0 for 0.5 step; the counter c = 0.5 (0.5 + 1 < 3.5: t = 0.5), 1.5 (2.5 < 3.5: t = 1.5),
// 2.5 (3.5 < 3.5 fails); the exit at 3.5 for R - c = 1 step. R <= 1 (hull [2, 2.75]): the entry alone,
// for R = 0.75 step. A callback that stops at an inner sample gets no exit sample.
TEST(March, VtkJsShaderLoopByHand) {
    using End = MarchSample::End;
    MarchOptions o{.step = 1.0, .placement = {MarchPlacement::Kind::HullPartialEnds, 0.5, true}};
    const std::vector<MarchSample> m = marched({{0.0, 1.0}, {2.0, 3.5}}, o);
    ASSERT_EQ(m.size(), 4u);
    const double t[] = {0.0, 0.5, 1.5, 3.5}, steps[] = {0.5, 1.0, 1.0, 1.0};
    const End end[] = {End::Entry, End::None, End::None, End::Exit};
    for (std::size_t i = 0; i < m.size(); ++i) {
        EXPECT_EQ(m[i].t, t[i]) << i;
        EXPECT_EQ(m[i].steps, steps[i]) << i;
        EXPECT_EQ(m[i].end, end[i]) << i;
    }
    // first = 1, h = 0.4 over [0, 1.1]: R = 2.75 (rounded); c = 1 (2 < 2.75: t = 0.4), c = 2 (3 < 2.75
    // fails); the exit for 2.75 - 2 = 0.75 step (to rounding).
    o = {.step = 0.4, .placement = {MarchPlacement::Kind::HullPartialEnds, 1.0, true}};
    const std::vector<MarchSample> n = marched({{0.0, 1.1}}, o);
    ASSERT_EQ(n.size(), 3u);
    EXPECT_EQ(n[1].t, 0.4);
    EXPECT_EQ(n[2].t, 1.1);
    EXPECT_NEAR(n[2].steps, 0.75, 1e-15);
    const std::vector<MarchSample> thin = marched({{2.0, 2.75}}, {.step = 1.0, .placement = {MarchPlacement::Kind::HullPartialEnds, 0.5, true}});
    ASSERT_EQ(thin.size(), 1u);
    EXPECT_EQ(thin[0].t, 2.0);
    EXPECT_EQ(thin[0].end, End::Only);
    EXPECT_EQ(thin[0].steps, 0.75);
    EXPECT_EQ(marched({{0.0, 3.5}}, {.step = 1.0, .placement = {MarchPlacement::Kind::HullPartialEnds, 0.5, true}}, 2).size(), 2u);
}

// Seed 001's loop (FromExitFloatSteps): s = t1, s - h, ... in float32 while s >= t0. With h = 0.25 over
// [0, 1] every s is exact: 1, 0.75, 0.5, 0.25, 0. With h = 0.1f over [0.5, 1] float32 rounding decides
// the last sample: the float32 steps give 1, 0.9, 0.79999995, 0.6999999, 0.5999999 and then
// 0.4999999 < 0.5, so five samples, not six as in exact arithmetic (1 - 5 h = 0.5).
TEST(March, SeedOneFloat32LoopByHand) {
    const MarchOptions o{.step = 0.25, .placement = {MarchPlacement::Kind::FromExitFloatSteps, 0.0, true}};
    std::vector<double> t;
    for (const MarchSample& m : marched({{0.0, 1.0}}, o)) t.push_back(m.t);
    EXPECT_EQ(t, (std::vector<double>{1.0, 0.75, 0.5, 0.25, 0.0}));
    const MarchOptions p{.step = double(0.1f), .placement = {MarchPlacement::Kind::FromExitFloatSteps, 0.0, true}};
    const std::vector<MarchSample> m = marched({{0.5, 1.0}}, p);
    float s = 1.0f;
    std::vector<float> expected;
    for (int i = 0; i < 5; ++i, s -= 0.1f) expected.push_back(s);
    ASSERT_EQ(m.size(), 5u);
    for (std::size_t i = 0; i < m.size(); ++i) EXPECT_EQ(float(m[i].t), expected[i]) << i;
    EXPECT_LT(s, 0.5f);  // the sixth value fails the test
    EXPECT_EQ(float(m[3].t), 0.6999999f);
    EXPECT_EQ(float(m[4].t), 0.5999999f);
}

TEST(March, TheCallbackStopsIt) {
    EXPECT_EQ(marched(kIntervals, {.step = 0.3}, 3).size(), 3u);
    EXPECT_EQ(marched(kIntervals, {.step = 0.3, .order = MarchOrder::BackToFront}, 5).size(), 5u);
    EXPECT_EQ(marched({{0.0, 1.0}}, {.step = 0.25, .placement = {MarchPlacement::Kind::FromEntry, 0.0, true}}, 2).size(), 2u);
    EXPECT_TRUE(marched({}, {.step = 0.3}).empty());
}

}  // namespace
}  // namespace volref
