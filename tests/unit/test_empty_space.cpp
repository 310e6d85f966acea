// Empty-space skipping (conventions section 4): the macrocell grid's ranges, the classifiers' range
// tests, and images that are bitwise the same with skipping on and off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "TestScenes.h"
#include "core/grid/ProceduralField.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/Tricubic.h"
#include "core/integrate/march/SegmentWalk.h"
#include "geometry/BoxIntersection.h"
#include "core/sample/VolumeSampler.h"
#include "transfer/BoundaryClassifier.h"
#include "transfer/IsovalueClassifier.h"
#include "transfer/TransferFunction.h"

using namespace volref;
using namespace volref::test;

namespace {

// The scalar path (where skipping happens; the SIMD packet path samples every segment), one thread.
Image render(const Scene& s, bool skipping) {
    RenderOptions o;
    o.threads = 1;
    o.empty_space_skipping = skipping;
    o.simd = false;
    return render_scene(s, o);
}

// The number of empty macrocells of the grid the renderer builds for `s`.
std::int64_t empty_macrocells(const Scene& s) {
    const Volume volume = load_volume(s.volume());
    const VolumeSampler sampler(volume, s.volume().interpolation);
    const auto classifier = make_classifier(s.volume(), volume);
    const MacrocellGrid grid(sampler, *classifier,
                             s.volume().classify == VolumeSpec::Classify::Pre ? MacrocellGrid::Classification::Pre
                                                                            : MacrocellGrid::Classification::Post);
    return grid.empty_count();
}

// Renders with skipping on and off and compares the pixel buffers byte for byte; also checks that the
// scene has empty space to skip and (unless told otherwise) is not blank. Returns the largest alpha.
double expect_bitwise_equal(const Scene& s, const std::string& what, bool require_visible = true) {
    SCOPED_TRACE(what);
    EXPECT_GT(empty_macrocells(s), 0) << "nothing to skip";
    const Image on = render(s, true), off = render(s, false);
    EXPECT_EQ(on.pixels.size(), off.pixels.size());
    if (on.pixels.size() != off.pixels.size()) return 0.0;
    EXPECT_EQ(std::memcmp(on.pixels.data(), off.pixels.data(), on.pixels.size() * sizeof(on.pixels[0])), 0);
    double max_alpha = 0.0;
    for (int y = 0; y < off.height; ++y)
        for (int x = 0; x < off.width; ++x) max_alpha = std::max(max_alpha, off.at(x, y, 3));
    if (require_visible) {
        EXPECT_GT(max_alpha, 0.0) << "blank image";
    }
    return max_alpha;
}

CameraSpec perspective(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up = {0, 0, 1}, double fov = 40.0) {
    CameraSpec c;
    c.type = CameraSpec::Type::Perspective;
    c.eye = eye;
    c.target = target;
    c.up = up;
    c.fov_y = fov;
    return c;
}

CameraSpec orthographic(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double height) {
    CameraSpec c;
    c.type = CameraSpec::Type::Orthographic;
    c.eye = eye;
    c.target = target;
    c.up = up;
    c.height = height;
    return c;
}

void set_step(Scene& s, double h, StepUnits units = StepUnits::World) {
    s.render.step = h;
    s.render.step_units = units;
}

// Marschner-Lobb (45^3: 44 cells, not a multiple of M) with a transfer function that is 0 below 0.8.
Scene marschner_lobb_scene() {
    FieldSpec f;
    f.kind = FieldSpec::Kind::MarschnerLobb;
    f.dims = {45, 45, 45};
    Scene s = field_scene(f);
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.8, 0.0}, {0.9, 0.6}, {1.0, 0.9}};
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.6}, {0.85, 1.0, 0.8, 0.3}, {1.0, 0.9, 0.1, 0.05}};
    s.camera = perspective({110, -70, 95}, {22, 22, 22});
    s.image.width = s.image.height = 20;
    set_step(s, 0.5, StepUnits::Voxel);
    return s;
}

// A Gaussian blob on a grid whose dims are not multiples of M, with origin and spacing that are not
// round, and a narrow opacity band (a thin shell).
Scene gaussian_scene() {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {37, 29, 33};
    g.center = {-3.3 + 18 * 0.7, 1.7 + 14 * 1.3, 0.1 + 16 * 0.9};
    g.sigma = 6.0;
    Scene s = field_scene(g, {-3.3, 1.7, 0.1}, {0.7, 1.3, 0.9});
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.55, 0.0}, {0.6, 0.8}, {0.65, 0.0}};
    s.volume().transfer.color = {{0.0, 0.2, 0.3, 1.0}, {1.0, 1.0, 0.8, 0.1}};
    s.volume().transfer.opacity_unit_distance = 2.0;
    s.camera = perspective({60, -40, 50}, g.center, {0, 0, 1}, 45.0);
    s.image.width = s.image.height = 20;
    set_step(s, 0.37);
    return s;
}

}  // namespace

// ---- the grid ----

// v = 10 i + j + 2 k on 12 x 2 x 2 voxels: 11 x 1 x 1 cells, macrocells {0..7} and {8..10} along i.
// Trilinear and nearest read voxels [0, 8] and [8, 11]; tricubic one more on each side, clamped:
// [0, 9] and [7, 11].
TEST(MacrocellGrid, RangesByHand) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Cells;
    f.dims = {12, 2, 2};
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 12; ++i) f.values.push_back(10.0 * i + j + 2.0 * k);
    const Volume v = make_procedural_volume(f, glm::dvec3(0.0), glm::dvec3(1.0));
    TransferSpec ts;
    ts.opacity = {{0.0, 1.0}};
    const TransferFunction tf(ts, v);
    using R = std::array<double, 2>;
    for (Interpolation i : {Interpolation::Nearest, Interpolation::Trilinear}) {
        const VolumeSampler sampler(v, i);
        const MacrocellGrid g(sampler, tf, MacrocellGrid::Classification::Post);
        EXPECT_EQ(g.counts(), (MacrocellGrid::Index{2, 1, 1}));
        EXPECT_EQ(g.range({0, 0, 0}), (R{0.0, 83.0}));
        EXPECT_EQ(g.range({1, 0, 0}), (R{80.0, 113.0}));
        EXPECT_EQ(g.empty_count(), 0);
    }
    for (Interpolation i : {Interpolation::TricubicBSpline, Interpolation::TricubicCatmullRom}) {
        const VolumeSampler sampler(v, i);
        const MacrocellGrid g(sampler, tf, MacrocellGrid::Classification::Post);
        EXPECT_EQ(g.range({0, 0, 0}), (R{0.0, 93.0}));
        EXPECT_EQ(g.range({1, 0, 0}), (R{70.0, 113.0}));
    }
}

// The macrocell grid of an n^3 volume of `values` (spacing 1, trilinear) classified by the ramp
// opacity 0 up to 0.5, rising to 1 at 1: a voxel of 0 is transparent, one of 1 is not.
template <typename Check>
void with_ramp_grid(std::int64_t n, std::vector<double> values, Check&& check) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Cells;
    f.dims = {n, n, n};
    f.values = std::move(values);
    const Volume v = make_procedural_volume(f, glm::dvec3(0.0), glm::dvec3(1.0));
    TransferSpec ts;
    ts.opacity = {{0.0, 0.0}, {0.5, 0.0}, {1.0, 1.0}};
    const TransferFunction tf(ts, v);
    const VolumeSampler sampler(v, Interpolation::Trilinear);
    const MacrocellGrid g(sampler, tf, MacrocellGrid::Classification::Post);
    check(g);
}

