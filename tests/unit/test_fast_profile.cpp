// The fast profile (render.profile "fast", core/integrate/packet/FastProfile.h): the reference's scene and
// formulas on float SIMD lanes, with early termination at kFastTransmittanceCutoff. Checked against
// the reference render (a second method, double precision throughout) and against a closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "TestScenes.h"
#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/explain/PixelTrace.h"
#include "core/grid/ProceduralField.h"
#include "core/io/NrrdWriter.h"
#include "core/render/PreparedScene.h"
#include "core/render/Renderer.h"

using namespace volref;
using namespace volref::test;
namespace fs = std::filesystem;

namespace {

Scene ml_scene() {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {33, 29, 31};
    Scene s = field_scene(ml, glm::dvec3(-3.0, 1.0, 2.0), glm::dvec3(0.5, 0.7, 0.6));
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {0.4, 0.3, 0.5, 0.2}, {0.55, 1.0, 0.8, 0.3}, {1.0, 1.0, 0.9, 0.6}};
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.3, 0.0}, {0.5, 0.35}, {0.52, 0.35}, {0.8, 0.9}, {1.0, 1.0}};
    s.volume().transfer.opacity_unit_distance = 2.0;
    s.image.width = 31;
    s.image.height = 23;
    return s;
}

Image render_with(Scene s, ProfileId profile, bool simd = true, int threads = 1) {
    s.render.profile = profile;
    RenderOptions o;
    o.threads = threads;
    o.simd = simd;
    return render_scene(s, o);
}

// max |fast - reference| over every channel, and a check that the image is not empty.
double max_difference(const Scene& s) {
    const Image fast = render_with(s, ProfileId::Fast), ref = render_with(s, ProfileId::Reference);
    double diff = 0.0, max_alpha = 0.0;
    for (std::size_t i = 0; i < ref.pixels.size(); ++i) {
        diff = std::max(diff, std::fabs(fast.pixels[i] - ref.pixels[i]));
        if (i % 4 == 3) max_alpha = std::max(max_alpha, ref.pixels[i]);
    }
    EXPECT_GT(max_alpha, 0.05) << "blank image";
    std::printf("max |fast - reference| = %.3g\n", diff);
    return diff;
}

// What termination may leave out: Tr <= 2^-10 times colours <= 1 (premultiplied).
constexpr double kCutoff = conventions::kFastTransmittanceCutoff;

