// Numerical stability on hard cases (issue 6 item 5), fixed-step and adaptive integration, against
// closed forms computed here.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <OpenImageIO/imageio.h>

#include "TestScenes.h"
#include "core/io/NrrdWriter.h"
#include "core/render/PreparedScene.h"

namespace fs = std::filesystem;

using namespace volref;
using namespace volref::test;

namespace {

// A constant field of value 2 seen down z through a box [0, 4]^2 x [z0, z0 + L] (origin shifted by
// `origin`), one pixel; opacity a per l, colour (0.2, 0.6, 0.9).
Scene chord_scene(double a, double l, double L, double step, glm::dvec3 origin = glm::dvec3(0.0),
                  glm::dvec3 spacing = glm::dvec3(1.0)) {
    Scene s = field_scene(constant_field(2.0, {5, 5, 5}), origin, spacing);
    s.volume().bounds.min = origin + glm::dvec3(0.0, 0.0, 0.2);
    s.volume().bounds.max = origin + glm::dvec3(4.0 * spacing.x, 4.0 * spacing.y, 0.2 + L);
    s.volume().transfer.opacity = {{0.0, a}};
    s.volume().transfer.color = {{0.0, 0.2, 0.6, 0.9}};
    s.volume().transfer.opacity_unit_distance = l;
    s.camera = ortho_down_z(origin.x + 2.1 * spacing.x, origin.y + 1.3 * spacing.y, origin.z + 10.0 + L, 1e-3);
    s.image.width = s.image.height = 1;
    s.render.step = step;
    s.render.step_units = StepUnits::World;
    return s;
}

PixelValue pixel(const Scene& s) { return PreparedScene(s, {1, false}).render_pixel(0, 0); }

// Every channel of every pixel finite.
bool all_finite(const Image& im) {
    for (double v : im.pixels)
        if (!std::isfinite(v) && !std::isinf(v)) return false;  // Z may be +inf (a miss); NaN never
    return true;
}

}  // namespace

// Steps of 1e-4 voxel: 37000 segments along a chord of 3.7; the closed form 1 - (1 - a)^(L / l) holds
// to 1e-13 (the segments' opacities multiply exactly in the optical depth).
TEST(Stability, StepsOfATenThousandthVoxel) {
    const double a = 0.35, l = 1.0, L = 3.7;
    const PixelValue p = pixel(chord_scene(a, l, L, 1e-4));
    const double alpha = 1.0 - std::pow(1.0 - a, L / l);
    EXPECT_NEAR(p.rgba.a, alpha, 1e-13);
    EXPECT_NEAR(p.rgba.b, 0.9 * alpha, 1e-13);
}

// An opacity of 1e-9 per unit over a chord of 1 sampled by a million segments: tau = 1e-6 sums of
// 1e-15, compensated; alpha = -expm1(log1p(-1e-9)) to a relative 1e-12 (a product of (1 - alpha_k)
// would lose about 6 digits). Adaptive: the same to 1e-14 relative.
TEST(Stability, TinyOpacityOverAMillionSamples) {
    const double a = 1e-9, L = 1.0;
    const double alpha = -std::expm1((L / 1.0) * std::log1p(-a));
    Scene s = chord_scene(a, 1.0, L, 1e-6);
    const PixelValue p = pixel(s);
    EXPECT_NEAR(p.rgba.a / alpha, 1.0, 1e-12);
    // The colour is a plain sum of 1e6 positive terms: relative rounding at most 1e6 eps ~ 1.1e-10.
    EXPECT_NEAR(p.rgba.g / (0.6 * alpha), 1.0, 1.1e-10);
    s.render.integrator = IntegrationMethod::Adaptive;
    const PixelValue q = pixel(s);
    EXPECT_NEAR(q.rgba.a / alpha, 1.0, 1e-14);
    EXPECT_NEAR(q.rgba.g / (0.6 * alpha), 1.0, 1e-14);
}

