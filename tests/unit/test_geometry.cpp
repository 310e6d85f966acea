// Ray intervals through Embree against hand-computed chords.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "geometry/BoundingGeometry.h"

using namespace volref;

namespace {
std::vector<Interval> query(const glm::dvec3& lo, const glm::dvec3& hi, const Ray& ray,
                            glm::dvec3 dlo = glm::dvec3(-100), glm::dvec3 dhi = glm::dvec3(100)) {
    BoundingGeometry g;
    const int id = g.add_box(lo, hi, dlo, dhi);
    g.commit();
    std::vector<Interval> out;
    g.intervals(ray, id, out);
    return out;
}
}  // namespace

TEST(BoxIntervals, AxisAlignedChord) {
    const auto iv = query({0, 0, 0}, {2, 3, 4}, Ray{{1, 1, 10}, {0, 0, -1}});
    ASSERT_EQ(iv.size(), 1u);
    EXPECT_EQ(iv[0].t0, 6.0);
    EXPECT_EQ(iv[0].t1, 10.0);
}

TEST(BoxIntervals, DiagonalChord) {
    // Through the unit cube's diagonal from (-1,-1,-1): enters at t = sqrt(3), leaves at 2 sqrt(3).
    const glm::dvec3 d = glm::normalize(glm::dvec3(1, 1, 1));
    const auto iv = query({0, 0, 0}, {1, 1, 1}, Ray{{-1, -1, -1}, d});
    ASSERT_EQ(iv.size(), 1u);
    EXPECT_NEAR(iv[0].t0, std::sqrt(3.0), 1e-15);
    EXPECT_NEAR(iv[0].t1, 2 * std::sqrt(3.0), 1e-15);
}

TEST(BoxIntervals, CameraInsideStartsAtZero) {
    const auto iv = query({0, 0, 0}, {2, 2, 2}, Ray{{1, 1, 1}, {1, 0, 0}});
    ASSERT_EQ(iv.size(), 1u);
    EXPECT_EQ(iv[0].t0, 0.0);
    EXPECT_EQ(iv[0].t1, 1.0);
}

TEST(BoxIntervals, BoxBehindIsMissed) {
    EXPECT_TRUE(query({0, 0, 0}, {2, 2, 2}, Ray{{1, 1, 5}, {0, 0, 1}}).empty());
}

TEST(BoxIntervals, GrazingAFaceGivesNothingOrTheFace) {
    // Along the face x = 0 (inside the closed box): the whole edge length; just outside: nothing.
    const auto on = query({0, 0, 0}, {2, 2, 2}, Ray{{0, 1, 5}, {0, 0, -1}});
    ASSERT_EQ(on.size(), 1u);
    EXPECT_EQ(on[0].t0, 3.0);
    EXPECT_EQ(on[0].t1, 5.0);
    EXPECT_TRUE(query({0, 0, 0}, {2, 2, 2}, Ray{{-1e-12, 1, 5}, {0, 0, -1}}).empty());
    // Touching an edge only (the single point (0, 1, 2)): zero length, dropped; never NaN.
    const glm::dvec3 d = glm::normalize(glm::dvec3(1, 0, 1));
    EXPECT_TRUE(query({0, 0, 0}, {2, 2, 2}, Ray{{-1, 1, 1}, d}).empty());
    // Entering through that edge and going inside: the full chord from the edge.
    const glm::dvec3 e = glm::normalize(glm::dvec3(1, 0, -1));
    const auto in = query({0, 0, 0}, {2, 2, 2}, Ray{{-1, 1, 3}, e});
    ASSERT_EQ(in.size(), 1u);
    EXPECT_NEAR(in[0].t0, std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(in[0].t1, 3 * std::sqrt(2.0), 1e-15);
}

TEST(BoxIntervals, ClippedToTheDomain) {
    // Bounds larger than the domain: the interval is the domain's chord.
    const auto iv = query({-5, -5, -5}, {5, 5, 5}, Ray{{0.5, 0.5, 10}, {0, 0, -1}}, {0, 0, 0}, {1, 1, 1});
    ASSERT_EQ(iv.size(), 1u);
    EXPECT_EQ(iv[0].t0, 9.0);
    EXPECT_EQ(iv[0].t1, 10.0);
}

TEST(RayIntervals, NormalizeSortsAndMerges) {
    std::vector<Interval> v{{5, 6}, {1, 2}, {1.5, 3}, {7, 7}, {3, 4}};
    normalize_intervals(v);
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].t0, 1.0);
    EXPECT_EQ(v[0].t1, 4.0);
    EXPECT_EQ(v[1].t0, 5.0);
    EXPECT_EQ(v[1].t1, 6.0);
}