fs::path temp_dir() {
    const fs::path d = fs::temp_directory_path() / ("volref-fast-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

}  // namespace

// Unshaded composite, mip and minip on a procedural (f64) volume, which the fast profile reads from a
// float copy: within the termination bound plus float rounding of the reference.
TEST(FastProfile, MatchesTheReferenceUnshaded) {
    Scene s = ml_scene();
    EXPECT_LT(max_difference(s), kCutoff + 2e-5);
    s.volume().transfer.domain = TransferSpec::Domain::Normalized;
    EXPECT_LT(max_difference(s), kCutoff + 2e-5);
    s.render.early_termination = 0.9;  // the scene's own termination applies as well
    EXPECT_LT(max_difference(s), 2e-5);
    s.render.early_termination.reset();
    s.volume().transfer.opacity = {{0.0, 0.3}, {1.0, 1.0}};  // the minimum (near 0) is visible too
    for (Projection p : {Projection::Mip, Projection::Minip}) {
        s.render.projection = p;
        // The extremum is found in float and classified in double at its t: a float-rounded position.
        EXPECT_LT(max_difference(s), 2e-5) << (p == Projection::Mip ? "mip" : "minip");
    }
}

// Shaded (central, forward and cached gradients; Blinn-Phong and Phong under two lights) and gradient
// opacity: float differences and normals. Shaded colours exceed 1 (two white lights: up to
// 2 (ka + kd + ks) = 2.4), so termination may leave out up to 2.4 x 2^-10.
TEST(FastProfile, MatchesTheReferenceShaded) {
    Scene s = ml_scene();
    s.volume().shading = ShadingSpec{};
    s.volume().shading->ks = 0.4;
    s.volume().shading->n = 12;
    s.lights = {LightSpec{}, LightSpec{}};
    s.lights[1].type = LightSpec::Type::Directional;
    s.lights[1].direction = glm::normalize(glm::dvec3(1, 2, 3));
    const double bound = 2.0 * (0.1 + 0.7 + 0.4) * kCutoff + 1e-4;
    for (auto scheme : {GradientSpec::Scheme::Central, GradientSpec::Scheme::Forward})
        for (bool cache : {false, true}) {
            s.volume().gradient.scheme = scheme;
            s.volume().gradient.cache = cache;
            EXPECT_LT(max_difference(s), bound) << "scheme " << int(scheme) << " cache " << cache;
        }
    s.volume().shading->model = ShadingSpec::Model::Phong;
    EXPECT_LT(max_difference(s), bound) << "phong";
    s.volume().shading.reset();
    s.volume().transfer.gradient_opacity = {{0.0, 0.0}, {0.5, 1.0}};
    EXPECT_LT(max_difference(s), kCutoff + 1e-4) << "gradient opacity";
}

// The voxel types the float kernel gathers itself (f32 and u16 NRRD files) give the same image as a
// float copy of them would: compared with the reference of the same file.
TEST(FastProfile, StorageTypes) {
    const fs::path dir = temp_dir();
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {21, 19, 23};
    const Volume v = make_procedural_volume(ml, glm::dvec3(0.0), glm::dvec3(1.0));
    NrrdWriteOptions o;
    o.type = ScalarType::F32;
    write_nrrd(v, dir / "ml32.nrrd", o);
    {  // u16: round(60000 v), written by hand
        std::ofstream f(dir / "ml16.nrrd", std::ios::binary);
        f << "NRRD0004\ntype: unsigned short\ndimension: 3\nsizes: 21 19 23\nendian: little\nencoding: raw\n\n";
        for (std::size_t i = 0; i < v.values.size(); ++i) {
            const std::uint16_t x = std::uint16_t(std::lround(60000.0 * v.values[i]));
            f.write(reinterpret_cast<const char*>(&x), 2);
        }
    }
    for (const char* file : {"ml32.nrrd", "ml16.nrrd"}) {
        Scene s;
        s.volume().source.file = dir / file;
        s.volume().transfer.domain = TransferSpec::Domain::Normalized;
        s.volume().transfer.opacity = {{0.0, 0.0}, {0.45, 0.0}, {0.5, 0.6}, {0.6, 0.1}, {1.0, 0.0}};
        s.image.width = s.image.height = 24;
        EXPECT_LT(max_difference(s), kCutoff + 2e-5) << file;
        s.render.projection = Projection::Mip;
        EXPECT_LT(max_difference(s), 2e-5) << file;
    }
    fs::remove_all(dir);
}

// A constant medium of opacity a per unit along a chord of length L = 40 at step h: the reference's
// alpha is 1 - (1 - a)^L; the fast profile stops after the first segment k where the transmittance
// (1 - a)^(k h) <= 2^-10, so its alpha is 1 - (1 - a)^(k h) for that k (float rounding aside).
TEST(FastProfile, TerminatesAtTheCutoffClosedForm) {
    for (const double a : {0.05, 0.2, 0.6})
        for (const double h : {0.5, 1.0, 0.7}) {
            Scene s = field_scene(constant_field(1.0, {5, 5, 41}));
            s.volume().transfer.opacity = {{0.0, a}};
            s.camera = ortho_down_z(2.0, 2.0, 100.0, 4.0);
            s.image.width = s.image.height = 4;
            s.render.step = h;
            s.render.step_units = StepUnits::World;
            const Image fast = render_with(s, ProfileId::Fast), ref = render_with(s, ProfileId::Reference);
            const double L = 40.0;
            const std::int64_t n = std::int64_t(std::ceil(L / h - 1e-9));
            std::int64_t k = 1;
            while (k < n && std::pow(1.0 - a, double(k) * h) > kCutoff) ++k;
            const double length = std::min(double(k) * h, L);
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x) {
                    EXPECT_NEAR(ref.at(x, y, 3), 1.0 - std::pow(1.0 - a, L), 1e-12);
                    EXPECT_NEAR(fast.at(x, y, 3), 1.0 - std::pow(1.0 - a, length), 2e-6) << "a " << a << " h " << h;
                    EXPECT_LE(std::fabs(fast.at(x, y, 3) - ref.at(x, y, 3)), kCutoff + 2e-6);
                }
        }
}

