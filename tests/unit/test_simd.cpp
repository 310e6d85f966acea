// The SIMD packet path of compositing (PacketComposite.h) against the scalar path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <hwy/targets.h>

#include "TestScenes.h"

using namespace volref;
using namespace volref::test;

namespace {

Scene ml_scene(int w, int h) {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {33, 29, 31};  // not multiples of anything
    Scene s = field_scene(ml, glm::dvec3(-3.0, 1.0, 2.0), glm::dvec3(0.5, 0.7, 0.6));
    s.volume.transfer.color = {{0.0, 0.1, 0.2, 0.9}, {0.4, 0.3, 0.5, 0.2}, {0.55, 1.0, 0.8, 0.3}, {1.0, 1.0, 0.9, 0.6}};
    s.volume.transfer.opacity = {{0.0, 0.0}, {0.3, 0.0}, {0.5, 0.35}, {0.52, 0.35}, {0.8, 0.9}, {1.0, 1.0}};
    s.volume.transfer.opacity_unit_distance = 2.0;
    s.image.width = w;
    s.image.height = h;
    return s;
}

// Max |SIMD - scalar| over the image, and a check that the image is not empty.
double max_difference(const Scene& s) {
    const Image simd = render_scene(s, {.threads = 1, .simd = true});
    const Image scalar = render_scene(s, {.threads = 1, .simd = false});
    double diff = 0.0, max_alpha = 0.0;
    for (std::size_t i = 0; i < simd.pixels.size(); ++i) {
        diff = std::max(diff, std::fabs(simd.pixels[i] - scalar.pixels[i]));
        if (i % 4 == 3) max_alpha = std::max(max_alpha, scalar.pixels[i]);
    }
    EXPECT_GT(max_alpha, 0.05);
    return diff;
}

}  // namespace

// The packet path differs from the scalar one only in the last bits of exp, expm1 and log1p.
TEST(Simd, CompositeMatchesTheScalarPath) {
    Scene s = ml_scene(37, 23);  // packets of 16 with a ragged tail
    EXPECT_LT(max_difference(s), 1e-13);
    s.render.step = 0.37;  // steps that do not divide the chords
    EXPECT_LT(max_difference(s), 1e-13);
    s.render.early_termination = 0.6;
    EXPECT_LT(max_difference(s), 1e-13);
    s.render.early_termination.reset();
    s.volume.transfer.domain = TransferSpec::Domain::Normalized;
    s.volume.transfer.window = std::array<double, 2>{-0.2, 1.1};
    EXPECT_LT(max_difference(s), 1e-13);
    s.volume.transfer.color = {{0.5, 0.3, 0.6, 0.9}};  // one row
    s.volume.transfer.opacity = {{0.0, 0.0}, {0.5, 0.0}, {0.5, 1.0}};  // a jump to opaque
    EXPECT_LT(max_difference(s), 1e-13);
}

TEST(Simd, OrthographicAxisAlignedAndFlatVolumes) {
    Scene s = ml_scene(20, 20);
    s.camera.type = CameraSpec::Type::Orthographic;
    s.camera.eye = {5.0, 10.0, 50.0};
    s.camera.target = {5.0, 10.0, 0.0};
    s.camera.height = 20.0;
    EXPECT_LT(max_difference(s), 1e-13);
    // A flat volume (one layer in z) seen edge-on.
    FieldSpec g;
    g.kind = FieldSpec::Kind::Gaussian;
    g.dims = {20, 20, 1};
    g.center = {10, 10, 0};
    g.sigma = 4;
    Scene f = field_scene(g);
    f.volume.transfer.opacity = {{0, 0}, {1, 0.7}};
    f.camera.type = CameraSpec::Type::Perspective;
    f.camera.eye = {10, -30, 0};
    f.camera.target = {10, 10, 0};
    f.camera.up = {0, 0, 1};
    f.image.width = f.image.height = 16;
    const Image a = render_scene(f, {.threads = 1, .simd = true}), b = render_scene(f, {.threads = 1, .simd = false});
    for (std::size_t i = 0; i < a.pixels.size(); ++i) EXPECT_NEAR(a.pixels[i], b.pixels[i], 1e-13);
}

