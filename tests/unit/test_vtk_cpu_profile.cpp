// The vtk-cpu profile (core/integrate/profiles/VtkFixedPointRenderer.h): vtkFixedPointVolumeRayCastMapper's 15-bit
// arithmetic checked against numbers worked out by hand in the comments (integer arithmetic, one
// unit = 1/32768), VTK's own clipping range (printed by python3-vtk9), and `volref trace` for every
// mirror profile (the last row is the rendered pixel, bit for bit). The images themselves are
// checked against VTK by the vtk_parity test (scripts/vtk-parity.sh).
#include <gtest/gtest.h>

#include <cmath>

#include "TestScenes.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/explain/PixelTrace.h"
#include "core/integrate/profiles/VtkFixedPointRenderer.h"
#include "core/render/PreparedScene.h"
#include "core/render/Renderer.h"
#include "transfer/Classifier.h"

using namespace volref;
using namespace volref::vtkcpu;

// ToFixedPointPosition: unsigned(v 32767 + 0.5). 1.5 -> 49150.5 + 0.5 = 49151 = 1 * 32768 + 16383:
// voxel 1, fraction 16383. 23 -> 753641.5 -> 753641 = 22 * 32768 + 32745: the scale is 32767 while
// the voxel index is pos >> 15 (/ 32768), so x = 23 lands in voxel 22 at fraction 32745 / 32768.
TEST(VtkCpuProfile, FixedPointPositions) {
    EXPECT_EQ(fixed_position(1.5f), 49151u);
    EXPECT_EQ(fixed_position(1.5f) >> kShift, 1u);
    EXPECT_EQ(fixed_position(1.5f) & kMask, 16383u);
    EXPECT_EQ(fixed_position(23.0f), 753641u);
    EXPECT_EQ(fixed_position(23.0f) >> kShift, 22u);
    EXPECT_EQ(fixed_position(23.0f) & kMask, 32745u);
    // Directions: the magnitude likewise, bit 31 set for positive ones; 0.25 -> 8191.75 + 0.5 -> 8192.
    EXPECT_EQ(fixed_direction(0.25f), 0x80000000u + 8192u);
    EXPECT_EQ(fixed_direction(-0.25f), 8192u);
    unsigned pos[3] = {100000u, 100000u, 100000u};
    const unsigned dir[3] = {fixed_direction(0.25f), fixed_direction(-0.25f), fixed_direction(0.0f)};
    fixed_increment(pos, dir);
    EXPECT_EQ(pos[0], 108192u);
    EXPECT_EQ(pos[1], 91808u);
    EXPECT_EQ(pos[2], 100000u);
}

// Weights at fractions (w2X, w2Y, w2Z) = (16383, 0, 0): w1X = 32767 - 16383 = 16384, w1Y = w1Z = 32767.
//   w1Xw1Y = (16384 + 16384 * 32767) >> 15 = 536870912 >> 15 = 16384
//   w2Xw1Y = (16384 + 16383 * 32767) >> 15 = 536838145 >> 15 = 16383 (16383 * 32768 = 536838144)
//   w1Xw2Y = w2Xw2Y = (16384 + 0) >> 15 = 0
//   A = (16384 + 16384 * 32767) >> 15 = 16384, B = (16384 + 16383 * 32767) >> 15 = 16383, the rest 0.
// Interpolating A = 1000, B = 3000: (32767 + 1000 * 16384 + 3000 * 16383) >> 15
//   = 65565767 >> 15 = 2000 (2000 * 32768 = 65536000, remainder 29767).
TEST(VtkCpuProfile, TrilinearWeightsByHand) {
    const unsigned pos[3] = {5u * 32768u + 16383u, 7u * 32768u, 2u * 32768u};
    const auto w = trilinear_weights(pos);
    const std::array<unsigned, 8> expected = {16384, 16383, 0, 0, 0, 0, 0, 0};
    EXPECT_EQ(w, expected);
    EXPECT_EQ(interpolate({1000, 3000, 7, 7, 7, 7, 7, 7}, w), 2000u);
}

