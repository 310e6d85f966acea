// volref-mpi's bricks (cli/mpi/Bricks.h; conventions §14): the k-d split by hand, the lattice over
// several (transformed) grids by hand, each grid's voxels for a brick by hand, and ownership as a
// partition (every point in exactly one brick). Bricks.cpp needs no MPI, so these run in every
// build, the sanitizers' included.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/mat4x4.hpp>

#include "cli/mpi/Bricks.h"
#include "cli/mpi/PartBuffer.h"
#include "core/Error.h"

namespace {

using namespace volref;
using namespace volref::mpi;

TEST(MpiBricks, KdSplitByHand) {
    // 10 x 4 x 6 cells, 3 ranks: x (longest) cut at 0 + (10 * 1 + 3 / 2) / 3 = 3 for 1 : 2 ranks;
    // then [3, 10) (7 cells, longer than z's 6) cut at 3 + (7 * 1 + 1) / 2 = 7.
    Lattice cells;
    cells.hi = {10, 4, 6};
    const std::vector<Brick> b = split_lattice(cells, 3);
    ASSERT_EQ(b.size(), 3u);
    EXPECT_EQ(b[0].lo, (std::array<std::int64_t, 3>{0, 0, 0}));
    EXPECT_EQ(b[0].hi, (std::array<std::int64_t, 3>{3, 4, 6}));
    EXPECT_EQ(b[1].lo, (std::array<std::int64_t, 3>{3, 0, 0}));
    EXPECT_EQ(b[1].hi, (std::array<std::int64_t, 3>{7, 4, 6}));
    EXPECT_EQ(b[2].lo, (std::array<std::int64_t, 3>{7, 0, 0}));
    EXPECT_EQ(b[2].hi, (std::array<std::int64_t, 3>{10, 4, 6}));
    EXPECT_THROW(split_lattice(cells, 11), Error);  // more ranks than the longest axis' cells
}

// --balance work (WorkBins, Bricks.h), by hand. 16 x 4 x 4 cells in 8 bins per axis: 8 x 4 x 4 bins
// (y and z have only 4 cells) of 2 x 1 x 1 cells. Work 3 in every bin with x < 4 (x bins 0, 1), 1
// elsewhere: per x bin 16 bins in y, z, so 24 a cell below x = 4 and 8 above, 96 + 96 = 192 in all;
// two ranks cut where 96 is reached: x = 4 (the cell rule: 8). Three ranks: the first third (64) is
// passed within cell 2 (48 before it, 72 after), the nearer boundary x = 3; then [3, 16) holds
// 24 + 96 = 120, half 60 reached within cell 8 (56 before it, 64 after: as near, the first, x = 8).
// No work: the cell rule.
TEST(MpiBricks, KdSplitByWorkByHand) {
    Lattice cells;
    cells.hi = {16, 4, 4};
    WorkBins w(cells, 8);
    ASSERT_EQ(w.bins, (std::array<std::int64_t, 3>{8, 4, 4}));
    ASSERT_EQ(w.width, (std::array<std::int64_t, 3>{2, 1, 1}));
    for (std::int64_t k = 0; k < 4; ++k)
        for (std::int64_t j = 0; j < 4; ++j)
            for (std::int64_t i = 0; i < 8; ++i) w.work[std::size_t(i + 8 * (j + 4 * k))] = i < 2 ? 3.0 : 1.0;
    std::vector<Brick> b = split_lattice(cells, 2, &w);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_EQ(b[0].hi[0], 4);
    EXPECT_EQ(b[1].lo[0], 4);
    EXPECT_EQ(split_lattice(cells, 2)[0].hi[0], 8);
    b = split_lattice(cells, 3, &w);
    ASSERT_EQ(b.size(), 3u);
    EXPECT_EQ(b[0].hi[0], 3);
    EXPECT_EQ(b[1].lo[0], 3);
    EXPECT_EQ(b[1].hi[0], 8);
    EXPECT_EQ(b[2].lo[0], 8);
    // bin_of: a continuous index in cell 5 of x, 3 of y, 0 of z is bin (2, 3, 0); outside clamps.
    EXPECT_EQ(w.bin_of(cells, glm::dvec3(5.5, 3.2, 0.1)), std::size_t(2 + 8 * 3));
    EXPECT_EQ(w.bin_of(cells, glm::dvec3(-3.0, 99.0, 4.0)), std::size_t(0 + 8 * (3 + 4 * 3)));
    std::fill(w.work.begin(), w.work.end(), 0.0);
    EXPECT_EQ(split_lattice(cells, 2, &w)[0].hi[0], 8);
}

// A packet's work (add_packet_work, Bricks.h), by hand: step j costs kWorkStepCost (16) + the distinct lines
// of the lanes with a j-th sample, shared equally among those lanes' bins, in units of 1 / 840. Three lanes:
// step 0 has all three, on lines 10, 10, 20 (2 distinct): 18 x 840 / 3 = 5040 each, to bins 0, 0, 2; step 1
// has lanes 0 and 1, on lines 11 and 12 (2): 18 x 840 / 2 = 7560 each, to bin 1 twice. Eight lanes on one
// line: 17 x 840 / 8 = 1785 each. Every share is an integer (840 = lcm(1, ..., 8)).
TEST(MpiBricks, PacketWorkByHand) {
    std::vector<LaneSample> lanes[kWorkPacketLanes];
    lanes[0] = {{0, 10}, {1, 11}};
    lanes[1] = {{0, 10}, {1, 12}};
    lanes[2] = {{2, 20}};
    std::vector<double> work(4, 0.0);
    add_packet_work(lanes, 3, work);
    EXPECT_EQ(work, (std::vector<double>{10080.0, 15120.0, 5040.0, 0.0}));
    for (auto& l : lanes) l = {{3, 7}};
    add_packet_work(lanes, kWorkPacketLanes, work);
    EXPECT_EQ(work[3], 8 * 1785.0);
    for (int live = 1; live <= kWorkPacketLanes; ++live)
        for (int distinct = 1; distinct <= live; ++distinct) {
            const double share = (kWorkStepCost + distinct) * (840.0 / live);
            EXPECT_EQ(share, std::round(share)) << live << " " << distinct;
        }
}

TEST(MpiBricks, EveryPointBelongsToExactlyOneBrick) {
    Lattice cells;
    cells.lo = {-3, 0, 2};
    cells.hi = {9, 5, 13};
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-6.0, 16.0);  // beyond the outer faces too
    for (int n = 1; n <= 7; ++n) {
        const std::vector<Brick> bricks = split_lattice(cells, n);
        for (int i = 0; i < 2000; ++i) {
            glm::dvec3 p(u(rng), u(rng), u(rng));
            if (i % 10 == 0) p.x = double(bricks[std::size_t(i) % bricks.size()].lo[0]);  // on a cut plane
            int owners = 0;
            for (const Brick& b : bricks) owners += owns(b, cells, p) ? 1 : 0;
            ASSERT_EQ(owners, 1) << n << " bricks, point " << p.x << " " << p.y << " " << p.z;
        }
    }
}