// The float lanes place the reference's segments (conventions 9b): on f = z seen from above (the ray
// enters at z = 4 and leaves at z = 0, 4 world units), MIP reads the first midpoint, z = 4 - h / 2, and
// MinIP the last, z = r / 2 with r = 4 - (n - 1) h the interval's short last segment (its end is the
// exit, not t0 + n h); alpha = v / 4. Steps 0.75 (r = h / 3), 0.9 (r = 0.44 h) and 4 / 70000.5 (70,001
// segments, r = h / 2: two of the walk's runs of at most 65,536, placed from the same block start).
// Placing the last segment a whole step long would move MinIP's alpha by (h - r) / 8 (3.6e-6 at the
// finest step); the float bound: a few ulp of t <= 4 (4.8e-7 each) in z, a quarter of that in alpha.
TEST(FastProfile, PlacesTheReferenceSegmentsInFloat) {
    for (const double h : {0.75, 0.9, 4.0 / 70000.5}) {
        const std::int64_t n = std::int64_t(std::ceil(4.0 / h - 1e-9));
        const double r = 4.0 - double(n - 1) * h;
        for (const Projection p : {Projection::Mip, Projection::Minip}) {
            Scene s = ramp_scene(ProfileId::Fast, p, h);
            const glm::dvec4 fast = rgba(render_scene(s, {1, false}), 0, 0);
            s.render.profile = ProfileId::Reference;
            const glm::dvec4 ref = rgba(render_scene(s, {1, false}), 0, 0);
            const double z = p == Projection::Mip ? 4.0 - h / 2.0 : r / 2.0;
            EXPECT_NEAR(ref.a, z / 4.0, 1e-12) << "h " << h;
            EXPECT_NEAR(fast.a, z / 4.0, 1e-6) << "h " << h << " n " << n << " r " << r;
        }
    }
}

// The same closed form past the float lanes' first blocks (conventions 9b: a lane's segments are placed
// from the start of their block of 2^23, b_0 = float(t0 + k_b h - t_ref), then b_0 + (k - k_b) h): at
// h = 4 / 17000000.5 the interval has n = 17,000,001 segments, so its last (r = h / 2) lies in the third
// block, past 2^24, where a float k would no longer be exact. MinIP reads that last midpoint, z = r / 2;
// a block start misplaced by a block (2^23 h = 1.97) would move alpha by 0.49 (a last segment placed a
// whole step long only by (h - r) / 8 = h / 16, below the float bound: the other test checks that).
TEST(FastProfile, PlacesSegmentsPastTheFirstFloatBlocks) {
    const double h = 4.0 / 17000000.5;
    const std::int64_t n = std::int64_t(std::ceil(4.0 / h - 1e-9));
    ASSERT_GT(n, std::int64_t(1) << 24);
    const double z = (4.0 - double(n - 1) * h) / 2.0;
    for (const ProfileId profile : {ProfileId::Fast, ProfileId::Reference}) {
        const glm::dvec4 c = rgba(render_scene(ramp_scene(profile, Projection::Minip, h), {1, false}), 0, 0);
        EXPECT_NEAR(c.a, z / 4.0, profile == ProfileId::Fast ? 1e-6 : 1e-12) << "n " << n;
    }
}