// Calls f(m, d) for every macrocell m of g, a 5^3 grid, d the Chebyshev distance from m to (2, 2, 2).
template <typename F>
void each_around_the_centre(const MacrocellGrid& g, F&& f) {
    ASSERT_EQ(g.counts(), (MacrocellGrid::Index{5, 5, 5}));
    for (std::int64_t k = 0; k < 5; ++k)
        for (std::int64_t j = 0; j < 5; ++j)
            for (std::int64_t i = 0; i < 5; ++i)
                f(MacrocellGrid::Index{i, j, k}, std::max({std::abs(i - 2), std::abs(j - 2), std::abs(k - 2)}));
}

// empty_radius by hand: one non-zero voxel at (20, 20, 20) of a 41^3 volume of zeros (40 cells per axis,
// 5 macrocells of 8): only macrocell (2, 2, 2) reads it (cells 16..23 read voxels 16..24), so every
// other macrocell's radius is its Chebyshev distance max_a |m_a - 2| to it; with no non-zero voxel,
// every radius is the cap.
TEST(MacrocellGrid, EmptyRadiusIsTheChebyshevDistanceToTheNearestNonEmptyMacrocell) {
    for (const bool spike : {true, false}) {
        std::vector<double> values(41 * 41 * 41, 0.0);
        if (spike) values[std::size_t(20 + 41 * (20 + 41 * 20))] = 1.0;
        with_ramp_grid(41, std::move(values), [&](const MacrocellGrid& g) {
            each_around_the_centre(g, [&](const MacrocellGrid::Index& m, std::int64_t d) {
                EXPECT_EQ(g.empty_radius(m), spike ? d : MacrocellGrid::kMaxEmptyRadius) << m[0] << "," << m[1] << "," << m[2];
                EXPECT_EQ(g.empty(m), !spike || d > 0);
            });
        });
    }
}

// The same against brute force (every pair of macrocells) on scattered spikes: 57^3 voxels (7
// macrocells per axis), spikes at fixed pseudo-random voxels, the radius of each empty macrocell the
// smallest Chebyshev distance to a macrocell the grid says is not empty.
// 57^3 voxels of 0 with `spikes` voxels of 1 at pseudo-random places (a linear congruential sequence from `seed`).
std::vector<double> scattered_spikes(std::uint32_t seed, int spikes) {
    std::vector<double> values(57 * 57 * 57, 0.0);
    for (int k = 0; k < spikes; ++k) {
        seed = seed * 1664525u + 1013904223u;
        values[std::size_t(seed % (57u * 57u * 57u))] = 1.0;
    }
    return values;
}

TEST(MacrocellGrid, EmptyRadiusMatchesBruteForce) {
    with_ramp_grid(57, scattered_spikes(12345, 5), [&](const MacrocellGrid& g) {
        ASSERT_EQ(g.counts(), (MacrocellGrid::Index{7, 7, 7}));
        // The smallest Chebyshev distance from (i, j, k) to a macrocell that is not empty.
        auto nearest = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
            std::int64_t d = MacrocellGrid::kMaxEmptyRadius;
            for (std::int64_t c = 0; c < 7; ++c)
                for (std::int64_t b = 0; b < 7; ++b)
                    for (std::int64_t a = 0; a < 7; ++a)
                        if (!g.empty({a, b, c})) d = std::min(d, std::max({std::abs(i - a), std::abs(j - b), std::abs(k - c)}));
            return d;
        };
        int non_empty = 0;
        for (std::int64_t k = 0; k < 7; ++k)
            for (std::int64_t j = 0; j < 7; ++j)
                for (std::int64_t i = 0; i < 7; ++i) {
                    const std::int64_t want = nearest(i, j, k);
                    non_empty += want == 0;
                    EXPECT_EQ(g.empty_radius({i, j, k}), want) << i << "," << j << "," << k;
                }
        EXPECT_GE(non_empty, 5);
    });
}

// octant_radii by hand, on the spike of EmptyRadiusIs...: for octant o (signs s per axis) the cube ahead
// of an empty m, m + (i s0, j s1, k s2) for 0 <= i, j, k < r, reaches the one non-empty macrocell
// (2, 2, 2) only if every e_a = s_a (2 - m_a) >= 0, and then first at r = max_a e_a + 1: so the distance
// ahead is max_a e_a, and the cap where some e_a < 0 (the spike lies behind on that axis). The spike
// itself, whose 7 neighbours ahead (or the grid's edge) are all of the other kind, has the cube of
// itself: 1. Checks signed radii (8 octants of a 5^3 grid) against that rule, `sign` the sign of every
// macrocell but the centre (+ empty, - not), whose own is the other.
void expect_cubes_ahead_of_the_centre(const MacrocellGrid& g, const std::vector<std::int32_t>& radii, int sign) {
    ASSERT_EQ(radii.size(), 8u * 125u);
    for (int o = 0; o < 8; ++o) {
        const std::int64_t s[3] = {(o & 1) ? -1 : 1, (o & 2) ? -1 : 1, (o & 4) ? -1 : 1};
        each_around_the_centre(g, [&](const MacrocellGrid::Index& m, std::int64_t d) {
            std::int64_t want = 0;
            for (int a = 0; a < 3; ++a) {
                const std::int64_t e = s[a] * (2 - m[a]);
                want = e < 0 || want == MacrocellGrid::kMaxEmptyRadius ? MacrocellGrid::kMaxEmptyRadius : std::max(want, e);
            }
            const std::int64_t signed_want = d == 0 ? -sign : sign * want;
            EXPECT_EQ(radii[std::size_t(o) * 125 + std::size_t(m[0] + 5 * (m[1] + 5 * m[2]))], signed_want)
                << "octant " << o << " at " << m[0] << "," << m[1] << "," << m[2];
        });
    }
}

TEST(MacrocellGrid, OctantRadiusOfAnEmptyMacrocellIsTheCubeAheadOfIt) {
    std::vector<double> values(41 * 41 * 41, 0.0);
    values[std::size_t(20 + 41 * (20 + 41 * 20))] = 1.0;
    with_ramp_grid(41, std::move(values), [&](const MacrocellGrid& g) { expect_cubes_ahead_of_the_centre(g, g.octant_radii(), +1); });
}

// The complement: a 41^3 volume of ones whose voxels 16..24 per axis (exactly those macrocell (2, 2, 2)
// reads) are 0, so (2, 2, 2) is the one empty macrocell (its neighbours also read ones), and the solid
// distance ahead of every other macrocell follows the same rule, negative; without the hole every
// radius is minus the cap.
TEST(MacrocellGrid, OctantRadiusOfANonEmptyMacrocellIsTheCubeAheadOfIt) {
    for (const bool hole : {true, false}) {
        std::vector<double> values(41 * 41 * 41, 1.0);
        if (hole)
            for (int k = 16; k <= 24; ++k)
                for (int j = 16; j <= 24; ++j)
                    for (int i = 16; i <= 24; ++i) values[std::size_t(i + 41 * (j + 41 * k))] = 0.0;
        with_ramp_grid(41, std::move(values), [&](const MacrocellGrid& g) {
            const std::vector<std::int32_t> radii = g.octant_radii();
            if (hole) {
                expect_cubes_ahead_of_the_centre(g, radii, -1);
            } else {
                for (const std::int32_t r : radii) EXPECT_EQ(r, -MacrocellGrid::kMaxEmptyRadius);
            }
            each_around_the_centre(g, [&](const MacrocellGrid::Index& m, std::int64_t d) { EXPECT_EQ(g.empty(m), hole && d == 0); });
        });
    }
}