// An opacity of 1 - 1e-12 (1 - a is exact in double): over L = 0.5 the transmittance is
// (1 - a)^0.5 ~ 1e-6; A = 1 - T with 1 - A = T to 1e-16 absolute, fixed (500 steps) and adaptive.
TEST(Stability, OpacityOneMinusTenToTheMinusTwelve) {
    const double a = 1.0 - 1e-12, L = 0.5;
    const double T = std::pow(1.0 - a, L);
    for (IntegrationMethod m : {IntegrationMethod::Fixed, IntegrationMethod::Adaptive}) {
        Scene s = chord_scene(a, 1.0, L, 1e-3);
        s.render.integrator = m;
        const PixelValue p = pixel(s);
        EXPECT_NEAR(1.0 - p.rgba.a, T, 2e-16);
        EXPECT_NEAR(p.rgba.r, 0.2 * (1.0 - T), 1e-15);
    }
}

// A transfer function with a jump (two rows at the same value 2, which is also a voxel value of f = z,
// i.e. on a cell face): f = z on [0, 4], opacity 0.1 below 2 and 0.6 from 2 on, colour red below and
// blue from 2 on. Down z from z = 4 (t = 6 at z = 4): blue over z in [2, 4], red over [0, 2]:
// A = 1 - 0.4^2 0.9^2, C = (1 - 0.4^2) blue + 0.4^2 (1 - 0.9^2) red. The fixed step converges to it
// with order 1 at most (a jump); adaptive is exact to rounding.
TEST(Stability, TransferFunctionJump) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {5, 5, 5}));
    s.volume().transfer.opacity = {{0.0, 0.1}, {2.0, 0.1}, {2.0, 0.6}, {4.0, 0.6}};
    s.volume().transfer.color = {{0.0, 1, 0, 0}, {2.0, 1, 0, 0}, {2.0, 0, 0, 1}, {4.0, 0, 0, 1}};
    s.camera = ortho_down_z(1.3, 2.7, 10.0, 1e-3);
    s.image.width = s.image.height = 1;
    const double A = 1.0 - 0.16 * 0.81, blue = 1.0 - 0.16, red = 0.16 * (1.0 - 0.81);
    s.render.integrator = IntegrationMethod::Adaptive;
    const PixelValue p = pixel(s);
    EXPECT_NEAR(p.rgba.a, A, 1e-13);
    EXPECT_NEAR(p.rgba.b, blue, 1e-13);
    EXPECT_NEAR(p.rgba.r, red, 1e-13);
    EXPECT_LE(p.error, 1e-6);
    s.render.integrator = IntegrationMethod::Fixed;
    s.render.step_units = StepUnits::World;
    for (double h : {0.3, 0.03, 0.003}) {
        s.render.step = h;
        const PixelValue q = pixel(s);
        EXPECT_NEAR(q.rgba.a, A, 2.0 * h) << h;
        EXPECT_NEAR(q.rgba.b, blue, 2.0 * h) << h;
    }
}

// Volume origins at 1e6: the constant chord's closed form to 1e-9 (t and positions near 1e6 carry
// absolute rounding of ~1e-10), fixed and adaptive.
TEST(Stability, OriginsAtAMillion) {
    const double a = 0.35, L = 2.0;
    const double alpha = 1.0 - std::pow(1.0 - a, L);
    for (IntegrationMethod m : {IntegrationMethod::Fixed, IntegrationMethod::Adaptive}) {
        Scene s = chord_scene(a, 1.0, L, 0.1, glm::dvec3(1e6, -1e6, 1e6));
        s.render.integrator = m;
        const PixelValue p = pixel(s);
        EXPECT_NEAR(p.rgba.a, alpha, 1e-9);
        EXPECT_NEAR(p.rgba.g, 0.6 * alpha, 1e-9);
    }
    // A linear field f = z - 1e6 + 1 there: adaptive and a fine fixed step agree.
    Scene s = field_scene(linear_field({0, 0, 1, -1e6 + 1}, {5, 5, 5}), glm::dvec3(1e6));
    s.volume().transfer.opacity = {{0.0, 0.0}, {5.0, 0.8}};
    s.volume().transfer.color = {{0.0, 1, 0, 0}, {5.0, 0, 1, 0}};
    s.camera = ortho_down_z(1e6 + 1.3, 1e6 + 2.7, 1e6 + 10.0, 1e-3);
    s.image.width = s.image.height = 1;
    s.render.integrator = IntegrationMethod::Adaptive;
    const PixelValue p = pixel(s);
    s.render.integrator = IntegrationMethod::Fixed;
    s.render.step = 1e-3;
    const PixelValue q = pixel(s);
    EXPECT_NEAR(p.rgba.a, q.rgba.a, 1e-7);
    EXPECT_NEAR(p.rgba.g, q.rgba.g, 1e-7);
    EXPECT_GT(p.rgba.a, 0.5);
}

