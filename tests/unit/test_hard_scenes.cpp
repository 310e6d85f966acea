// Issue 18: the adaptive integrator's error channel must bound the true error on every pixel of a
// held-back set of random hard scenes. Each scene is drawn from a fixed seed (the seeds are the test's
// parameters; they were not tuned): a field linear along one axis whose transfer-function rows lie
// on grid planes (jumps of colour and opacity, tents reaching opacity 1, steps), anisotropic spacing,
// origins far from 0, and cameras whose rays run along, across and inside the grid planes.
//
// The truth is a fine fixed step (midpoint segments, conventions section 4) at h = 2e-4 world units,
// with its own error bound: 4 x the largest difference to the steps 0.77 h and 0.61 h (the smooth
// part, O(h^2)), plus 3 h sigma_max at the transfer function's jump (derived where it is computed
// below), plus 1e-7 for rounding over ~10^5 samples. A pixel fails when
//   |adaptive - fixed(h)| > error channel + that bound.
// The floor of what this detects is therefore about 1.4e-3 (sigma_max = -log(0.1)); the failures it
// was written for were 0.03-0.99 off with an error of 2e-13 (with the old opaque-piece rule, seeds
// 1002, 1009 and 1011 fail by up to 0.99). Every seed from 1001 to 1040 is run; none was dropped.
//
// The scenes are in the class where the estimate is a bound (Cartesian trilinear, post-classified
// transfer function, unshaded: every kink of the integrand is a cut). Shaded, gradient-opacity,
// Levoy-classified, tricubic and beam-space scenes carry kAdaptiveWeakSafety instead
// (test_adaptive.cpp, WeakerGuaranteeScenesStayWithinTheirEstimate).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "TestScenes.h"

using namespace volref;
using namespace volref::test;