// The same against brute force on scattered spikes (as EmptyRadiusMatchesBruteForce): the largest r (up
// to the grid's 7, then the cap) whose cube ahead holds only macrocells of m's kind, + for an empty m,
// - for a non-empty one; the empty ones never below empty_radius (the symmetric box holds the cube
// ahead of that size).
TEST(MacrocellGrid, OctantRadiiMatchBruteForce) {
    with_ramp_grid(57, scattered_spikes(777, 9), [&](const MacrocellGrid& g) {
        ASSERT_EQ(g.counts(), (MacrocellGrid::Index{7, 7, 7}));
        const std::vector<std::int32_t> radii = g.octant_radii();
        int capped = 0, finite_empty = 0, finite_solid = 0;
        for (int o = 0; o < 8; ++o) {
            const std::int64_t s[3] = {(o & 1) ? -1 : 1, (o & 2) ? -1 : 1, (o & 4) ? -1 : 1};
            for (std::int64_t k = 0; k < 7; ++k)
                for (std::int64_t j = 0; j < 7; ++j)
                    for (std::int64_t i = 0; i < 7; ++i) {
                        const bool kind = g.empty({i, j, k});
                        auto cube_of_kind = [&](std::int64_t r) {
                            for (std::int64_t c = 0; c < r; ++c)
                                for (std::int64_t b = 0; b < r; ++b)
                                    for (std::int64_t a = 0; a < r; ++a) {
                                        const MacrocellGrid::Index q{i + a * s[0], j + b * s[1], k + c * s[2]};
                                        const bool in = q[0] >= 0 && q[0] < 7 && q[1] >= 0 && q[1] < 7 && q[2] >= 0 && q[2] < 7;
                                        if (in && g.empty(q) != kind) return false;
                                    }
                            return true;
                        };
                        std::int64_t want = 0;
                        while (want < 7 && cube_of_kind(want + 1)) ++want;
                        if (want == 7) want = MacrocellGrid::kMaxEmptyRadius;
                        if (want == MacrocellGrid::kMaxEmptyRadius) ++capped;
                        else if (want > 1) ++(kind ? finite_empty : finite_solid);
                        const std::int64_t got = radii[std::size_t(o) * 343 + std::size_t(i + 7 * (j + 7 * k))];
                        EXPECT_EQ(got, kind ? want : -want) << "octant " << o << " at " << i << "," << j << "," << k;
                        if (kind) EXPECT_GE(got, g.empty_radius({i, j, k}));
                    }
        }
        EXPECT_GT(capped, 100);
        EXPECT_GT(finite_empty, 300);
        EXPECT_GT(finite_solid, 0);
    });
}

// One non-zero voxel in a 20^3 volume of zeros (19 cells per axis: macrocells of 8, 8 and 3 cells):
// the macrocells whose samples can read it are not empty, all others are.
TEST(MacrocellGrid, SpikeAndApron) {
    struct Case {
        std::int64_t voxel;
        std::vector<std::int64_t> trilinear, tricubic;  // macrocells (per axis) that read it
    };
    const std::vector<Case> cases = {
        {0, {0}, {0}}, {7, {0}, {0, 1}}, {8, {0, 1}, {0, 1}}, {9, {1}, {0, 1}},
        {16, {1, 2}, {1, 2}}, {17, {2}, {1, 2}}, {19, {2}, {2}},
    };
    for (const Case& c : cases) {
        FieldSpec f;
        f.kind = FieldSpec::Kind::Cells;
        f.dims = {20, 20, 20};
        f.values.assign(8000, 0.0);
        f.values[std::size_t(c.voxel * (1 + 20 + 400))] = 1.0;
        const Volume v = make_procedural_volume(f, glm::dvec3(0.0), glm::dvec3(1.0));
        TransferSpec ts;
        ts.opacity = {{0.0, 0.0}, {1.0, 1.0}};
        const TransferFunction tf(ts, v);
        for (Interpolation interp : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                                     Interpolation::TricubicCatmullRom}) {
            const VolumeSampler sampler(v, interp);
            const bool cubic = sampler.is_tricubic();
            const auto& readers = cubic ? c.tricubic : c.trilinear;
            for (auto cls : {MacrocellGrid::Classification::Post, MacrocellGrid::Classification::Pre}) {
                const MacrocellGrid g(sampler, tf, cls);
                EXPECT_EQ(g.counts(), (MacrocellGrid::Index{3, 3, 3}));
                for (std::int64_t a = 0; a < 3; ++a)
                    for (std::int64_t b = 0; b < 3; ++b)
                        for (std::int64_t d = 0; d < 3; ++d) {
                            auto reads = [&](std::int64_t m) {
                                return std::find(readers.begin(), readers.end(), m) != readers.end();
                            };
                            const bool hit = reads(a) && reads(b) && reads(d);
                            EXPECT_EQ(g.range({a, b, d})[1], hit ? 1.0 : 0.0) << c.voxel << " " << a << b << d;
                            EXPECT_EQ(g.empty({a, b, d}), !hit) << c.voxel << " " << a << b << d;
                        }
            }
        }
    }
}

// A sample belongs to the macrocell of the cell VolumeSampler::locate gives it: a point on a face at
// u = 8 is in cell 8 (macrocell 1); the domain's far face (u = n - 1) is in the last cell.
TEST(MacrocellGrid, MacrocellOfAPoint) {
    const Volume v = make_procedural_volume(constant_field(0.0, {20, 9, 2}), glm::dvec3(0.0), glm::dvec3(1.0));
    const VolumeSampler sampler(v, Interpolation::Trilinear);
    TransferSpec ts;
    const TransferFunction tf(ts, v);
    const MacrocellGrid g(sampler, tf, MacrocellGrid::Classification::Post);
    EXPECT_EQ(g.counts(), (MacrocellGrid::Index{3, 1, 1}));
    EXPECT_EQ(g.macrocell_at({8.0, 8.0, 1.0}), (MacrocellGrid::Index{1, 0, 0}));
    EXPECT_EQ(g.macrocell_at({std::nextafter(8.0, 0.0), 0.0, 0.0}), (MacrocellGrid::Index{0, 0, 0}));
    EXPECT_EQ(g.macrocell_at({19.0, 9.0, 5.0}), (MacrocellGrid::Index{2, 0, 0}));
    EXPECT_EQ(g.macrocell_at({-4.0, -1.0, -1.0}), (MacrocellGrid::Index{0, 0, 0}));
    EXPECT_EQ(g.macrocell_at({NAN, 0.0, 0.0}), (MacrocellGrid::Index{-1, -1, -1}));
    EXPECT_FALSE(g.empty({-1, -1, -1}));
    // The exit of macrocell 0 along +x is the face x = 8; along an axis-parallel ray there is none.
    Ray r;
    r.origin = {-2.0, 3.0, 0.5};
    r.direction = {1.0, 0.0, 0.0};
    EXPECT_EQ(g.exit_distance(r, {0, 0, 0}), 10.0);
    EXPECT_EQ(g.entry_distance(r, {1, 0, 0}), 10.0);
    EXPECT_EQ(g.entry_distance(r, {0, 0, 0}), -INFINITY);
    EXPECT_EQ(g.exit_distance(r, {2, 0, 0}), INFINITY);
    r.direction = {0.0, 0.0, -1.0};
    EXPECT_EQ(g.exit_distance(r, {0, 0, 0}), INFINITY);
}