// On a grid point (all fractions 0) the weights do not sum to 1: w1 = 32767,
//   w1Xw1Y = (16384 + 32767^2) >> 15 = 1073692673 >> 15 = 32766 (remainder 16385),
//   A = (16384 + 32766 * 32767) >> 15 = 1073659906 >> 15 = 32765 (remainder 16386);
// so a corner value of 32767 reads (32767 + 32767 * 32765) >> 15 = 1073643522 >> 15 = 32765.
TEST(VtkCpuProfile, GridPointReadsLowByTwoUnits) {
    const unsigned pos[3] = {3u * 32768u, 3u * 32768u, 3u * 32768u};
    const auto w = trilinear_weights(pos);
    EXPECT_EQ(w[0], 32765u);
    for (int i = 1; i < 8; ++i) EXPECT_EQ(w[std::size_t(i)], 0u) << i;
    EXPECT_EQ(interpolate({32767, 0, 0, 0, 0, 0, 0, 0}, w), 32765u);
}

// LookupColorUS with colour entry 16384 (0.5) and opacity entry 8192 (0.25):
//   c = (16384 * 8192 + 32767) >> 15 = 134250495 >> 15 = 4096 (4096 * 32768 = 134217728).
// A transparent entry gives a = 0 (the caller skips the sample).
TEST(VtkCpuProfile, TableLookupByHand) {
    const unsigned short color[6] = {16384, 16384, 32767, 0, 0, 0};
    const unsigned short opacity[2] = {8192, 0};
    const Sample15 s = lookup(color, opacity, 0);
    EXPECT_EQ(s.rgb[0], 4096);
    EXPECT_EQ(s.rgb[1], 4096);
    EXPECT_EQ(s.rgb[2], 8192);  // (32767 * 8192 + 32767) >> 15 = 268460031 >> 15 = 8192 (8192 * 32768 = 268435456)
    EXPECT_EQ(s.a, 8192);
    EXPECT_EQ(lookup(color, opacity, 1).a, 0);
}

// One compositing step from an empty ray (remaining 32767) with s = (4096, 4096, 8192; a 8192):
//   C_r += (4096 * 32767 + 32767) >> 15 = 134246399 >> 15 = 4096
//   C_b += (8192 * 32767 + 32767) >> 15 = 268460031 >> 15 = 8192
//   R = (32767 * (32767 - 8192) + 32767) >> 15 = 805281792 >> 15 = 24575 (24575 * 32768 = 805273600)
// A second identical step: C_r += (4096 * 24575 + 32767) >> 15 = 100691967 >> 15 = 3072,
//   R = (24575 * 24575 + 32767) >> 15 = 603963392 >> 15 = 18431.
TEST(VtkCpuProfile, CompositeStepByHand) {
    unsigned color[3] = {0, 0, 0};
    unsigned short remaining = 0x7fff;
    Sample15 s;
    s.rgb[0] = 4096;
    s.rgb[1] = 4096;
    s.rgb[2] = 8192;
    s.a = 8192;
    EXPECT_FALSE(composite(color, remaining, s));
    EXPECT_EQ(color[0], 4096u);
    EXPECT_EQ(color[2], 8192u);
    EXPECT_EQ(remaining, 24575);
    EXPECT_FALSE(composite(color, remaining, s));
    EXPECT_EQ(color[0], 4096u + 3072u);
    EXPECT_EQ(remaining, 18431);
}

// Termination: the ray stops once the remaining transparency is below 0xff = 255 (alpha above
// 1 - 255 / 32767 = 0.99222). With a = 16384: from R = 600, (600 * 16383 + 32767) >> 15 =
// 9862567 >> 15 = 300 >= 255, go on; from R = 300, (300 * 16383 + 32767) >> 15 = 4947667 >> 15 = 150
// < 255, stop.
TEST(VtkCpuProfile, TerminationByHand) {
    unsigned color[3] = {0, 0, 0};
    Sample15 s;
    s.a = 16384;
    unsigned short remaining = 600;
    EXPECT_FALSE(composite(color, remaining, s));
    EXPECT_EQ(remaining, 300);
    EXPECT_TRUE(composite(color, remaining, s));
    EXPECT_EQ(remaining, 150);
}