// Anisotropic spacing 1000:1 (x spacing 1000, y and z 1): the constant chord down z (closed form), and
// a chord along x through a linear field f = x / 1000 (the transfer function's rows inside cells):
// the optical depth is integral sigma(f(x)) dx with f linear, compared with the closed form of
// -log(1 - a(f)) for a(f) = 0.5 f / 4 over x in [0, 4000]: tau = (4000 / 1000) integral_0^4 -log(1 - f / 8) df
// / unit distance (1000), i.e. 4 [ (8 - f) log(1 - f / 8) + f ]_0^4 / 1000 ... computed below.
TEST(Stability, AnisotropicSpacingThousandToOne) {
    const double a = 0.35, L = 3.0;
    const double alpha = 1.0 - std::pow(1.0 - a, L);
    for (IntegrationMethod m : {IntegrationMethod::Fixed, IntegrationMethod::Adaptive}) {
        Scene s = chord_scene(a, 1.0, L, 0.05, glm::dvec3(0.0), glm::dvec3(1000.0, 1.0, 1.0));
        s.render.integrator = m;
        const PixelValue p = pixel(s);
        EXPECT_NEAR(p.rgba.a, alpha, 1e-13);
    }
    Scene s = field_scene(linear_field({1e-3, 0, 0, 0}, {5, 5, 5}), glm::dvec3(0.0), glm::dvec3(1000.0, 1.0, 1.0));
    s.volume().transfer.opacity = {{0.0, 0.0}, {4.0, 0.5}};
    s.volume().transfer.opacity_unit_distance = 1000.0;
    s.camera.type = CameraSpec::Type::Orthographic;
    s.camera.eye = {-100.0, 1.3, 2.7};
    s.camera.target = {0.0, 1.3, 2.7};
    s.camera.up = {0, 0, 1};
    s.camera.height = 1e-3;
    s.image.width = s.image.height = 1;
    s.render.integrator = IntegrationMethod::Adaptive;
    s.render.tolerance = 1e-10;
    // tau = (1 / 1000) integral_0^4000 -log(1 - x / 8000) dx = 8 [(1 - u) log(1 - u) + u] at u = 1/2.
    const double tau = 8.0 * (0.5 * std::log(0.5) + 0.5);
    const PixelValue p = pixel(s);
    EXPECT_NEAR(p.rgba.a, -std::expm1(-tau), 1e-10);
    s.render.integrator = IntegrationMethod::Fixed;  // step 0.5 voxel = 0.5 world: 8000 segments
    EXPECT_NEAR(pixel(s).rgba.a, -std::expm1(-tau), 1e-7);
}