// Nearest reads voxel values; trilinear and B-spline average them (plus rounding); Catmull-Rom can
// overshoot by (5/4)^3 of the half-range, and does so at t = 1/2 for taps (-, +, +, -) per axis.
TEST(MacrocellGrid, ReconstructionBounds) {
    using R = std::array<double, 2>;
    EXPECT_EQ(MacrocellGrid::reconstruction_bounds(Interpolation::Nearest, 2.0, 3.0), (R{2.0, 3.0}));
    EXPECT_EQ(MacrocellGrid::reconstruction_bounds(Interpolation::Trilinear, 0.0, 0.0), (R{0.0, 0.0}));
    const R t = MacrocellGrid::reconstruction_bounds(Interpolation::Trilinear, 2.0, 3.0);
    EXPECT_LT(t[0], 2.0);
    EXPECT_GT(t[1], 3.0);
    EXPECT_NEAR(t[0], 2.0, 1e-11);
    EXPECT_NEAR(t[1], 3.0, 1e-11);
    const R c = MacrocellGrid::reconstruction_bounds(Interpolation::TricubicCatmullRom, 0.0, 1.0);
    EXPECT_NEAR(c[0], 0.5 - 0.5 * 1.953125, 1e-11);
    EXPECT_NEAR(c[1], 0.5 + 0.5 * 1.953125, 1e-11);
    EXPECT_LE(c[0], 0.5 - 0.5 * 1.953125);
    EXPECT_GE(c[1], 0.5 + 0.5 * 1.953125);

    // The worst case is reached: 4 x 4 x 4 taps in {0, 1} with sign pattern (-, +, +, -) per axis.
    Volume v;
    v.dims = {4, 4, 4};
    const double s[4] = {-1, 1, 1, -1};
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) v.values.push_back(0.5 + 0.5 * s[i] * s[j] * s[k]);
    const double peak = tricubic(v, CubicKernel::CatmullRom, glm::dvec3(1.5));
    EXPECT_NEAR(peak, 0.5 + 0.5 * 1.953125, 1e-14);
    EXPECT_LE(peak, c[1]);

    // Random taps and positions stay inside the bounds, for every kernel.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> value(-3.0, 5.0), pos(0.0, 3.0);
    for (int trial = 0; trial < 2000; ++trial) {
        Volume w;
        w.dims = {4, 4, 4};
        double lo = INFINITY, hi = -INFINITY;
        const bool constant = trial % 5 == 0;
        const double c0 = value(rng);
        for (int n = 0; n < 64; ++n) {
            w.values.push_back(constant ? c0 : value(rng));
            lo = std::min(lo, w.values.back());
            hi = std::max(hi, w.values.back());
        }
        const glm::dvec3 u(pos(rng), pos(rng), pos(rng));
        for (Interpolation i : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                                Interpolation::TricubicCatmullRom}) {
            const VolumeSampler sampler(w, i);
            const double f = sampler.value(u);
            const R b = MacrocellGrid::reconstruction_bounds(i, lo, hi);
            EXPECT_LE(b[0], f);
            EXPECT_GE(b[1], f);
        }
    }
}

// ---- the classifiers' range tests ----

TEST(EmptySpaceClassifiers, TransferFunctionRanges) {
    const Volume v = make_procedural_volume(constant_field(0.0, {2, 2, 2}), glm::dvec3(0.0), glm::dvec3(1.0));
    TransferSpec ts;
    ts.opacity = {{0.0, 0.0}, {0.4, 0.0}, {0.5, 1.0}, {0.6, 0.0}, {1.0, 0.0}};
    for (bool gradient_opacity : {false, true}) {
        if (gradient_opacity) ts.gradient_opacity = {{0.0, 0.0}, {1.0, 1.0}};
        const TransferFunction tf(ts, v);
        EXPECT_FALSE(tf.may_have_opacity(-5.0, -1.0));
        EXPECT_FALSE(tf.may_have_opacity(0.0, 0.39));
        EXPECT_FALSE(tf.may_have_opacity(0.0, 0.4));  // 0 on row 0.4 itself
        EXPECT_TRUE(tf.may_have_opacity(0.0, 0.41));
        EXPECT_TRUE(tf.may_have_opacity(0.45, 0.45));
        EXPECT_TRUE(tf.may_have_opacity(0.55, 0.7));
        EXPECT_TRUE(tf.may_have_opacity(-1.0, 2.0));
        EXPECT_FALSE(tf.may_have_opacity(0.61, 0.99));
        EXPECT_FALSE(tf.may_have_opacity(0.7, 5.0));  // clamped to the last row
        EXPECT_TRUE(tf.may_have_opacity(1.0, 0.0));   // empty range: unsure
        EXPECT_TRUE(tf.may_have_opacity(NAN, 1.0));
    }
    // The normalised domain maps the window [100, 200] to [0, 1].
    TransferSpec tn = ts;
    tn.gradient_opacity.clear();
    tn.domain = TransferSpec::Domain::Normalized;
    tn.window = std::array<double, 2>{100.0, 200.0};
    const TransferFunction tf(tn, v);
    EXPECT_FALSE(tf.may_have_opacity(100.0, 139.0));
    EXPECT_TRUE(tf.may_have_opacity(140.0, 150.0));
    EXPECT_FALSE(tf.may_have_opacity(161.0, 1000.0));
}

// Whenever the answer is "no", classify gives opacity 0 at every value of the range (any gradient).
TEST(EmptySpaceClassifiers, NoMeansZeroEverywhere) {
    const Volume v = make_procedural_volume(constant_field(0.0, {2, 2, 2}), glm::dvec3(0.0), glm::dvec3(1.0));
    TransferSpec ts;
    ts.opacity = {{0.0, 0.0}, {0.4, 0.0}, {0.5, 1.0}, {0.5, 0.0}, {0.6, 0.0}, {0.7, 0.3}, {0.8, 0.0}};
    ts.gradient_opacity = {{0.0, 0.5}, {2.0, 1.0}};
    const TransferFunction tf(ts, v);
    const BoundaryClassifier bc({{0.1, 0.0, glm::dvec3(1)}, {0.3, 0.0, glm::dvec3(1)}, {0.5, 0.8, glm::dvec3(1)},
                                 {0.6, 0.0, glm::dvec3(1)}, {0.75, 0.0, glm::dvec3(1)}},
                                1.0);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> x(-0.2, 1.2);
    int no = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        double lo = x(rng), hi = x(rng);
        if (trial % 7 == 0) lo = hi = 0.1 * double(trial % 13);  // on breakpoints
        if (lo > hi) std::swap(lo, hi);
        for (const Classifier* c : {static_cast<const Classifier*>(&tf), static_cast<const Classifier*>(&bc)}) {
            if (c->may_have_opacity(lo, hi)) continue;
            ++no;
            for (int n = 0; n <= 20; ++n) {
                const double f = std::min(hi, lo + (hi - lo) * n / 20.0);
                for (double g : {0.0, 1.0, 3.0, 1e12})
                    EXPECT_EQ(c->classify(f, g).opacity, 0.0) << lo << " " << hi << " " << f;
            }
        }
    }
    EXPECT_GT(no, 1000);
}

TEST(EmptySpaceClassifiers, BoundaryAndIsovalueRanges) {
    const BoundaryClassifier bc({{0.0, 0.0, glm::dvec3(1)}, {10.0, 0.0, glm::dvec3(1)}, {20.0, 1.0, glm::dvec3(1)},
                                 {30.0, 0.0, glm::dvec3(1)}},
                                1.0);
    EXPECT_FALSE(bc.may_have_opacity(-5.0, -1.0));  // below fv_1
    EXPECT_FALSE(bc.may_have_opacity(31.0, 40.0));  // above fv_N
    EXPECT_FALSE(bc.may_have_opacity(0.0, 9.0));    // regions 0 and 1 have av = 0
    EXPECT_FALSE(bc.may_have_opacity(-3.0, 10.0));
    EXPECT_TRUE(bc.may_have_opacity(0.0, 10.5));
    EXPECT_TRUE(bc.may_have_opacity(25.0, 29.0));
    EXPECT_TRUE(bc.may_have_opacity(-100.0, 100.0));
    EXPECT_TRUE(bc.may_have_opacity(NAN, NAN));
    // Isovalue contours: |grad f| can make any value opaque, so no range is transparent.
    const IsovalueClassifier ic({{5.0, 1.0, 1.0, glm::dvec3(1)}}, 1.0);
    EXPECT_TRUE(ic.may_have_opacity(100.0, 200.0));
    EXPECT_GT(ic.classify(150.0, 1000.0).opacity, 0.0);
}