// Many rays at once (BoundingGeometry::intervals over a batch: SIMD lanes, BoxIntervals.cpp) give
// each ray the interval that a plain slab test written out here gives it (the second method: std::max /
// std::min and an early return per axis, as the scalar code was before the lane template), bit for bit;
// batches of every length up to 37 (not multiples of the lanes), directions parallel to faces, origins
// inside, boxes behind, and a box that is not its domain.
namespace {
bool plain_slab_test(const glm::dvec3& lo, const glm::dvec3& hi, const Ray& ray, double& t0, double& t1) {
    t0 = -std::numeric_limits<double>::infinity();
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        const double o = ray.origin[a], d = ray.direction[a];
        if (d == 0.0) {
            if (o < lo[a] || o > hi[a]) return false;
            continue;
        }
        double ta = (lo[a] - o) / d, tb = (hi[a] - o) / d;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1;
}
}  // namespace

TEST(BoxIntervals, BatchesAreThePlainSlabTestRayByRay) {
    const glm::dvec3 lo(-3, -2, -1), hi(4, 5, 6), dlo(-1, -1, -1), dhi(2, 3, 4);
    BoundingGeometry g;
    const int own = g.add_box(lo, hi, lo, hi);      // the box is its domain
    const int clipped = g.add_box(lo, hi, dlo, dhi);  // the domain inside the box
    g.commit();
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> pos(-12.0, 12.0), dir(-1.0, 1.0);
    std::uniform_int_distribution<int> kind(0, 5);
    std::vector<Ray> rays(37);
    int hits = 0, parallel = 0;
    for (int round = 0; round < 40; ++round) {
        for (Ray& r : rays) {
            r.origin = {pos(rng), pos(rng), pos(rng)};
            glm::dvec3 d(dir(rng), dir(rng), dir(rng));
            const int k = kind(rng);  // some directions parallel to one or two faces' axes
            if (k < 3) d[k] = 0.0;
            if (k == 3) d[0] = d[1] = 0.0;
            if (k == 4) r.origin = {0.5, 1.0, 1.5};  // inside both
            r.direction = glm::normalize(d);
        }
        for (int count = 1; count <= int(rays.size()); count += 1 + round % 5)
            for (int id : {own, clipped}) {
                std::vector<std::vector<Interval>> out(std::size_t(count), std::vector<Interval>(1, Interval{-7, -7}));
                g.intervals(rays.data(), count, id, out.data());
                for (int i = 0; i < count; ++i) {
                    const Ray& r = rays[std::size_t(i)];
                    double s0, s1, e0, e1;
                    bool hit = plain_slab_test(lo, hi, r, s0, s1);
                    if (id == clipped) hit = hit && plain_slab_test(dlo, dhi, r, e0, e1);
                    else e0 = s0, e1 = s1;
                    const double t0 = std::max({s0, e0, 0.0}), t1 = std::min(s1, e1);
                    hit = hit && t1 > t0;
                    parallel += r.direction.x == 0.0 || r.direction.y == 0.0 || r.direction.z == 0.0;
                    SCOPED_TRACE(testing::Message() << "round " << round << " count " << count << " ray " << i);
                    if (!hit) {
                        EXPECT_TRUE(out[std::size_t(i)].empty());
                        continue;
                    }
                    ++hits;
                    ASSERT_EQ(out[std::size_t(i)].size(), 1u);
                    EXPECT_EQ(out[std::size_t(i)][0].t0, t0);
                    EXPECT_EQ(out[std::size_t(i)][0].t1, t1);
                }
            }
    }
    EXPECT_GT(hits, 1000);  // the batches are not all misses
    EXPECT_GT(parallel, 1000);
}