// Rays exactly along a cell face and along a cell edge (x = 2, and x = 2, y = 3, in a grid of spacing
// 1), through f = z + 0.1 x + 0.1 y on [0, 4]^3: the same closed form as a ray beside them, since the
// field is continuous across the face. Opacity a(f) = 0.1 f, so tau = integral_0^4 -log1p(-0.1 f(z)) dz.
TEST(Stability, RayAlongACellFaceOrEdge) {
    for (glm::dvec2 xy : {glm::dvec2(2.0, 2.5), glm::dvec2(2.0, 3.0), glm::dvec2(2.3, 3.0)}) {
        Scene s = field_scene(linear_field({0.1, 0.1, 1.0, 0.0}, {5, 5, 5}));
        s.volume().transfer.opacity = {{0.0, 0.0}, {10.0, 1.0}};
        s.volume().transfer.color = {{0.0, 1, 1, 1}};
        s.camera = ortho_down_z(xy.x, xy.y, 10.0, 1e-9);
        s.image.width = s.image.height = 1;
        // u = 1 - 0.1 (z + c), c = 0.1 (x + y), dz = -10 du: integral_0^4 -log u dz = 10 [F(u(4)) - F(u(0))]
        // with F(u) = u log u - u.
        const double c = 0.1 * (xy.x + xy.y);
        auto F = [](double u) { return u * std::log(u) - u; };
        const double tau = 10.0 * (F(1.0 - 0.1 * (4.0 + c)) - F(1.0 - 0.1 * c));
        for (IntegrationMethod m : {IntegrationMethod::Adaptive, IntegrationMethod::Fixed}) {
            s.render.integrator = m;
            s.render.step = 0.01;
            const PixelValue p = pixel(s);
            EXPECT_NEAR(p.rgba.a, -std::expm1(-tau), m == IntegrationMethod::Adaptive ? 1e-12 : 1e-6)
                << xy.x << "," << xy.y;
            EXPECT_NEAR(p.rgba.r, p.rgba.a, 1e-12);  // white: C = A
        }
    }
}

// NaN and +-Inf voxels (docs/accuracy.md): a sample whose value is not finite is transparent (no
// opacity, no emission), line integrals count it as 0, mip/minip ignore it; nothing non-finite reaches
// the image, in any projection, fixed or adaptive, scalar or SIMD; RenderStats counts the voxels.
TEST(Stability, NonFiniteVoxelsAreTransparentAndCounted) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    FieldSpec f;
    f.kind = FieldSpec::Kind::Cells;
    f.dims = {4, 4, 4};
    for (int k = 0; k < 64; ++k) f.values.push_back(0.25 * (k % 5));
    f.values[21] = nan;   // (1, 1, 1)
    f.values[42] = inf;   // (2, 2, 2)
    f.values[5] = -inf;   // (1, 1, 0)
    Scene s = field_scene(f);
    s.volume().transfer.opacity = {{0.0, 0.2}, {1.0, 0.9}};
    s.volume().transfer.color = {{0.0, 1, 0, 0}, {1.0, 0, 0, 1}};
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {8.0, 6.0, 9.0};
    s.camera.target = {1.5, 1.5, 1.5};
    s.camera.up = {0, 1, 0};
    s.camera.fov_y = 40.0;
    s.image.width = s.image.height = 16;
    s.render.isovalue = 0.6;
    for (Projection proj : {Projection::Composite, Projection::Mip, Projection::Minip, Projection::Average,
                            Projection::Xray, Projection::FirstHit})
        for (IntegrationMethod m : {IntegrationMethod::Fixed, IntegrationMethod::Adaptive})
            for (bool simd : {false, true}) {
                s.render.projection = proj;
                s.render.integrator = m;
                RenderOptions o{1, false};
                o.simd = simd;
                RenderStats stats;
                const Image im = render_scene(s, o, &stats);
                EXPECT_TRUE(all_finite(im)) << int(proj) << " " << int(m) << " simd " << simd;
                EXPECT_EQ(stats.non_finite_voxels, 3u);
            }
}

