// Ray intervals through Embree against hand-computed chords.
#include <gtest/gtest.h>

#include <cmath>

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