// Every pixel goes through the packets: the image does not depend on RenderOptions::simd, the thread
// count or empty-space skipping.
TEST(FastProfile, SameImageForAnySimdOptionThreadsAndSkipping) {
    Scene s = ml_scene();
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.45, 0.0}, {0.5, 0.6}, {0.55, 0.0}};  // empty space to skip
    for (Projection p : {Projection::Composite, Projection::Mip}) {
        s.render.projection = p;
        const Image a = render_with(s, ProfileId::Fast, true, 1), b = render_with(s, ProfileId::Fast, false, 2);
        s.render.profile = ProfileId::Fast;
        const Image c = render_scene(s, {.threads = 2, .empty_space_skipping = false});
        s.render.profile = ProfileId::Reference;
        EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(double)), 0);
        EXPECT_EQ(std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(double)), 0);
    }
}

// Skipping on the lanes (PacketKernels-inl.h, VectorSkip; float and double) passes over samples in empty boxes
// only: the image is the image without skipping, bit for bit, at steps shorter and longer than a
// macrocell, with an origin and spacings that are not 1, a clip plane that cuts rays into two
// intervals, and bounds larger than the grid (samples beyond it clamp into its boundary cells).
TEST(FastProfile, VectorSkipIsExact) {
    auto expect_exact = [](const Scene& scene, const std::string& label) {
        Scene s = scene;
        for (double step : {0.3, 1.0, 2.5, 7.0, 19.0}) {
            s.render.step = step;
            const Image a = render_scene(s, {.threads = 1}), b = render_scene(s, {.threads = 2, .empty_space_skipping = false});
            double alpha = 0.0;
            for (std::size_t i = 3; i < a.pixels.size(); i += 4) alpha = std::max(alpha, a.pixels[i]);
            if (step < 10.0) {
                EXPECT_GT(alpha, 0.05) << "blank image: " << label << ", step " << step;
            }
            EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(double)), 0)
                << label << ", step " << step;
        }
    };
    for (ProfileId profile : {ProfileId::Fast, ProfileId::Reference}) {  // float lanes; double lanes (world coordinates)
        SCOPED_TRACE(profile == ProfileId::Fast ? "fast" : "reference");
        Scene s = ml_scene();
        s.volume().transfer.opacity = {{0.0, 0.0}, {0.46, 0.0}, {0.5, 0.7}, {0.54, 0.0}};
        s.render.profile = profile;
        s.render.step_units = StepUnits::Voxel;
        expect_exact(s, "marschner-lobb");
        s.volume().clip_planes = {ClipPlaneSpec{glm::dvec3(5.0, 12.0, 10.0), glm::dvec3(0.3, -1.0, 0.2)}};
        expect_exact(s, "clip plane");
        s.volume().clip_planes.clear();
        s.volume().bounds.type = BoundsSpec::Type::Box;
        s.volume().bounds.min = glm::dvec3(-6.0, -1.0, 0.0);
        s.volume().bounds.max = glm::dvec3(16.0, 22.0, 22.0);
        expect_exact(s, "bounds beyond the grid");
        // A thin shell (a Gaussian's f = 0.5) in a volume mostly empty, far from the world origin: the
        // lanes skip most of each ray, so a box misplaced by a cell would change the image.
        FieldSpec g;
        g.kind = FieldSpec::Kind::Gaussian;
        g.dims = {48, 41, 45};
        const glm::dvec3 origin(-300.0, 120.0, 75.0), spacing(0.5, 0.7, 0.6);
        g.center = origin + spacing * glm::dvec3(22.0, 21.0, 23.0);
        g.sigma = 6.0;
        Scene shell = field_scene(g, origin, spacing);
        shell.volume().transfer = s.volume().transfer;
        shell.image = s.image;
        shell.render.profile = profile;
        shell.render.step_units = StepUnits::Voxel;
        expect_exact(shell, "gaussian shell");
    }
}

