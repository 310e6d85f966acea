// The SIMD packet path of compositing (PacketComposite.h) against the scalar path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <hwy/targets.h>

#include "TestScenes.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/march/SegmentWalk.h"
#include "core/integrate/packet/PairFetch.h"
#include "core/SimdMath.h"
#include "core/render/PreparedScene.h"

using namespace volref;
using namespace volref::test;

namespace {

Scene ml_scene(int w, int h) {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {33, 29, 31};  // not multiples of anything
    Scene s = field_scene(ml, glm::dvec3(-3.0, 1.0, 2.0), glm::dvec3(0.5, 0.7, 0.6));
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {0.4, 0.3, 0.5, 0.2}, {0.55, 1.0, 0.8, 0.3}, {1.0, 1.0, 0.9, 0.6}};
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.3, 0.0}, {0.5, 0.35}, {0.52, 0.35}, {0.8, 0.9}, {1.0, 1.0}};
    s.volume().transfer.opacity_unit_distance = 2.0;
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

// Issue 18: a ray that meets nothing (a miss, or only transparent samples) has alpha +0, not -0, on
// every path (the SIMD path once gave -0: Highway's expm1(-0) is +0 and the alpha is its negation).
TEST(Simd, EmptyPixelsHavePositiveZeroAlpha) {
    Scene s = ml_scene(37, 23);
    s.camera.type = CameraSpec::Type::Perspective;
    for (bool simd : {true, false})
        for (ProfileId p : {ProfileId::Reference, ProfileId::Fast}) {
            s.render.profile = p;
            const Image im = render_scene(s, {.threads = 1, .simd = simd});
            int zeros = 0;
            for (std::size_t i = 3; i < im.pixels.size(); i += 4)
                if (im.pixels[i] == 0.0) {
                    ++zeros;
                    EXPECT_FALSE(std::signbit(im.pixels[i])) << "pixel " << i / 4 << " simd " << simd;
                }
            EXPECT_GT(zeros, 0);  // the scene has empty pixels
        }
}

// The packet path differs from the scalar one only in the last bits of exp, expm1 and log1p.
TEST(Simd, CompositeMatchesTheScalarPath) {
    Scene s = ml_scene(37, 23);  // packets of 16 with a ragged tail
    EXPECT_LT(max_difference(s), 1e-13);
    s.render.step = 0.37;  // steps that do not divide the chords
    EXPECT_LT(max_difference(s), 1e-13);
    s.render.early_termination = 0.6;
    EXPECT_LT(max_difference(s), 1e-13);
    s.render.early_termination.reset();
    s.volume().transfer.domain = TransferSpec::Domain::Normalized;
    s.volume().transfer.window = std::array<double, 2>{-0.2, 1.1};
    EXPECT_LT(max_difference(s), 1e-13);
    s.volume().transfer.color = {{0.5, 0.3, 0.6, 0.9}};  // one row
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.5, 0.0}, {0.5, 1.0}};  // a jump to opaque
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
    f.volume().transfer.opacity = {{0, 0}, {1, 0.7}};
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
    s.volume().transfer.opacity = {{0.0, 0.35}};
    s.volume().transfer.color = {{0.0, 0.2, 0.6, 0.9}};
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
namespace {
Scene shaded_ml_scene();
void expect_identical_across_instruction_sets(const Scene& s);
}  // namespace