// ---- skipping skips ----

namespace {
// Counts the samples classified (one per evaluated segment with post-classification).
class CountingClassifier final : public Classifier {
public:
    explicit CountingClassifier(const Classifier& c) : c_(c) {}
    Classified classify(double v, double g) const override {
        ++calls;
        return c_.classify(v, g);
    }
    bool needs_gradient() const override { return c_.needs_gradient(); }
    double unit_distance() const override { return c_.unit_distance(); }
    bool may_have_opacity(double lo, double hi) const override { return c_.may_have_opacity(lo, hi); }
    mutable std::int64_t calls = 0;

private:
    const Classifier& c_;
};
}  // namespace

// With a transfer function that is transparent over most of the Gaussian blob, fewer than half the
// segments are sampled, and the pixels are the same, in both orders.
TEST(EmptySpace, SkipsMostSamples) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {41, 41, 41};
    g.center = {20.0, 20.0, 20.0};
    g.sigma = 6.0;
    const Volume volume = make_procedural_volume(g, glm::dvec3(0.0), glm::dvec3(1.0));
    TransferSpec ts;
    ts.opacity = {{0.0, 0.0}, {0.7, 0.0}, {0.8, 0.5}, {1.0, 0.5}};
    const TransferFunction tf(ts, volume);
    const CountingClassifier counting(tf);
    const VolumeSampler sampler(volume, Interpolation::Trilinear);
    const SamplePipeline pipeline(sampler, counting, nullptr, nullptr, nullptr);
    const MacrocellGrid grid(sampler, counting, MacrocellGrid::Classification::Post);
    EXPECT_GT(grid.empty_count(), 64);  // of 125
    for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
        RenderSpec render;
        render.order = order;
        const IntegrationContext with{pipeline, 0.37, render, &grid}, without{pipeline, 0.37, render, nullptr};
        const CompositeIntegrator skipping(with), plain(without);
        std::int64_t on = 0, off = 0;
        double max_alpha = 0.0;
        for (double x = 0.25; x < 40.0; x += 1.5)
            for (double y = 0.5; y < 40.0; y += 1.25) {
                Ray ray;
                ray.origin = {x, y, 100.0};
                ray.direction = {0.0, 0.0, -1.0};
                const std::vector<Interval> iv{{60.0, 100.0}};
                counting.calls = 0;
                const PixelValue a = skipping.integrate(ray, iv);
                on += counting.calls;
                counting.calls = 0;
                const PixelValue b = plain.integrate(ray, iv);
                off += counting.calls;
                EXPECT_EQ(std::memcmp(&a.rgba, &b.rgba, sizeof(a.rgba)), 0) << x << " " << y;
                max_alpha = std::max(max_alpha, b.rgba.a);
            }
        EXPECT_GT(max_alpha, 0.1);
        EXPECT_LT(2 * on, off) << "sampled " << on << " of " << off;
        std::printf("order %d: sampled %lld of %lld segments\n", int(order), (long long)on, (long long)off);
    }
}

// Rays nearly parallel to the macrocell face u = 8 (direction x component +-1e-8), on a grid whose
// origin is far from 0 (x ~ 1000: positions are rounded to 1.1e-13, i.e. to ~1e-5 in t) and whose
// spacing is not a power of 2: the sample positions cross the face up to ~100 segments away from where
// the slab planes put it, before or after. The first voxel layer macrocell 0 does not read is 1 (all
// else 0), so every sample past the face has opacity > 0: the walk must check its estimate of the
// exit, in both orders.
TEST(EmptySpace, GrazingRaysAtAFace) {
    int visible = 0, rays = 0;
    for (double sx : {0.7, 0.3})
        for (Interpolation interp : {Interpolation::Trilinear, Interpolation::TricubicBSpline}) {
            // The first voxel layer the samples of macrocell 0 do not read: 9, or 10 with the apron.
            const int layer = interp == Interpolation::Trilinear ? 9 : 10;
            FieldSpec f;
            f.kind = FieldSpec::Kind::Cells;
            f.dims = {17, 3, 3};
            for (int k = 0; k < 3; ++k)
                for (int j = 0; j < 3; ++j)
                    for (int i = 0; i < 17; ++i) f.values.push_back(i == layer ? 1.0 : 0.0);
            const double ox = 1000.1;
            const Volume volume = make_procedural_volume(f, glm::dvec3(ox, 0.0, 0.0), glm::dvec3(sx, 1.0, 1.0));
            TransferSpec ts;
            ts.opacity = {{0.0, 0.0}, {1.0, 1.0}};
            const TransferFunction tf(ts, volume);
            const VolumeSampler sampler(volume, interp);
            const SamplePipeline pipeline(sampler, tf, nullptr, nullptr, nullptr);
            const MacrocellGrid grid(sampler, tf, MacrocellGrid::Classification::Post);
            ASSERT_TRUE(grid.empty({0, 0, 0}));
            const double face = ox + 8.0 * sx;
            for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront})
                for (double sign : {1.0, -1.0})
                    for (int n = 0; n < 50; ++n) {
                        RenderSpec render;
                        render.order = order;
                        const double step = 1e-7;
                        const IntegrationContext with{pipeline, step, render, &grid}, without{pipeline, step, render, nullptr};
                        const CompositeIntegrator skipping(with), plain(without);
                        const double dx = 1e-8 * (1.0 + 0.003 * n), dz = std::sqrt(1.0 - dx * dx);
                        Ray ray;
                        ray.origin = {face - sign * 1e-8, 1.0 + 0.01 * n, 0.0};
                        ray.direction = {sign * dx, 0.0, dz};
                        const double tc = 1e-8 / dx;  // about where the ray meets the face
                        const std::vector<Interval> iv{{tc - 3e-5, tc + 3e-5}};
                        const PixelValue a = skipping.integrate(ray, iv), b = plain.integrate(ray, iv);
                        EXPECT_EQ(std::memcmp(&a.rgba, &b.rgba, sizeof(a.rgba)), 0)
                            << "sx " << sx << " sign " << sign << " n " << n << " alpha " << b.rgba.a;
                        visible += b.rgba.a > 0.0;
                        ++rays;
                    }
        }
    EXPECT_EQ(visible, rays);
}

// ---- bitwise equality of skipping on and off ----

TEST(EmptySpace, MarschnerLobbStepsAndOrders) {
    for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront})
        for (double h : {0.5, 0.37, 1.0, 2.3, 0.125}) {
            Scene s = marschner_lobb_scene();
            s.render.order = order;
            set_step(s, h, h == 0.5 ? StepUnits::Voxel : StepUnits::World);
            expect_bitwise_equal(s, "order " + std::to_string(int(order)) + " h " + std::to_string(h));
        }
}

TEST(EmptySpace, Interpolations) {
    for (Interpolation i : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                            Interpolation::TricubicCatmullRom})
        for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
            Scene s = gaussian_scene();
            s.volume().interpolation = i;
            s.render.order = order;
            expect_bitwise_equal(s, "interpolation " + std::to_string(int(i)));
            Scene m = marschner_lobb_scene();
            m.volume().interpolation = i;
            m.render.order = order;
            set_step(m, 0.61);
            expect_bitwise_equal(m, "ML interpolation " + std::to_string(int(i)));
        }
}