namespace {

// The colour always jumps at the row value k; the opacity jumps there, ramps over 1e-9 or peaks.
Scene hard_scene(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
    auto pick = [&](int n) { return int(std::uniform_int_distribution<int>(0, n - 1)(rng)); };
    const int axis = pick(3);
    const std::int64_t n = pick(2) ? 5 : 9;
    // Half of the scenes on the unit grid at 0 (where a row's root and a cell face coincide to the last
    // bit), the others anisotropic and far from 0.
    const bool unit_grid = pick(2) == 0;
    const double spacings[] = {1.0, 0.5, 2.0, 0.75};
    glm::dvec3 spacing(1.0);
    const double offsets[] = {0.0, 0.0, -3.25, 1e5};
    glm::dvec3 origin(0.0);
    for (int a = 0; a < 3; ++a) {
        spacing[a] = unit_grid ? 1.0 : spacings[pick(4)];
        origin[a] = unit_grid ? 0.0 : offsets[pick(4)];
    }
    // f = (x_axis - origin) / spacing: voxel i holds i, so value k is reached on the grid plane i = k.
    std::array<double, 4> coefficients{0.0, 0.0, 0.0, -origin[axis] / spacing[axis]};
    coefficients[std::size_t(axis)] = 1.0 / spacing[axis];
    Scene s = field_scene(linear_field(coefficients, {n, n, n}), origin, spacing);
    const double k = double(1 + pick(int(n) - 2)), top = double(n - 1);
    TransferSpec& tf = s.volume().transfer;
    const double below[] = {0.0, 0.05}, above[] = {0.5, 0.9, 1.0};
    switch (pick(3)) {
        case 0:  // a jump of colour and opacity at k
            tf.opacity = {{0.0, below[pick(2)]}, {k, below[pick(2)]}, {k, above[pick(3)]}, {top, 0.9}};
            break;
        case 1:  // a tent peaking at k (opacity 1 at a point when the peak is 1)
            tf.opacity = {{0.0, 0.0}, {k, above[pick(3)]}, {top, 0.0}};
            break;
        default:  // a ramp over one billionth of a unit
            tf.opacity = {{0.0, 0.0}, {k, 0.0}, {k + 1e-9, 0.8}, {top, 0.8}};
            break;
    }
    tf.color = {{0.0, 0.0, 0.0, 1.0}, {k, 0.0, 0.0, 1.0}, {k, 1.0, 0.5, 0.0}, {top, 1.0, 0.5, 0.0}};
    const glm::dvec3 centre = origin + 0.5 * top * spacing;
    const double extent = top * std::max({spacing.x, spacing.y, spacing.z});
    s.image.width = s.image.height = 16;
    s.camera.target = centre;
    s.camera.up = glm::dvec3(0.0, 0.0, 1.0);
    switch (pick(3)) {
        case 0: {  // orthographic along a grid axis: rays along and inside grid planes
            glm::dvec3 d(0.0);
            const int along = pick(3);
            d[along] = pick(2) ? 1.0 : -1.0;
            s.camera.type = CameraSpec::Type::Orthographic;
            s.camera.eye = centre - 3.0 * extent * d;
            s.camera.up = along == 2 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(0.0, 0.0, 1.0);
            s.camera.height = extent;
            break;
        }
        case 1:
            s.camera.type = CameraSpec::Type::Orthographic;
            s.camera.eye = centre + extent * glm::dvec3(uniform(-2, 2), uniform(-2, 2), uniform(-2, 2));
            s.camera.height = extent;
            break;
        default:
            s.camera.type = CameraSpec::Type::Perspective;
            s.camera.eye = centre + extent * glm::dvec3(uniform(-2.5, 2.5), uniform(-2.5, 2.5), uniform(-2.5, 2.5));
            s.camera.fov_y = 40.0;
            break;
    }
    s.render.projection = pick(5) == 0 ? Projection::Xray : Projection::Composite;
    s.render.gain = 0.05;
    return s;
}

class HardScenes : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(HardScenes, ErrorChannelBoundsTheTrueErrorOnEveryPixel) {
    Scene s = hard_scene(GetParam());
    s.render.integrator = IntegrationMethod::Adaptive;
    const Image a = render_scene(s, {.threads = 2});
    s.render.integrator = IntegrationMethod::Fixed;
    s.render.step_units = StepUnits::World;
    Image fixed[3];
    const double h = 2e-4, factors[3] = {1.0, 0.77, 0.61};
    for (int i = 0; i < 3; ++i) {
        s.render.step = h * factors[i];
        fixed[i] = render_scene(s, {.threads = 2});
    }
    const std::size_t err = a.channel_count() - 1;
    ASSERT_EQ(a.channels[err], "error");
    // At the jump of the transfer function (crossed at most once: the field is linear along the ray) the
    // segment holding it takes one side's sample for its whole length h: its optical depth is off by
    // at most h |sigma_2 - sigma_1|, which changes everything behind it by at most that times K = 1,
    // and its own emission by at most alpha K <= h sigma_max; together <= 3 h sigma_max, sigma_max the
    // largest extinction -log(1 - a) / l of the rows with a < 1 (a = 1 beyond the jump: the segment
    // before it is off by the same bound, and the opaque sample's colour is the row's constant).
    double sigma_max = 0.0;
    for (const auto& row : s.volume().transfer.opacity)
        if (row[1] < 1.0) sigma_max = std::max(sigma_max, -std::log1p(-row[1]) / s.volume().transfer.opacity_unit_distance);
    const double jump_bound = s.render.projection == Projection::Composite ? 3.0 * h * sigma_max : 0.0;
    int seen = 0;
    for (int y = 0; y < s.image.height; ++y)
        for (int x = 0; x < s.image.width; ++x) {
            double diff = 0.0, spread = 0.0;
            for (std::size_t c = 0; c < 4; ++c) {
                diff = std::max(diff, std::fabs(a.at(x, y, c) - fixed[0].at(x, y, c)));
                for (int i = 1; i < 3; ++i) spread = std::max(spread, std::fabs(fixed[0].at(x, y, c) - fixed[i].at(x, y, c)));
            }
            seen += fixed[0].at(x, y, 3) > 0.01;
            EXPECT_LE(diff, a.at(x, y, err) + 4.0 * spread + jump_bound + 1e-7)
                << "seed " << GetParam() << " pixel " << x << "," << y << ": error channel " << a.at(x, y, err)
                << ", fixed-step spread " << spread;
        }
    EXPECT_GT(seen, 0) << "seed " << GetParam() << ": the volume is in view";
}

INSTANTIATE_TEST_SUITE_P(HeldBack, HardScenes, ::testing::Range<std::uint64_t>(1001, 1041));

}  // namespace