// Transfer functions of 1 to 40 rows: the packet kernels pick rows from registers (RegisterTable: up
// to 4 vectors of rows, so 16 rows on 4 double lanes, 32 on 8 float lanes) or gather them (more rows);
// every count from one part to past the last must give the scalar path's values, and the same values
// on every instruction set (2, 4 or 8 lanes: different parts for the same row; bitwise between AVX-512
// and AVX2, within 1e-13 on SSE4, as expect_identical_across_instruction_sets checks).
TEST(Simd, TablesOfManyRowsMatchTheScalarPath) {
    for (int rows : {1, 3, 4, 5, 8, 9, 16, 17, 31, 33, 40}) {
        Scene s = ml_scene(23, 17);
        s.volume().transfer.opacity.clear();
        s.volume().transfer.color.clear();
        for (int r = 0; r < rows; ++r) {
            // irregular abscissae over [0, 1]; values that change from row to row
            const double x = rows == 1 ? 0.5 : (r + 0.3 * std::sin(1.7 * r) * (r > 0 && r < rows - 1)) / (rows - 1);
            s.volume().transfer.opacity.push_back({x, 0.45 + 0.4 * std::sin(2.3 * r + 0.5)});
            s.volume().transfer.color.push_back({x, 0.5 + 0.4 * std::cos(1.1 * r), 0.5 + 0.4 * std::sin(0.7 * r), 0.3 + 0.02 * r});
        }
        SCOPED_TRACE(rows);
        EXPECT_LT(max_difference(s), 1e-13);
        expect_identical_across_instruction_sets(s);
        // The fast profile's float lanes on every instruction set against the reference (scalar),
        // within its bound (conventions 9b: termination at 2^-10 times colours <= 1, plus float
        // rounding); a wrong row would be about 0.1 off.
        const Image reference = render_scene(s, {.threads = 1, .simd = false});
        s.render.profile = ProfileId::Fast;
        for (std::int64_t target : {HWY_AVX3, HWY_AVX2, HWY_SSE4}) {
            if ((hwy::SupportedTargets() & target) == 0) continue;
            hwy::SetSupportedTargetsForTest(target);
            const Image fast = render_scene(s, {.threads = 1, .simd = true});
            hwy::SetSupportedTargetsForTest(0);
            double diff = 0.0;
            for (std::size_t i = 0; i < fast.pixels.size(); ++i) diff = std::max(diff, std::fabs(fast.pixels[i] - reference.pixels[i]));
            EXPECT_LT(diff, std::ldexp(1.0, -10) + 2e-5) << hwy::TargetName(target);
        }
    }
}

TEST(Simd, BitwiseIdenticalAcrossInstructionSets) {
    expect_identical_across_instruction_sets(ml_scene(29, 17));
    expect_identical_across_instruction_sets(shaded_ml_scene());
}