TEST(EmptySpace, EarlyTerminationShadingGradientOpacity) {
    Scene s = gaussian_scene();
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.55, 0.0}, {0.6, 1.0}, {0.65, 0.9}, {0.8, 0.0}};
    s.render.early_termination = 0.5;
    expect_bitwise_equal(s, "early termination");
    s.render.early_termination.reset();
    s.volume().shading = ShadingSpec{};
    for (Interpolation i : {Interpolation::Trilinear, Interpolation::TricubicBSpline}) {
        s.volume().interpolation = i;
        expect_bitwise_equal(s, "shaded");
    }
    s.volume().transfer.gradient_opacity = {{0.0, 0.0}, {0.2, 1.0}};
    expect_bitwise_equal(s, "gradient opacity");
    s.volume().gradient.cache = true;
    expect_bitwise_equal(s, "cached gradient");
    s.volume().gradient.cache = false;
    s.volume().interpolation = Interpolation::Trilinear;
    s.volume().gradient.scheme = GradientSpec::Scheme::Forward;
    expect_bitwise_equal(s, "forward gradient");
    // The normalised domain.
    Scene n = gaussian_scene();
    n.volume().transfer.domain = TransferSpec::Domain::Normalized;
    n.volume().transfer.window = std::array<double, 2>{-1.0, 3.0};
    n.volume().transfer.opacity = {{0.0, 0.0}, {0.38, 0.0}, {0.4, 0.7}, {0.42, 0.0}};
    expect_bitwise_equal(n, "normalized");
}

TEST(EmptySpace, PreClassification) {
    for (Interpolation i : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                            Interpolation::TricubicCatmullRom})
        for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
            Scene s = gaussian_scene();
            s.volume().classify = VolumeSpec::Classify::Pre;
            s.volume().interpolation = i;
            s.render.order = order;
            expect_bitwise_equal(s, "pre " + std::to_string(int(i)));
            s.volume().shading = ShadingSpec{};
            s.volume().transfer.gradient_opacity = {{0.0, 0.0}, {0.2, 1.0}};
            expect_bitwise_equal(s, "pre, shaded, gradient opacity " + std::to_string(int(i)));
        }
}

TEST(EmptySpace, BoundaryClassification) {
    for (auto classify : {VolumeSpec::Classify::Post, VolumeSpec::Classify::Pre})
        for (Interpolation i : {Interpolation::Trilinear, Interpolation::TricubicBSpline}) {
            Scene s = gaussian_scene();
            ClassificationSpec c;
            c.type = ClassificationSpec::Type::Boundary;
            c.regions = {{0.0, 0.0, {0.1, 0.1, 0.1}}, {0.5, 0.0, {0.2, 0.4, 0.9}}, {0.6, 0.8, {1.0, 0.6, 0.2}},
                         {0.7, 0.0, {1.0, 1.0, 1.0}}};
            c.opacity_unit_distance = 0.5;
            s.volume().classification = c;
            s.volume().classify = classify;
            s.volume().interpolation = i;
            expect_bitwise_equal(s, "boundary");
            s.volume().shading = ShadingSpec{};
            s.render.order = CompositeOrder::BackToFront;
            expect_bitwise_equal(s, "boundary, shaded, back to front");
        }
}

// Orthographic rays along each axis through macrocell faces and edges (the pixel centres land on
// integer voxel coordinates, every 8th of them a macrocell face), with steps whose midpoints fall on
// faces; a perspective ray along a macrocell edge; cameras inside the volume and a box smaller than
// the domain.
TEST(EmptySpace, AxisParallelRaysOnFacesAndEdges) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {33, 33, 33};
    g.center = {15.0, 17.0, 16.0};
    g.sigma = 7.0;
    // 16 x 16 pixels over a view height of 16 centred on 8.5: pixel centres at 1, 2, ..., 16.
    struct View {
        glm::dvec3 eye, target, up;
    };
    const std::vector<View> views = {
        {{8.5, 8.5, 100.0}, {8.5, 8.5, 0.0}, {0, 1, 0}},   {{8.5, 8.5, -100.0}, {8.5, 8.5, 0.0}, {0, 1, 0}},
        {{100.0, 8.5, 8.5}, {0.0, 8.5, 8.5}, {0, 0, 1}},   {{-100.0, 8.5, 8.5}, {0.0, 8.5, 8.5}, {0, 0, 1}},
        {{8.5, 100.0, 8.5}, {8.5, 0.0, 8.5}, {0, 0, 1}},   {{8.5, -100.0, 8.5}, {8.5, 0.0, 8.5}, {1, 0, 0}},
    };
    for (Interpolation i : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline})
        for (double h : {1.0, 3.2, 16.0 / 7.0, 0.5})
            for (const View& v : views) {
                Scene s = field_scene(g);
                s.volume().transfer.opacity = {{0.0, 0.0}, {0.6, 0.0}, {0.7, 0.9}, {0.8, 0.2}};
                s.volume().interpolation = i;
                s.camera = orthographic(v.eye, v.target, v.up, 16.0);
                s.image.width = s.image.height = 16;
                set_step(s, h);
                s.render.order = h == 1.0 ? CompositeOrder::BackToFront : CompositeOrder::FrontToBack;
                expect_bitwise_equal(s, "axis view, step " + std::to_string(h));
            }
    // A perspective camera whose centre ray (odd image) runs along the edge x = y = 16.
    Scene s = field_scene(g);
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.6, 0.0}, {0.7, 0.9}, {0.8, 0.2}};
    s.camera = perspective({16.0, 16.0, 80.0}, {16.0, 16.0, 0.0}, {0, 1, 0}, 30.0);
    s.image.width = s.image.height = 17;
    set_step(s, 1.0);
    expect_bitwise_equal(s, "edge ray");
    // Eyes inside the volume (inside the shell), looking in several directions.
    for (const glm::dvec3& target : {glm::dvec3(15, 17, 16), glm::dvec3(0, 0, 0), glm::dvec3(32, 3, 30)}) {
        s.camera = perspective({17.0, 18.0, 16.5}, target, {0, 0, 1}, 70.0);
        expect_bitwise_equal(s, "inside");
    }
    // A box smaller than the domain: intervals start and end inside macrocells.
    s.volume().bounds.min = glm::dvec3(3.3, 2.1, 5.7);
    s.volume().bounds.max = glm::dvec3(29.9, 30.2, 27.1);
    s.camera = perspective({60, -40, 50}, {16, 16, 16}, {0, 0, 1}, 40.0);
    expect_bitwise_equal(s, "bounds");
}