// vtkSphericalDirectionEncoder: low byte int(theta 255 / 359 + 0.5), high byte
// int((phi + 90) 254 / 180 + 0.5), code = low + 256 high; zero = 255 * 256.
//   (1, 0, 0): theta 0, phi 0 -> high int(127.5) = 127 -> 32512; decoded phi = -89.5 + 127 179 / 254 = 0.
//   (0, 0, 1): x = 0 and y <= 0 -> theta 270 -> low int(191.78 + 0.5) = 192; phi 90 -> high 254 -> 65216.
//   (0, 1, 0): theta 90 -> low int(63.93 + 0.5) = 64; high 127 -> 32576.
TEST(VtkCpuProfile, DirectionEncodingByHand) {
    const float x[3] = {1, 0, 0}, z[3] = {0, 0, 1}, y[3] = {0, 1, 0}, zero[3] = {0, 0, 0};
    EXPECT_EQ(encode_direction(x), 32512u);
    EXPECT_EQ(encode_direction(z), 65216u);
    EXPECT_EQ(encode_direction(y), 32576u);
    EXPECT_EQ(encode_direction(zero), 65280u);
    const glm::vec3 d = decode_direction(32512u);
    EXPECT_NEAR(d.x, 1.0, 1e-6);
    EXPECT_NEAR(d.y, 0.0, 1e-6);
    EXPECT_NEAR(d.z, 0.0, 1e-6);
    EXPECT_EQ(decode_direction(65280u), glm::vec3(0.0f));
}

// VTK's own numbers: python3-vtk9, vtkRenderer::ResetCameraClippingRange for the box
// [-11.5, 11.5]^3 seen from (29, 17, 63) towards 0 at 30 degrees printed (35.760288154171604,
// 116.45174279158363) (the parity test's camera).
TEST(VtkCpuProfile, ClippingRangeIsVtks) {
    const glm::dvec3 eye(29, 17, 63);
    const auto r = clipping_range(eye, -glm::normalize(eye), 30.0, glm::dvec3(-11.5), glm::dvec3(11.5));
    EXPECT_NEAR(r[0], 35.760288154171604, 1e-9);
    EXPECT_NEAR(r[1], 116.45174279158363, 1e-9);
}

namespace {

// A Gaussian blob in a 17^3 float-valued grid seen in perspective, 12 x 12 pixels.
Scene blob(ProfileId profile, Projection projection, bool shaded) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Gaussian;
    f.dims = {17, 17, 17};
    f.center = {8.0, 8.0, 8.0};
    f.sigma = 3.5;
    Scene s = test::field_scene(f);
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.2, 0.0}, {1.0, 0.5}};
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {1.0, 1.0, 0.8, 0.2}};
    s.volume().transfer.opacity_unit_distance = 1.0;
    if (projection == Projection::Mip || projection == Projection::Minip)
        s.volume().transfer.opacity = {{0.0, 0.2}, {1.0, 1.0}};  // minip sees the faint outside too
    if (shaded) {
        s.volume().shading = ShadingSpec{};
        s.volume().shading->two_sided = true;
    }
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {30.0, 20.0, 40.0};
    s.camera.target = {8.0, 8.0, 8.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.fov_y = 30.0;
    s.image.width = s.image.height = 12;
    s.render.projection = projection;
    s.render.step = 0.5;
    s.render.profile = profile;
    return s;
}

}  // namespace

// The tables of a scene by hand: data range [min, max] of the blob, opacity 0.5 everywhere, unit
// distance 1, step 0.5 voxel: every composite entry is 1 - (1 - 0.5)^0.5 = 0.29289 -> 0.29289 * 32767
// + 0.5 = 9597.73 -> 9597; for mip the uncorrected 0.5 -> 16383.5 + 0.5 -> 16384. Colour 0.5 -> 16384.
TEST(VtkCpuProfile, OpacityTableCorrectedForTheStepByHand) {
    Scene s = blob(ProfileId::VtkCpu, Projection::Composite, false);
    s.volume().transfer.opacity = {{0.0, 0.5}, {1.0, 0.5}};
    s.volume().transfer.color = {{0.0, 0.5, 0.5, 0.5}, {1.0, 0.5, 0.5, 0.5}};
    const Volume v = load_volume(s.volume());
    const std::unique_ptr<Classifier> k = make_classifier(s.volume(), v);
    const vtkcpu::VtkFixedPointRenderer c(v, *k, nullptr, Projection::Composite, 0.5, s.camera, s.image, Interpolation::Trilinear);
    EXPECT_EQ(c.opacity_table().size(), 32768u);
    EXPECT_EQ(c.opacity_table().front(), 9597);
    EXPECT_EQ(c.opacity_table().back(), 9597);
    EXPECT_EQ(c.color_table()[0], 16384);
    const vtkcpu::VtkFixedPointRenderer m(v, *k, nullptr, Projection::Mip, 0.5, s.camera, s.image,
                           Interpolation::Trilinear);
    EXPECT_EQ(m.opacity_table()[100], 16384);
}