namespace {
void expect_identical_across_instruction_sets(const Scene& s) {
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
}  // namespace

// mip and minip: only reconstruction and comparisons are vectorised, so the packet path is
// bitwise the scalar one.
TEST(Simd, MipAndMinipAreBitwiseTheScalarPath) {
    for (auto proj : {Projection::Mip, Projection::Minip}) {
        Scene s = ml_scene(37, 23);
        s.render.projection = proj;
        s.render.step = 0.37;
        s.volume().transfer.opacity = {{0.0, 0.2}, {0.5, 0.1}, {1.0, 0.9}};
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

namespace {

// True when the scene's composite integrator takes the SIMD packet path.
bool takes_packet_path(const Scene& s) {
    const PreparedScene prepared(s, {.threads = 1});
    const auto* composite = dynamic_cast<const CompositeIntegrator*>(&prepared.integrator());
    return composite && composite->has_packet_path();
}

Scene shaded_ml_scene() {
    Scene s = ml_scene(37, 23);
    ShadingSpec shading;
    shading.ka = 0.2;
    shading.kd = 0.7;
    shading.ks = 0.3;
    shading.n = 10.0;
    s.volume().shading = shading;
    LightSpec directional;
    directional.type = LightSpec::Type::Directional;
    directional.direction = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    directional.color = {0.9, 0.6, 0.3};
    s.lights = {LightSpec{}, directional};
    return s;
}

// Max |a - b| over two images.
double image_difference(const Image& a, const Image& b) {
    double d = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) d = std::max(d, std::fabs(a.pixels[i] - b.pixels[i]));
    return d;
}

}  // namespace

// Shading, gradients (central, forward, cached) and gradient-magnitude opacity in the packet path:
// the scalar path's arithmetic except exp/expm1/log1p and s^n = exp(n log s) (PacketComposite.h).
TEST(Simd, ShadedCompositeMatchesTheScalarPath) {
    Scene s = shaded_ml_scene();
    ASSERT_TRUE(takes_packet_path(s));
    // Shading must matter, or the comparison below would prove nothing about it.
    Scene unshaded = s;
    unshaded.volume().shading.reset();
    EXPECT_GT(image_difference(render_scene(s, {.threads = 1}), render_scene(unshaded, {.threads = 1})), 0.05);
    EXPECT_LT(max_difference(s), 1e-13);

    Scene phong = s;  // Phong, two-sided, depth cue
    phong.volume().shading->model = ShadingSpec::Model::Phong;
    phong.volume().shading->two_sided = true;
    phong.volume().shading->kl = 0.05;
    ASSERT_TRUE(takes_packet_path(phong));
    EXPECT_LT(max_difference(phong), 1e-13);

    Scene nodal = s;
    nodal.volume().shading->model = ShadingSpec::Model::Nodal;
    nodal.render.step = 0.37;
    nodal.render.early_termination = 0.7;
    EXPECT_LT(max_difference(nodal), 1e-13);

    Scene forward = s;
    forward.volume().gradient.scheme = GradientSpec::Scheme::Forward;
    ASSERT_TRUE(takes_packet_path(forward));
    EXPECT_LT(max_difference(forward), 1e-13);

    Scene cached = s;
    cached.volume().gradient.cache = true;
    ASSERT_TRUE(takes_packet_path(cached));
    EXPECT_LT(max_difference(cached), 1e-13);
}

TEST(Simd, GradientOpacityMatchesTheScalarPath) {
    Scene s = ml_scene(37, 23);
    s.volume().transfer.gradient_opacity = {{0.0, 0.1}, {0.5, 0.6}, {2.0, 1.0}};
    ASSERT_TRUE(takes_packet_path(s));
    EXPECT_LT(max_difference(s), 1e-13);
    Scene shaded = shaded_ml_scene();
    shaded.volume().transfer.gradient_opacity = s.volume().transfer.gradient_opacity;
    shaded.volume().gradient.scheme = GradientSpec::Scheme::Forward;
    EXPECT_LT(max_difference(shaded), 1e-13);
    // With skipping on and off the packet path stays bitwise the same.
    const Image on = render_scene(shaded, {.threads = 1, .empty_space_skipping = true, .simd = true});
    const Image off = render_scene(shaded, {.threads = 1, .empty_space_skipping = false, .simd = true});
    EXPECT_EQ(std::memcmp(on.pixels.data(), off.pixels.data(), on.pixels.size() * sizeof(double)), 0);
}

// Paths the packet kernel does not serve keep the scalar path (and therefore equal it bitwise).
TEST(Simd, UnservedScenesTakeTheScalarPath) {
    Scene s = shaded_ml_scene();
    s.render.order = CompositeOrder::BackToFront;
    EXPECT_FALSE(takes_packet_path(s));
    s = shaded_ml_scene();
    s.volume().interpolation = Interpolation::TricubicBSpline;
    EXPECT_FALSE(takes_packet_path(s));
    s = shaded_ml_scene();
    s.lights.assign(9, LightSpec{});  // more than kMaxPacketLights
    EXPECT_FALSE(takes_packet_path(s));
}

// A call of several packets (a block of kMaxPacketRays rays) interleaves their steps (composite_all,
// two packets in flight): each ray's pixel is the one it gets in a call of its own, bit for bit, for
// both profiles, with early termination (packets that stop at different steps) and every count of rays
// up to kMaxPacketRays (a ragged last packet).
TEST(Simd, InterleavedPacketsGiveEachRayItsOwnPixel) {
    for (ProfileId profile : {ProfileId::Reference, ProfileId::Fast})
        for (bool early : {false, true}) {
            Scene s = ml_scene(37, 23);
            s.render.profile = profile;
            if (early) s.render.early_termination = 0.6;
            const PreparedScene prepared(s, {.threads = 1, .simd = true});
            ASSERT_TRUE(takes_packet_path(s));
            PreparedScene::Scratch scratch;
            int xs[kMaxPacketRays], ys[kMaxPacketRays];
            int opaque = 0;
            for (int count = 1; count <= kMaxPacketRays; ++count) {
                for (int i = 0; i < count; ++i) {  // a diagonal band of pixels through the volume
                    xs[i] = (7 + 3 * i + count) % 37;
                    ys[i] = (2 + i + count) % 23;
                }
                PixelValue together[kMaxPacketRays];
                prepared.pixels(xs, ys, count, together, true, scratch);
                for (int i = 0; i < count; ++i) {
                    PixelValue alone;
                    prepared.pixels(xs + i, ys + i, 1, &alone, true, scratch);
                    for (int c = 0; c < 4; ++c)
                        EXPECT_EQ(std::memcmp(&together[i].rgba[c], &alone.rgba[c], sizeof(double)), 0)
                            << "count " << count << " ray " << i << " channel " << c;
                    opaque += together[i].rgba.a > 0.5;
                }
            }
            EXPECT_GT(opaque, 50);  // rays that composite, not an empty band
        }
}

// A lane whose ray has one interval of at most ForwardSegmentWalk::kMaxRun segments takes its one run
// from the packet's constructor (no walk built: RayPacketT, skipping on the lanes); a longer chord,
// several intervals or a span take the walk's runs. Both kinds in one packet (chords of 1.3 to 18 units
// at 1.5e-4: 8.5k to 120k segments): the image is the same bit for bit as with skipping off (every lane
// walked) and within the transcendentals' last bits of the scalar path; a one-run lane asking its
// (unbuilt) walk for a second run crashes here.
TEST(Simd, OneRunLanesAndWalkedLanesPlaceTheSameSegments) {
    Scene s = ml_scene(9, 7);
    s.render.step = 0.0003;  // voxels: 1.5e-4 world units; kMaxRun = 65,536 segments are 9.8 units, the chords 1.3 to 18
    const PreparedScene prepared(s, {.threads = 1});
    const double h = 0.0003 * 0.5;  // times the smallest spacing
    int one_run = 0, several = 0;
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 9; ++x) {
            const std::vector<Interval> iv = prepared.intervals(prepared.pixel_ray(x, y));
            if (iv.size() != 1) continue;
            (segment_count(iv.front(), h) <= ForwardSegmentWalk::kMaxRun ? one_run : several) += 1;
        }
    ASSERT_GT(one_run, 0);
    ASSERT_GT(several, 0);
    for (ProfileId profile : {ProfileId::Reference, ProfileId::Fast}) {
        s.render.profile = profile;
        const Image on = render_scene(s, {.threads = 1, .empty_space_skipping = true, .simd = true});
        const Image off = render_scene(s, {.threads = 1, .empty_space_skipping = false, .simd = true});
        EXPECT_EQ(std::memcmp(on.pixels.data(), off.pixels.data(), on.pixels.size() * sizeof(double)), 0);
        if (profile == ProfileId::Reference) EXPECT_LT(max_difference(s), 1e-12);
    }
}

// PairFetch.h: f32 voxels' x-neighbour pairs read by 64-bit loads or by 64-bit gathers give the same image
// bit for bit, on the reference's double lanes and the fast profile's float lanes, on every instruction set
// Highway offers here (the gathers' byte offsets 4 idx and the halves' order are what this checks: a
// gather of the upper half's lanes into the lower half, or offsets in elements, changes the image).
TEST(Simd, VoxelPairsLoadedAndGatheredAreTheSame) {
    Scene s = ml_scene(23, 19);
    const Volume doubles = load_volume(s.volume());
    auto floats = std::make_shared<Volume>();
    floats->dims = doubles.dims;
    floats->origin = doubles.origin;
    floats->spacing = doubles.spacing;
    floats->type = ScalarType::F32;
    floats->values.allocate(ScalarType::F32, doubles.values.size());
    for (std::size_t i = 0; i < doubles.values.size(); ++i) floats->values.set(i, double(float(doubles.values[i])));
    s.volume().source.field.reset();
    s.volume().source.file = "ml-f32 (in memory)";
    s.volume().source.memory = floats;
    int compared = 0;
    for (ProfileId profile : {ProfileId::Reference, ProfileId::Fast}) {
        s.render.profile = profile;
        for (std::int64_t target : {HWY_AVX3, HWY_AVX2, HWY_SSE4}) {
            if ((hwy::SupportedTargets() & target) == 0) continue;
            hwy::SetSupportedTargetsForTest(target);
            set_pair_fetch(PairFetch::Loads);
            const Image loaded = render_scene(s, {.threads = 1, .simd = true});
            set_pair_fetch(PairFetch::Gathers);
            const Image gathered = render_scene(s, {.threads = 1, .simd = true});
            set_pair_fetch(PairFetch::Auto);
            hwy::SetSupportedTargetsForTest(0);
            EXPECT_EQ(std::memcmp(loaded.pixels.data(), gathered.pixels.data(), loaded.pixels.size() * sizeof(double)), 0)
                << hwy::TargetName(target);
            ++compared;
        }
        // Not a blank image, and the reference's still the scalar path's (to 1e-12, as above).
        const Image im = render_scene(s, {.threads = 1, .simd = true});
        double max_alpha = 0.0;
        for (std::size_t i = 3; i < im.pixels.size(); i += 4) max_alpha = std::max(max_alpha, im.pixels[i]);
        EXPECT_GT(max_alpha, 0.05);
        if (profile == ProfileId::Reference) EXPECT_LT(max_difference(s), 1e-12);
    }
    EXPECT_GE(compared, 4);
}

// The fast profile's log1p and expm1 (core/SimdLanes-inl.h: one polynomial each after a range
// reduction, no division) against the C library in double, on every instruction set: within 2 ulp of
// float over their domains (log1p: -1 <= x <= 1, every 61st float of it; expm1: -87 <= x <= 88, every
// 61st float), -1 below -87, and the special values.
namespace {
// |got - want| in units of the float ulp at want (want rounded to float; 2^-149 at 0).
double ulps(float got, double want) {
    const float w = float(std::fabs(want));
    const double ulp = double(std::nextafter(w, std::numeric_limits<float>::infinity())) - double(w);
    return std::fabs(double(got) - want) / (ulp > 0.0 ? ulp : std::ldexp(1.0, -149));
}
std::vector<float> floats_between(float lo, float hi, std::uint32_t stride) {
    // every stride-th float of [lo, hi] by bit pattern (both signs), and the ends
    std::vector<float> xs{lo, hi};
    auto walk = [&](float a, float b) {  // 0 <= a <= b
        std::uint32_t ia, ib;
        std::memcpy(&ia, &a, 4);
        std::memcpy(&ib, &b, 4);
        for (std::uint64_t i = ia; i <= ib; i += stride) {
            const std::uint32_t bits = std::uint32_t(i);
            float f;
            std::memcpy(&f, &bits, 4);
            if (f >= lo && f <= hi) xs.push_back(f);
            if (-f >= lo && -f <= hi) xs.push_back(-f);
        }
    };
    walk(0.0f, std::max(std::fabs(lo), std::fabs(hi)));
    return xs;
}
}  // namespace

TEST(Simd, FloatLog1pAndExpm1WithinTwoUlp) {
    const std::vector<float> lx = floats_between(-1.0f, 1.0f, 61), ex = floats_between(-87.0f, 88.0f, 61);
    std::vector<float> out(std::max(lx.size(), ex.size()));
    int targets = 0;
    for (std::int64_t target : {HWY_AVX3, HWY_AVX2, HWY_SSE4}) {
        if ((hwy::SupportedTargets() & target) == 0) continue;
        ++targets;
        SCOPED_TRACE(hwy::TargetName(target));
        hwy::SetSupportedTargetsForTest(target);
        double worst = 0.0;
        float_lanes_log1p(lx.data(), out.data(), lx.size());
        for (std::size_t i = 0; i < lx.size(); ++i) {
            if (lx[i] == -1.0f) {
                EXPECT_EQ(out[i], -std::numeric_limits<float>::infinity());
                continue;
            }
            const double u = ulps(out[i], std::log1p(double(lx[i])));
            worst = std::max(worst, u);
            ASSERT_LE(u, 2.0) << "log1p(" << lx[i] << ") = " << out[i];
        }
        RecordProperty(std::string("log1p_worst_ulp_") + hwy::TargetName(target), std::to_string(worst));
        worst = 0.0;
        float_lanes_expm1(ex.data(), out.data(), ex.size());
        for (std::size_t i = 0; i < ex.size(); ++i) {
            const double u = ulps(out[i], std::expm1(double(ex[i])));
            worst = std::max(worst, u);
            ASSERT_LE(u, 2.0) << "expm1(" << ex[i] << ") = " << out[i];
        }
        RecordProperty(std::string("expm1_worst_ulp_") + hwy::TargetName(target), std::to_string(worst));
        // Special values: -1 below the range, NaN through, zeros, the sign of tiny arguments.
        const float specials[] = {-88.0f, -1e30f, -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(),
                                  0.0f, -1e-30f, 1e-30f};
        float s_out[7];
        float_lanes_expm1(specials, s_out, 7);
        EXPECT_EQ(s_out[0], -1.0f);
        EXPECT_EQ(s_out[1], -1.0f);
        EXPECT_EQ(s_out[2], -1.0f);
        EXPECT_TRUE(std::isnan(s_out[3]));
        EXPECT_EQ(s_out[4], 0.0f);
        EXPECT_EQ(s_out[5], -1e-30f);
        EXPECT_EQ(s_out[6], 1e-30f);
        const float l_specials[] = {std::numeric_limits<float>::quiet_NaN(), 0.0f, -1e-30f, 1e-30f};
        float l_out[4];
        float_lanes_log1p(l_specials, l_out, 4);
        EXPECT_TRUE(std::isnan(l_out[0]));
        EXPECT_EQ(l_out[1], 0.0f);
        EXPECT_EQ(l_out[2], -1e-30f);
        EXPECT_EQ(l_out[3], 1e-30f);
        hwy::SetSupportedTargetsForTest(0);
    }
    EXPECT_GE(targets, 2);
}
