// Reconstruction against hand calculations and closed forms (conventions section 2).
#include <gtest/gtest.h>

#include <random>

#include "core/grid/ProceduralField.h"
#include "core/sample/Trilinear.h"
#include "core/sample/VolumeSampler.h"

using namespace volref;

// Levoy's lecture cell: f1..f8 = 5.0, 5.1, 5.2, 4.6, 4.9, 5.1, 5.3, 4.7. The expected values were
// worked by hand as three nested linear interpolations (p along the q = 0 and q = 1 edges, then q,
// then r), a different order from the renderer's weighted sum:
//   (0.2, 0.3, 0.8): r=0 face: 5.02, 4.72 -> 4.93;  r=1 face: 4.94, 4.82 -> 4.904;  -> 4.9092
//   (0.5, 0.5, 0.5): the mean of the corners, 39.9 / 8 = 4.9875
//   (0.8, 0.7, 0.2): r=0 face: 5.08, 5.08 -> 5.08;  r=1 face: 5.06, 5.18 -> 5.144;  -> 5.0928
TEST(Trilinear, LevoyLectureCell) {
    const std::array<double, 8> f{5.0, 5.1, 5.2, 4.6, 4.9, 5.1, 5.3, 4.7};
    EXPECT_NEAR(trilinear(f, 0.2, 0.3, 0.8), 4.9092, 1e-13);
    EXPECT_NEAR(trilinear(f, 0.5, 0.5, 0.5), 4.9875, 1e-13);
    EXPECT_NEAR(trilinear(f, 0.8, 0.7, 0.2), 5.0928, 1e-13);
    // The corners themselves, in Levoy's order.
    const double corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (int n = 0; n < 8; ++n) EXPECT_EQ(trilinear(f, corners[n][0], corners[n][1], corners[n][2]), f[n]);
}

TEST(Trilinear, LevoyCellThroughTheSampler) {
    FieldSpec cells;
    cells.kind = FieldSpec::Kind::Cells;
    cells.dims = {2, 2, 2};
    // Levoy's corners in file order (i fastest): f1 (0,0,0), f2 (1,0,0), f4 (0,1,0), f3 (1,1,0), ...
    cells.values = {5.0, 5.1, 4.6, 5.2, 4.9, 5.1, 4.7, 5.3};
    const Volume v = make_procedural_volume(cells, glm::dvec3(0.0), glm::dvec3(1.0));
    const VolumeSampler s(v, Interpolation::Trilinear);
    EXPECT_NEAR(s.value({0.2, 0.3, 0.8}), 4.9092, 1e-13);
    EXPECT_NEAR(s.value({0.8, 0.7, 0.2}), 5.0928, 1e-13);
}

// A linear field f = a x + b y + c z + d is reproduced by trilinear reconstruction at any point.
TEST(Trilinear, ReproducesLinearFields) {
    FieldSpec lin;
    lin.kind = FieldSpec::Kind::Linear;
    lin.dims = {7, 5, 9};
    lin.coefficients = {0.7, -1.3, 2.1, 0.25};
    const glm::dvec3 origin(-1.0, 2.0, 0.5), spacing(0.3, 0.7, 0.45);
    const Volume v = make_procedural_volume(lin, origin, spacing);
    const VolumeSampler s(v, Interpolation::Trilinear);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const glm::dvec3 extent = v.domain_max() - v.domain_min();
    for (int n = 0; n < 1000; ++n) {
        const glm::dvec3 p = origin + glm::dvec3(u(rng), u(rng), u(rng)) * extent;
        const double expected = 0.7 * p.x - 1.3 * p.y + 2.1 * p.z + 0.25;
        EXPECT_NEAR(s.value(p), expected, 1e-12) << p.x << " " << p.y << " " << p.z;
    }
}

// Nearest: the voxel at round-half-up of the continuous index.
TEST(Nearest, RoundsHalfUp) {
    FieldSpec cells;
    cells.kind = FieldSpec::Kind::Cells;
    cells.dims = {3, 1, 1};
    cells.values = {10.0, 20.0, 30.0};
    const Volume v = make_procedural_volume(cells, glm::dvec3(0.0), glm::dvec3(2.0));
    const VolumeSampler s(v, Interpolation::Nearest);
    EXPECT_EQ(s.value({0.99, 0, 0}), 10.0);  // index 0.495
    EXPECT_EQ(s.value({1.0, 0, 0}), 20.0);   // index 0.5 rounds up
    EXPECT_EQ(s.value({2.99, 0, 0}), 20.0);  // index 1.495
    EXPECT_EQ(s.value({3.0, 0, 0}), 30.0);   // index 1.5 rounds up
    EXPECT_EQ(s.value({4.0, 0, 0}), 30.0);   // the last voxel
}

// A flat axis (n = 1) uses its single layer.
TEST(Trilinear, FlatAxis) {
    FieldSpec cells;
    cells.kind = FieldSpec::Kind::Cells;
    cells.dims = {2, 1, 1};
    cells.values = {1.0, 3.0};
    const Volume v = make_procedural_volume(cells, glm::dvec3(0.0), glm::dvec3(1.0));
    const VolumeSampler s(v, Interpolation::Trilinear);
    EXPECT_DOUBLE_EQ(s.value({0.25, 0, 0}), 1.5);
}

TEST(ProceduralField, MarschnerLobbAtKnownPoints) {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {3, 3, 3};
    const Volume v = make_procedural_volume(ml, glm::dvec3(0.0), glm::dvec3(1.0));
    // Centre voxel (1,1,1) is x = y = z = 0: r = 0, rho = cos(2 pi 6 cos 0) = 1,
    // f = (1 - 0 + 0.25 * 2) / 2.5 = 0.6.
    EXPECT_NEAR(v.at(1, 1, 1), 0.6, 1e-15);
    // Voxel (2,1,2): x = 1, y = 0, z = 1: r = 1, cos(pi/2) ~ 0, rho = cos(~0) = 1,
    // f = (1 - 1 + 0.5) / 2.5 = 0.2.
    EXPECT_NEAR(v.at(2, 1, 2), 0.2, 1e-12);
}