// A constant box through the packet path keeps the closed form alpha = 1 - (1 - a)^(L / l).
TEST(Simd, ConstantBoxClosedForm) {
    Scene s = field_scene(constant_field(2.0, {5, 5, 5}));
    s.volume.transfer.opacity = {{0.0, 0.35}};
    s.volume.transfer.color = {{0.0, 0.2, 0.6, 0.9}};
    s.camera = ortho_down_z(2.0, 2.0, 10.0, 0.3);  // 19 x 3 pixels over [1.05, 2.95] x [1.85, 2.15]
    s.image.width = 19;
    s.image.height = 3;
    s.render.step = 0.3;
    s.render.step_units = StepUnits::World;
    const Image im = render_scene(s, {.threads = 2, .simd = true});
    const double alpha = 1.0 - std::pow(0.65, 4.0);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 19; ++x) {
            EXPECT_NEAR(im.at(x, y, 3), alpha, 1e-14);
            EXPECT_NEAR(im.at(x, y, 1), 0.6 * alpha, 1e-14);
        }
}

// Determinism across SIMD widths: the image is bitwise the same whether Highway dispatches to
// AVX-512 (8 lanes) or AVX2 (4 lanes): every lane computes the same arithmetic, and both have fused
// multiply-adds inside Highway's exp/log polynomials. SSE4 has no FMA, so its exp/log differ in the
// last bits: within 1e-13 of the others.
TEST(Simd, BitwiseIdenticalAcrossInstructionSets) {
    const Scene s = ml_scene(29, 17);
    const Image best = render_scene(s, {.threads = 1, .simd = true});
    int compared = 0;
    for (std::int64_t target : {HWY_AVX3, HWY_AVX2, HWY_SSE4}) {
        if ((hwy::SupportedTargets() & target) == 0) continue;
        hwy::SetSupportedTargetsForTest(target);
        const Image im = render_scene(s, {.threads = 1, .simd = true});
        hwy::SetSupportedTargetsForTest(0);
        if (target == HWY_SSE4) {
            for (std::size_t i = 0; i < im.pixels.size(); ++i) EXPECT_NEAR(im.pixels[i], best.pixels[i], 1e-13);
        } else {
            EXPECT_EQ(std::memcmp(im.pixels.data(), best.pixels.data(), im.pixels.size() * sizeof(double)), 0)
                << hwy::TargetName(target);
        }
        ++compared;
    }
    EXPECT_GE(compared, 2);
}

// mip and minip: only reconstruction and comparisons are vectorised, so the packet path is
// bitwise the scalar one.
TEST(Simd, MipAndMinipAreBitwiseTheScalarPath) {
    for (auto proj : {Projection::Mip, Projection::Minip}) {
        Scene s = ml_scene(37, 23);
        s.render.projection = proj;
        s.render.step = 0.37;
        s.volume.transfer.opacity = {{0.0, 0.2}, {0.5, 0.1}, {1.0, 0.9}};
        const Image a = render_scene(s, {.threads = 1, .simd = true});
        const Image b = render_scene(s, {.threads = 1, .simd = false});
        EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(double)), 0);
        double max_alpha = 0.0;
        for (std::size_t i = 3; i < a.pixels.size(); i += 4) max_alpha = std::max(max_alpha, a.pixels[i]);
        EXPECT_GT(max_alpha, 0.1);
    }
}

// Empty-space skipping in the packet path (each lane walks with ForwardSegmentWalk) leaves every
// pixel bitwise as without skipping, as in the scalar path.
TEST(Simd, SkippingDoesNotChangeThePacketPath) {
    for (double step : {0.5, 0.37, 1.3}) {
        Scene s = ml_scene(41, 19);
        s.render.step = step;
        const Image on = render_scene(s, {.threads = 1, .empty_space_skipping = true, .simd = true});
        const Image off = render_scene(s, {.threads = 1, .empty_space_skipping = false, .simd = true});
        EXPECT_EQ(std::memcmp(on.pixels.data(), off.pixels.data(), on.pixels.size() * sizeof(double)), 0) << step;
    }
}