// Transparent, in numbers: a constant field 2 on a 2 x 2 x 5 grid whose voxel (0, 0, 4) is NaN (or
// +Inf): down z at (0.5, 0.5) the top cell z in [3, 4] reads it and is transparent, so
// A = 1 - (1 - a)^3; average = 2 * 3 / 4 (the cell counts 0 over its length), xray = 6; mip = 2.
TEST(Stability, NonFiniteCellIsTransparentClosedForm) {
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
        for (IntegrationMethod m : {IntegrationMethod::Fixed, IntegrationMethod::Adaptive})
            for (bool simd : {false, true}) {
                FieldSpec f;
                f.kind = FieldSpec::Kind::Cells;
                f.dims = {2, 2, 5};
                f.values.assign(20, 2.0);
                f.values[16] = bad;  // (0, 0, 4)
                Scene s = field_scene(f);
                s.volume().transfer.opacity = {{0.0, 0.3}};
                s.volume().transfer.color = {{0.0, 0.5, 0.5, 0.5}};
                s.camera = ortho_down_z(0.5, 0.5, 10.0, 1e-3);
                s.image.width = s.image.height = 1;
                s.render.integrator = m;
                s.render.step = 0.25;
                RenderOptions o{1, false};
                o.simd = simd;
                const double alpha = 1.0 - std::pow(0.7, 3.0);
                EXPECT_NEAR(render_scene(s, o).at(0, 0, 3), alpha, 1e-13) << int(m) << simd;
                s.render.projection = Projection::Average;
                EXPECT_NEAR(render_scene(s, o).at(0, 0, 0), 1.5, 1e-13);
                s.render.projection = Projection::Xray;
                EXPECT_NEAR(render_scene(s, o).at(0, 0, 0), 6.0, 1e-13);
                s.render.projection = Projection::Mip;
                EXPECT_NEAR(render_scene(s, o).at(0, 0, 3), 0.3, 1e-15);
            }
}

// volref render reports the count on stderr ("3 non-finite voxels") and writes a finite image; the
// EXR gets an "error" channel with --error (fixed) and with the adaptive integrator.
TEST(Stability, CliReportsNonFiniteVoxelsAndWritesTheErrorChannel) {
    const fs::path dir = fs::temp_directory_path() / ("volref-stability-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    Volume v;
    v.dims = {4, 4, 4};
    v.values.assign(64, 0.5);
    v.values[21] = std::numeric_limits<double>::quiet_NaN();
    v.values[42] = std::numeric_limits<double>::infinity();
    v.values[5] = -std::numeric_limits<double>::infinity();
    write_nrrd(v, dir / "v.nrrd");
    std::ofstream(dir / "s.json") << R"({"volume": {"source": "v.nrrd", "transfer": {"opacity": [[0, 0.5]]}},
        "image": {"width": 8, "height": 8}, "render": {"step": 0.25}})";
    auto run = [&](const std::string& args) {
        const std::string cmd = std::string(VOLREF_CLI) + " render " + (dir / "s.json").string() + " -o " +
                                (dir / "out.exr").string() + " " + args + " > /dev/null 2> " + (dir / "err.txt").string();
        const int status = std::system(cmd.c_str());
        std::ifstream in(dir / "err.txt");
        std::stringstream ss;
        ss << in.rdbuf();
        EXPECT_EQ(status, 0) << ss.str();
        return ss.str();
    };
    auto channels = [&]() {
        auto in = OIIO::ImageInput::open((dir / "out.exr").string());
        std::vector<std::string> names = in->spec().channelnames;
        std::vector<float> px(std::size_t(in->spec().width * in->spec().height) * names.size());
        in->read_image(0, 0, 0, int(names.size()), OIIO::TypeDesc::FLOAT, px.data());
        for (float x : px) EXPECT_FALSE(std::isnan(x));
        return names;
    };
    EXPECT_NE(run("").find("volref: warning: 3 non-finite voxels"), std::string::npos);
    std::vector<std::string> names = channels();
    EXPECT_EQ(std::count(names.begin(), names.end(), "error"), 0);
    run("--error");
    names = channels();
    EXPECT_EQ(std::count(names.begin(), names.end(), "error"), 1);
    run("--set render.integrator=adaptive");
    names = channels();
    EXPECT_EQ(std::count(names.begin(), names.end(), "error"), 1);
    fs::remove_all(dir);
}