// Odd dims (one axis of 2 voxels, one of 1 voxel), orthographic and perspective, many camera positions.
TEST(EmptySpace, OddDimsAndRandomCameras) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), elevation(-1.4, 1.4), dist(35.0, 80.0);
    const std::vector<std::array<std::int64_t, 3>> dims = {{21, 30, 13}, {19, 2, 23}, {26, 17, 9}};
    for (const auto& d : dims) {
        FieldSpec g;
        g.kind = FieldSpec::Kind::Gaussian;
        g.dims = d;
        g.center = {0.45 * double(d[0] - 1), 0.5 * double(d[1] - 1), 0.55 * double(d[2] - 1)};
        g.sigma = 5.0;
        Scene s = field_scene(g);
        s.volume().transfer.opacity = {{0.0, 0.0}, {0.5, 0.0}, {0.55, 0.8}, {0.6, 0.0}};
        s.image.width = s.image.height = 12;
        double max_alpha = 0.0;
        for (int n = 0; n < 6; ++n) {
            const double a = angle(rng), e = elevation(rng), r = dist(rng);
            const glm::dvec3 eye = g.center + r * glm::dvec3(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e));
            s.camera = n % 2 ? perspective(eye, g.center, {0, 0, 1}, 35.0) : orthographic(eye, g.center, {0, 0, 1}, 30.0);
            set_step(s, 0.3 + 0.2 * n);
            s.volume().interpolation = n % 3 == 0 ? Interpolation::TricubicBSpline : Interpolation::Trilinear;
            s.render.order = n % 2 ? CompositeOrder::BackToFront : CompositeOrder::FrontToBack;
            max_alpha = std::max(max_alpha, expect_bitwise_equal(s, "dims " + std::to_string(d[0]) + "x" +
                                                                        std::to_string(d[1]) + "x" + std::to_string(d[2]) +
                                                                        " camera " + std::to_string(n),
                                                                    false));
        }
        EXPECT_GT(max_alpha, 0.0);
    }
    // A single layer (n = 1 along z) seen along its plane.
    FieldSpec f;
    f.kind = FieldSpec::Kind::Radial;
    f.dims = {30, 25, 1};
    f.center = {14.0, 12.0, 0.0};
    Scene s = field_scene(f);
    s.volume().transfer.opacity = {{0.0, 0.0}, {6.0, 0.0}, {7.0, 0.5}, {8.0, 0.0}};
    s.camera = orthographic({14.0, -50.0, 0.0}, {14.0, 0.0, 0.0}, {0, 0, 1}, 2.0);  // 30 wide
    s.image.width = 15;
    s.image.height = 1;
    set_step(s, 0.7);
    expect_bitwise_equal(s, "single layer");
}

// Small bright spots next to empty macrocells: voxels at 1, 2, 6, 7 (mod 8) per axis, so the first
// segment after an empty run, or the last before one, often has opacity > 0. Skipping one segment too
// many, or sampling a skipped one at another t, changes pixels here.
TEST(EmptySpace, SpotsNextToEmptyMacrocells) {
    std::mt19937_64 rng(5);
    const std::vector<std::int64_t> near_faces = {1, 2, 6, 7, 9, 10, 14, 15, 17, 18, 22, 23, 25, 26, 30, 31};
    std::uniform_int_distribution<std::size_t> pick(0, near_faces.size() - 1);
    FieldSpec f;
    f.kind = FieldSpec::Kind::Cells;
    f.dims = {34, 34, 34};
    f.values.assign(34 * 34 * 34, 0.0);
    for (int n = 0; n < 60; ++n) {
        const std::int64_t i = near_faces[pick(rng)], j = near_faces[pick(rng)], k = near_faces[pick(rng)];
        f.values[std::size_t(i + 34 * (j + 34 * k))] = 0.5 + 0.01 * n;
    }
    std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), elevation(-1.4, 1.4);
    for (Interpolation interp : {Interpolation::Nearest, Interpolation::Trilinear, Interpolation::TricubicBSpline,
                                 Interpolation::TricubicCatmullRom})
        for (int n = 0; n < 8; ++n) {
            Scene s = field_scene(f, {0.25, -0.5, 0.125}, {1.0, 0.75, 1.25});
            s.volume().interpolation = interp;
            s.volume().transfer.opacity = {{0.0, 0.0}, {1.0, 0.9}};
            s.volume().transfer.color = {{0.0, 1.0, 0.5, 0.25}, {1.0, 0.25, 0.5, 1.0}};
            if (interp == Interpolation::TricubicCatmullRom)  // overshoot below 0 is transparent too
                s.volume().transfer.opacity = {{-1.0, 0.0}, {0.0, 0.0}, {1.0, 0.9}};
            const glm::dvec3 c(16.75, 12.0, 20.75);
            if (n < 3) {  // axis-parallel, pixel centres on voxel columns
                const glm::dvec3 axis = n == 0 ? glm::dvec3(0, 0, 1) : n == 1 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
                s.camera = orthographic(c + 100.0 * axis, c, n == 0 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1), 16.0);
                s.image.width = s.image.height = 16;
            } else {
                const double a = angle(rng), e = elevation(rng);
                const glm::dvec3 eye = c + 70.0 * glm::dvec3(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e));
                s.camera = n % 2 ? perspective(eye, c, {0, 0, 1}, 40.0) : orthographic(eye, c, {0, 0, 1}, 44.0);
                s.image.width = s.image.height = 24;
            }
            set_step(s, n % 3 == 0 ? 16.0 / 9.0 : n % 3 == 1 ? 0.5 : 0.77);
            s.render.order = n % 2 ? CompositeOrder::BackToFront : CompositeOrder::FrontToBack;
            expect_bitwise_equal(s, "spots, interpolation " + std::to_string(int(interp)) + " view " + std::to_string(n));
        }
}

// The composite walk against every segment of the chord, checked without the walk's own logic: each
// segment it passes over has its midpoint in an empty macrocell (MacrocellGrid::empty at the
// sampler's macrocell of that midpoint), each segment in a non-empty macrocell is visited, in order
// and once; next_run hands out exactly the segments next() returns one by one, in runs within one
// interval. Scattered spots (nearly every ray meets empty and non-empty macrocells in turn), two
// intervals per ray (the chord split in the middle), random directions and steps.
TEST(EmptySpace, WalkVisitsEveryNonEmptySegmentAndRunsMatchSegments) {
    std::mt19937_64 rng(11);
    FieldSpec f;
    f.kind = FieldSpec::Kind::Cells;
    f.dims = {50, 43, 37};
    f.values.assign(50 * 43 * 37, 0.0);
    std::uniform_int_distribution<int> ix(0, 49), iy(0, 42), iz(0, 36);
    for (int n = 0; n < 40; ++n) f.values[std::size_t(ix(rng) + 50 * (iy(rng) + 43 * iz(rng)))] = 1.0;
    const Volume volume = make_procedural_volume(f, glm::dvec3(-3.0, 2.0, 0.5), glm::dvec3(1.0, 0.75, 1.25));
    const VolumeSampler sampler(volume, Interpolation::Trilinear);
    TransferSpec ts;
    ts.opacity = {{0.0, 0.0}, {1.0, 0.5}};
    const TransferFunction tf(ts, volume);
    const MacrocellGrid grid(sampler, tf, MacrocellGrid::Classification::Post);
    ASSERT_GT(grid.empty_count(), 0);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const glm::dvec3 centre = 0.5 * (volume.domain_min() + volume.domain_max());
    std::int64_t visited = 0, all = 0, runs = 0;
    for (int n = 0; n < 300; ++n) {
        Ray ray;
        ray.origin = centre + 80.0 * glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
        ray.direction = glm::normalize(centre + 20.0 * glm::dvec3(u(rng), u(rng), u(rng)) - ray.origin);
        Interval chord;
        if (!intersect_box(ray, volume.domain_min(), volume.domain_max(), chord)) continue;
        const double mid = 0.5 * (chord.t0 + chord.t1);
        const std::vector<Interval> iv{{chord.t0, mid}, {mid, chord.t1}};
        const double step = 0.2 + 0.15 * (n % 9);
        // Every segment, and whether the walk may pass over it.
        std::vector<Segment> every;
        std::vector<bool> in_empty;
        for_each_segment(iv, step, [&](const Segment& sg) {
            every.push_back(sg);
            in_empty.push_back(grid.empty(grid.macrocell_at(ray.at(sg.midpoint()))));
            return true;
        });
        all += std::int64_t(every.size());
        // next(): a subsequence of `every` (compared bitwise) holding every non-empty segment.
        ForwardSegmentWalk walk(&grid, ray, iv, step);
        std::vector<Segment> by_segment;
        Segment sg;
        while (walk.next(sg)) by_segment.push_back(sg);
        std::size_t j = 0;
        for (const Segment& v : by_segment) {
            while (j < every.size() && std::memcmp(&every[j], &v, sizeof(Segment)) != 0) {
                EXPECT_TRUE(in_empty[j]) << "ray " << n << ": segment " << j << " passed over in a non-empty macrocell";
                ++j;
            }
            ASSERT_LT(j, every.size()) << "ray " << n << ": a visited segment that is not one of the chord's, or out of order";
            ++j;
        }
        for (; j < every.size(); ++j) EXPECT_TRUE(in_empty[j]) << "ray " << n << ": trailing segment " << j;
        visited += std::int64_t(by_segment.size());
        // next_run(): the same segments, placed by segment() from (iv, k, n).
        ForwardSegmentWalk run_walk(&grid, ray, iv, step);
        ForwardSegmentWalk::Run r;
        std::vector<Segment> by_run;
        while (run_walk.next_run(r)) {
            ++runs;
            ASSERT_LT(r.k, r.end);
            ASSERT_LE(r.end, r.n);
            EXPECT_EQ(r.n, segment_count(*r.iv, step));
            for (std::int64_t k = r.k; k < r.end; ++k) by_run.push_back(segment(*r.iv, step, k, r.n));
        }
        ASSERT_EQ(by_run.size(), by_segment.size()) << "ray " << n;
        if (!by_run.empty()) {  // (memcmp of empty vectors would pass null pointers)
            EXPECT_EQ(std::memcmp(by_run.data(), by_segment.data(), by_run.size() * sizeof(Segment)), 0) << "ray " << n;
        }
    }
    EXPECT_GT(all, 10000);
    EXPECT_LT(visited, all);  // something was passed over
    std::printf("visited %lld of %lld segments in %lld runs\n", (long long)visited, (long long)all, (long long)runs);
}