TEST(MpiBricks, UnionLatticeByHand) {
    GridBox g0;
    g0.dims = {11, 5, 7};  // cells [0, 10) x [0, 4) x [0, 6)
    GridBox shifted;       // x from -2.5 to -0.5, y from 1 to 3, z from 0 to 9 (beyond g0's 6)
    shifted.dims = {5, 3, 10};
    shifted.origin = {-2.5, 1.0, 0.0};
    shifted.spacing = {0.5, 1.0, 1.0};
    Lattice l = union_lattice({g0, shifted});
    EXPECT_EQ(l.lo, (std::array<std::int64_t, 3>{-3, 0, 0}));  // floor(-2.5)
    EXPECT_EQ(l.hi, (std::array<std::int64_t, 3>{10, 4, 9}));
    // Turned 90 degrees about z (local (x, y, z) -> world (-y, x, z)): its box [0, 2] x [0, 4] x [0, 1]
    // lies at x in [-4, 0], y in [0, 2] in the world.
    glm::dmat4 m(1.0);
    m[0] = glm::dvec4(0, 1, 0, 0);
    m[1] = glm::dvec4(-1, 0, 0, 0);
    const VolumeTransform turn(m);
    GridBox turned;
    turned.dims = {3, 5, 2};
    turned.to_world = &turn;
    l = union_lattice({g0, turned});
    EXPECT_EQ(l.lo, (std::array<std::int64_t, 3>{-4, 0, 0}));
    EXPECT_EQ(l.hi, (std::array<std::int64_t, 3>{10, 4, 6}));
}

TEST(MpiBricks, VoxelsForByHand) {
    GridBox g0;
    g0.dims = {11, 5, 7};
    Lattice cells;
    cells.hi = {10, 4, 6};
    Brick inner;  // cells x [3, 7), all of y and z (the lattice's outer faces)
    inner.lo = {3, 0, 0};
    inner.hi = {7, 4, 6};
    std::array<std::int64_t, 3> lo{}, hi{};
    // The lattice's own grid: the cells' corners 3 .. 7, +- 2 ghost voxels; the outer faces reach the grid's.
    voxels_for(inner, cells, g0, g0, 2, lo, hi);
    EXPECT_EQ(lo, (std::array<std::int64_t, 3>{1, 0, 0}));
    EXPECT_EQ(hi, (std::array<std::int64_t, 3>{9, 4, 6}));
    // A finer grid (spacing 0.5, 21 x 9 x 13 voxels over the same box): world x in [3, 7] is its index
    // [6, 14], +- 1 ghost voxel.
    GridBox fine;
    fine.dims = {21, 9, 13};
    fine.spacing = glm::dvec3(0.5);
    voxels_for(inner, cells, g0, fine, 1, lo, hi);
    EXPECT_EQ(lo, (std::array<std::int64_t, 3>{5, 0, 0}));
    EXPECT_EQ(hi, (std::array<std::int64_t, 3>{15, 8, 12}));
    // A grid the brick does not meet (x from 20 to 24): a sliver at its face, never sampled.
    GridBox far;
    far.dims = {5, 5, 7};
    far.origin = {20.0, 0.0, 0.0};
    voxels_for(inner, cells, g0, far, 1, lo, hi);
    EXPECT_EQ(lo[0], 0);
    EXPECT_LE(hi[0], 0);
}

}  // namespace

// PartBuffer (cli/mpi/PartBuffer.h): a large buffer starts on a 2 MiB boundary (so that madvise's huge
// pages cover all of it), a small one is std::allocator's; both hold what is written, and copy like
// any vector (the values never depend on where the storage lies).
TEST(MpiPartBuffer, LargeBuffersStartOnHugePageBoundaries) {
    constexpr std::size_t kHuge = std::size_t(1) << 21;
    for (std::size_t n : {std::size_t(3), kHuge / sizeof(double) - 1, kHuge / sizeof(double), 3 * kHuge / sizeof(double) + 5}) {
        PartBuffer b(n, 0.0);
        if (n * sizeof(double) >= kHuge) {
            EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.data()) % kHuge, 0u) << n;
        }
        for (std::size_t i = 0; i < n; ++i) b[i] = double(i) * 0.5;
        const PartBuffer c = b;
        double sum = 0.0;
        for (double v : c) sum += v;
        EXPECT_EQ(sum, 0.25 * double(n) * double(n - 1)) << n;  // 0.5 * n (n - 1) / 2, exact in doubles here
    }
}