// Scenes the float packets do not take are one-line errors naming render.profile (no silent fallback).
TEST(FastProfile, UnservedScenesAreErrors) {
    auto message = [](Scene s) {
        s.render.profile = ProfileId::Fast;
        try {
            render_scene(s, {.threads = 1});
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    auto expect_error = [&](const Scene& s, const std::string& reason) {
        const std::string m = message(s);
        EXPECT_EQ(m.rfind("render.profile: \"fast\"", 0), 0u) << m;
        EXPECT_NE(m.find(reason), std::string::npos) << m;
    };
    Scene s = ml_scene();
    s.volume().interpolation = Interpolation::TricubicBSpline;
    expect_error(s, "not trilinear");
    s = ml_scene();
    s.render.order = CompositeOrder::BackToFront;
    expect_error(s, "back to front");
    s = ml_scene();
    s.volume().classify = VolumeSpec::Classify::Pre;
    expect_error(s, "pre-classified");
    s = ml_scene();
    s.render.projection = Projection::Average;
    expect_error(s, "projection");
    s = ml_scene();
    s.render.integrator = IntegrationMethod::Adaptive;
    expect_error(s, "adaptive");
    s = ml_scene();
    ClassificationSpec iso;
    iso.type = ClassificationSpec::Type::Isovalue;
    iso.isovalues = {{0.5, 0.8, 0.05, {1, 1, 1}}};
    s.volume().classification = iso;
    expect_error(s, "classified otherwise");
    s = ml_scene();
    s.volume().transform = glm::dmat4(1.0);
    EXPECT_NE(message(s).find("only render.profile \"reference\" (with no rules set over it) renders transformed volumes"), std::string::npos) << message(s);
    s = ml_scene();
    s.volumes.push_back(s.volumes.front());
    EXPECT_NE(message(s).find("only \"reference\" (with no rules set over it) renders several volumes"), std::string::npos) << message(s);
    // volref trace follows the reference's loops, which the fast profile does not have.
    s = ml_scene();
    s.render.profile = ProfileId::Fast;
    const PreparedScene prepared(s, RenderOptions{});
    EXPECT_THROW(explain::trace_pixel(prepared, 10, 10), Error);
}

// The float copy of f64 voxels is checked against the memory limit with the volume it copies: a
// 32^3 f64 field (256 KiB) renders under a 300 KiB limit with the reference, and the fast profile,
// which would add 128 KiB of floats, is refused before allocating them.
TEST(FastProfile, FloatCopyRespectsTheMemoryLimit) {
    Scene s = field_scene(constant_field(0.5, {32, 32, 32}));
    s.volume().transfer.opacity = {{0.0, 0.1}};
    s.image.width = s.image.height = 4;
    const std::size_t saved = memory_limit();
    set_memory_limit(300 << 10);
    std::string message;
    EXPECT_NO_THROW(render_with(s, ProfileId::Reference));
    try {
        render_with(s, ProfileId::Fast);
    } catch (const Error& e) {
        message = e.what();
    }
    set_memory_limit(saved);
    EXPECT_EQ(message.rfind("render.profile: the fast profile's float copy of the voxels: needs 384 KiB", 0), 0u) << message;
}

// Issue 18, case 4: a volume far from the world origin (5e5, and 1e6 with spacing 1e-3) keeps the
// fast profile within its bound: the float lanes work relative to the volume's origin and to each
// ray's entry (the default camera follows the volume). World float positions were 0.235 and 0.57 off.
TEST(FastProfile, FarFromTheOriginKeepsItsBound) {
    for (const auto& [offset, spacing] : {std::pair{glm::dvec3(5e5, -3e5, 4e5), 1.0}, std::pair{glm::dvec3(1e6), 1e-3}}) {
        Scene s = ml_scene();
        s.volume().origin = *s.volume().origin + offset;
        s.volume().spacing = *s.volume().spacing * spacing;
        s.volume().transfer.opacity_unit_distance *= spacing;
        EXPECT_LT(max_difference(s), kCutoff + 2e-5) << "composite at " << offset.x;
        s.volume().shading = ShadingSpec{};
        s.volume().shading->kl = 0.01 / spacing;  // depth cueing reads the world t
        EXPECT_LT(max_difference(s), 2.0 * kCutoff + 1e-4) << "shaded at " << offset.x;
        s.volume().shading.reset();
        s.volume().transfer.opacity = {{0.0, 0.3}, {1.0, 1.0}};
        for (Projection p : {Projection::Mip, Projection::Minip}) {
            s.render.projection = p;
            EXPECT_LT(max_difference(s), 2e-5) << "extremum at " << offset.x;
        }
    }
}