// ---- mip / minip: macrocells whose values cannot beat a ray's extremum so far -----------------

// The walk in extremum mode against every segment: the same extremum, first reached at the same t,
// bitwise, while visiting fewer segments (a Gaussian: once a ray has passed its closest approach to
// the centre, no macrocell beats its maximum; the minimum is at the ends of the chord).
TEST(ExtremumSkipping, WalkFindsTheSameExtremumWithFewerSamples) {
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {41, 37, 43};
    g.center = {17.0, 20.0, 22.0};
    g.sigma = 6.0;
    const Volume volume = make_procedural_volume(g, glm::dvec3(0.0), glm::dvec3(1.0));
    const VolumeSampler sampler(volume, Interpolation::Trilinear);
    TransferSpec ts;
    const TransferFunction tf(ts, volume);
    const MacrocellGrid grid(sampler, tf, MacrocellGrid::Classification::Post);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const bool maximum : {true, false}) {
        std::int64_t visited = 0, all = 0;
        for (int n = 0; n < 400; ++n) {
            Ray ray;
            ray.origin = glm::dvec3(20.0, 18.0, 21.0) + 60.0 * glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
            const glm::dvec3 target = glm::dvec3(20.0 + 15 * u(rng), 18.0 + 15 * u(rng), 21.0 + 15 * u(rng));
            ray.direction = glm::normalize(target - ray.origin);
            Interval chord;
            if (!intersect_box(ray, volume.domain_min(), volume.domain_max(), chord)) continue;
            const std::vector<Interval> iv{chord};
            const double step = 0.3 + 0.1 * (n % 7);
            auto run = [&](bool skip, std::int64_t& count) {
                double best = std::numeric_limits<double>::quiet_NaN(), t_best = 0.0;
                ForwardSegmentWalk walk = skip ? ForwardSegmentWalk(&grid, ray, iv, step, &best, maximum)
                                               : ForwardSegmentWalk(nullptr, ray, iv, step);
                Segment s;
                while (walk.next(s)) {
                    ++count;
                    const double v = sampler.value(ray.at(s.midpoint()));
                    if (std::isnan(best) || (maximum ? v > best : v < best)) {
                        best = v;
                        t_best = s.midpoint();
                    }
                }
                return std::make_pair(best, t_best);
            };
            const auto a = run(true, visited), b = run(false, all);
            EXPECT_EQ(std::memcmp(&a, &b, sizeof(a)), 0) << (maximum ? "max" : "min") << " ray " << n;
        }
        EXPECT_LT(visited, all) << (maximum ? "max" : "min");
        std::printf("%s: visited %lld of %lld segments\n", maximum ? "mip" : "minip", (long long)visited, (long long)all);
        EXPECT_LT(visited, all) << "some segments skipped";
        if (!maximum) {
            EXPECT_LT(10 * visited, 6 * all) << "minip: most of each chord skipped";
        }
    }
}

// Whole renders on the SIMD path (where mip / minip skip), skipping on and off: bitwise the same image,
// over several fields, odd dims, steps, cameras (perspective, orthographic, axis-parallel, inside) and
// a bounds box smaller than the domain.
TEST(ExtremumSkipping, RendersAreBitwiseTheSame) {
    auto render_simd = [](const Scene& s, bool skipping) {
        RenderOptions o;
        o.threads = 1;
        o.empty_space_skipping = skipping;
        return render_scene(s, o);
    };
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), elevation(-1.4, 1.4), dist(35.0, 80.0);
    std::vector<FieldSpec> fields;
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {33, 29, 2};
    g.center = {15.0, 13.0, 0.5};
    g.sigma = 6.0;
    fields.push_back(g);
    g.dims = {31, 33, 35};
    g.center = {12.0, 17.0, 20.0};
    fields.push_back(g);
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {41, 41, 41};
    fields.push_back(ml);
    int n = 0;
    for (const FieldSpec& f : fields)
        for (const Projection p : {Projection::Mip, Projection::Minip}) {
            Scene s = field_scene(f);
            s.volume().transfer.opacity = {{0.0, 0.1}, {1.0, 1.0}};
            s.render.projection = p;
            s.image.width = s.image.height = 16;
            const glm::dvec3 c = 0.5 * glm::dvec3(double(f.dims[0] - 1), double(f.dims[1] - 1), double(f.dims[2] - 1));
            for (int k = 0; k < 5; ++k, ++n) {
                const double a = angle(rng), e = elevation(rng), r = dist(rng);
                const glm::dvec3 eye = c + r * glm::dvec3(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e));
                if (k == 3)
                    s.camera = orthographic(c + glm::dvec3(0, 0, 90), c, {0, 1, 0}, 40.0);  // axis-parallel rays
                else if (k == 4)
                    s.camera = perspective(c + glm::dvec3(1.5, -0.5, 0.25), eye, {0, 0, 1}, 80.0);  // eye inside
                else
                    s.camera = k % 2 ? perspective(eye, c, {0, 0, 1}, 35.0) : orthographic(eye, c, {0, 0, 1}, 40.0);
                set_step(s, 0.25 + 0.35 * k);
                if (n % 4 == 3) {
                    s.volume().bounds.min = 0.4 * c;  // starts and ends inside macrocells
                    s.volume().bounds.max = 1.5 * c;
                } else {
                    s.volume().bounds.min.reset();
                    s.volume().bounds.max.reset();
                }
                const Image on = render_simd(s, true), off = render_simd(s, false);
                ASSERT_EQ(on.pixels.size(), off.pixels.size());
                EXPECT_EQ(std::memcmp(on.pixels.data(), off.pixels.data(), on.pixels.size() * sizeof(on.pixels[0])), 0)
                    << "case " << n;
                double max_alpha = 0.0;
                for (int y = 0; y < off.height; ++y)
                    for (int x = 0; x < off.width; ++x) max_alpha = std::max(max_alpha, off.at(x, y, 3));
                EXPECT_GT(max_alpha, 0.0) << "case " << n << ": blank image";
            }
        }
}