// The fixed-point mapper renders neither average, x-ray nor isosurfaces (VTK 9.1): one-line errors.
TEST(VtkCpuProfile, AverageXrayAndIsosurfacesAreErrors) {
    for (Projection pr : {Projection::Average, Projection::Xray}) {
        try {
            render_scene(blob(ProfileId::VtkCpu, pr, false), {1, false});
            ADD_FAILURE() << "no error";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("render.profile: \"vtk-cpu\""), std::string::npos) << m;
            EXPECT_NE(m.find("render.projection"), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    }
    // Isosurfaces (first-hit) neither.
    Scene iso = blob(ProfileId::VtkCpu, Projection::FirstHit, false);
    iso.render.isovalue = 0.5;
    try {
        render_scene(iso, {1, false});
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("render.profile: \"vtk-cpu\" does not render the first-hit projection"), std::string::npos) << m;
    }
    Scene ortho = blob(ProfileId::VtkCpu, Projection::Composite, false);
    ortho.camera.type = CameraSpec::Type::Orthographic;
    EXPECT_THROW(render_scene(ortho, {1, false}), Error);
}

// `volref trace` for every mirror profile: the last row is the pixel the renderer writes, bit for
// bit, and the trace has samples (the pixel sees the blob).
TEST(VtkCpuProfile, TraceLastRowIsTheRenderedPixelForEveryProfile) {
    struct Case {
        ProfileId profile;
        Projection projection;
        bool shaded;
    };
    const Case cases[] = {
        {ProfileId::VtkGpu, Projection::Composite, true},    {ProfileId::VtkGpu, Projection::Mip, false},
        {ProfileId::VtkCpu, Projection::Composite, false},   {ProfileId::VtkCpu, Projection::Composite, true},
        {ProfileId::VtkCpu, Projection::Mip, false},         {ProfileId::VtkCpu, Projection::Minip, false},
        {ProfileId::GlslBasic, Projection::Composite, true}, {ProfileId::Ospray, Projection::Composite, true},
        {ProfileId::CudaCurvilinear, Projection::Composite, false}, {ProfileId::CudaCurvilinear, Projection::Xray, false},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(::testing::Message() << "profile " << int(c.profile) << " projection " << int(c.projection)
                                          << " shaded " << c.shaded);
        const Scene s = blob(c.profile, c.projection, c.shaded);
        const Image image = render_scene(s, {1, false});
        const PreparedScene p(s, {1, false});
        for (const auto& [x, y] : {std::pair{6, 6}, std::pair{4, 7}}) {
            const explain::PixelTrace t = explain::trace_pixel(p, x, y);
            ASSERT_GE(t.samples.size(), 2u);
            const glm::dvec4 last = t.samples.back().record.accumulated;
            const glm::dvec4 rendered = test::rgba(image, x, y);
            for (int ch = 0; ch < 4; ++ch) EXPECT_EQ(last[ch], rendered[ch]) << "channel " << ch;
            EXPECT_GT(rendered.a, 0.0);
        }
    }
}

// The per-voxel tables are checked against the memory limit before they are allocated: 17^3 voxels
// shaded need 17^3 (4 + 4 + 2 + 8) = 88434 bytes = 86.4 KiB, more than a limit of 50000 bytes.
TEST(VtkCpuProfile, TablesRespectTheMemoryLimit) {
    const std::size_t saved = memory_limit();
    set_memory_limit(50000);
    std::string message;
    try {
        const PreparedScene p(blob(ProfileId::VtkCpu, Projection::Composite, true), {1, false});
    } catch (const Error& e) {
        message = e.what();
    }
    set_memory_limit(saved);
    EXPECT_NE(message.find("\"vtk-cpu\" voxel tables: needs 86.4 KiB"), std::string::npos) << message;
}
