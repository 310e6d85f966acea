// Several volumes, transforms, clip planes and crop boxes (issue 9), against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "TestScenes.h"
#include "core/Angles.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "geometry/CropRegions.h"

using namespace volref;
using namespace volref::test;

namespace {

// A constant volume of value 1 on the box [lo, lo + (dims - 1)] (spacing 1) whose transfer function
// gives colour `c` and opacity `a` per unit length.
VolumeSpec constant_box(glm::dvec3 lo, std::array<std::int64_t, 3> dims, glm::dvec3 c, double a) {
    VolumeSpec v;
    v.source.field = constant_field(1.0, dims);
    v.origin = lo;
    v.spacing = glm::dvec3(1.0);
    v.transfer.color = {{0.0, c.r, c.g, c.b}};
    v.transfer.opacity = {{0.0, a}};
    return v;
}

// An orthographic w x h image of the rectangle [x0, x0 + w] x [y0, y0 + h] (one world unit per
// pixel), looking along -z from z = 20.
Scene ortho_scene(double x0, double y0, int w, int h) {
    Scene s;
    s.camera = ortho_down_z(x0 + 0.5 * w, y0 + 0.5 * h, 20.0, double(h));
    s.image.width = w;
    s.image.height = h;
    s.render.step = 0.37;  // any step: constant media are integrated exactly piece by piece
    s.render.step_units = StepUnits::World;
    return s;
}

Image render1(const Scene& s) {
    RenderOptions o;
    o.threads = 1;
    return render_scene(s, o);
}

void expect_near(const glm::dvec4& got, const glm::dvec4& want, double tol, const std::string& what) {
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], want[c], tol) << what << " channel " << c;
}

// 1 - (1 - a)^L: the opacity of length L of a medium of opacity a per unit length.
double alpha_of(double a, double L) { return 1.0 - std::pow(1.0 - a, L); }

}  // namespace

// ---- scene files -----------------------------------------------------------------------------

TEST(MultiVolumeLoader, VolumesTransformClipAndCrop) {
    const Scene s = parse_scene(R"({
      "volumes": [
        {"source": {"field": "constant", "dims": [2, 2, 2], "value": 1},
         "transform": [0, -1, 0, 5,  1, 0, 0, 6,  0, 0, 1, 7,  0, 0, 0, 1],
         "clip_planes": [{"point": [1, 2, 3], "normal": [0, 0, 2]}],
         "crop": {"planes": [0, 1, 0, 1, 0, 1], "regions": "cross"}},
        {"source": {"field": "constant", "dims": [2, 2, 2], "value": 2},
         "transform": {"scale": [2, 3, 4], "rotate": {"axis": [0, 0, 1], "degrees": 90}, "translate": [1, 2, 3]},
         "crop": {"planes": [0, 1, 0, 1, 0, 1], "regions": 5}}
      ]})", "", "scene.json");
    ASSERT_EQ(s.volumes.size(), 2u);
    // Row-major: the first row is (0, -1, 0, 5), so m[col][row]: m[1][0] = -1, m[3][0] = 5.
    const glm::dmat4 m = *s.volumes[0].transform;
    EXPECT_EQ(m[1][0], -1.0);
    EXPECT_EQ(m[0][1], 1.0);
    EXPECT_EQ(m[3][0], 5.0);
    EXPECT_EQ(m[3][1], 6.0);
    EXPECT_EQ(m[3][2], 7.0);
    ASSERT_EQ(s.volumes[0].clip_planes.size(), 1u);
    EXPECT_EQ(s.volumes[0].clip_planes[0].normal, glm::dvec3(0, 0, 1));  // normalised
    EXPECT_EQ(s.volumes[0].crop->regions, 0x0417410u);                    // VTK_CROP_CROSS
    EXPECT_EQ(s.volumes[1].crop->regions, 5u);
    // T R S with R = 90 degrees about z: x -> (2x) rotated = (0, 2, 0); local (1, 0, 0) -> (1, 4, 3).
    const glm::dmat4 t = *s.volumes[1].transform;
    const glm::dvec4 p = t * glm::dvec4(1, 0, 0, 1);
    EXPECT_EQ(glm::dvec3(p), glm::dvec3(1, 4, 3));
    const glm::dvec4 q = t * glm::dvec4(0, 1, 0, 1);  // (0, 3, 0) rotated = (-3, 0, 0)
    EXPECT_EQ(glm::dvec3(q), glm::dvec3(-2, 2, 3));
}

TEST(MultiVolumeLoader, BadInputNamesTheKey) {
    auto message = [](const std::string& volume_keys) {
        try {
            parse_scene(R"({"volumes": [{"source": {"field": "constant", "dims": [2, 2, 2]}}, {"source": {"field": "constant", "dims": [2, 2, 2]}, )" +
                            volume_keys + "}]}",
                        "", "scene.json");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message(R"("transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1])").find("volumes[1].transform: expected an affine matrix"),
              std::string::npos);
    EXPECT_NE(message(R"("transform": [1,0,0,0, 0,0,0,0, 0,0,1,0, 0,0,0,1])").find("volumes[1].transform: the matrix is not invertible"),
              std::string::npos);
    EXPECT_NE(message(R"("transform": {"scale": [1, 0, 1]})").find("volumes[1].transform.scale: expected non-zero"),
              std::string::npos);
    EXPECT_NE(message(R"("transform": {"rotate": {"axis": [0, 0, 0], "degrees": 3}})").find("volumes[1].transform.rotate.axis"),
              std::string::npos);
    EXPECT_NE(message(R"("transform": {"shear": 1})").find("volumes[1].transform.shear: unknown key"), std::string::npos);
    EXPECT_NE(message(R"("clip_planes": [{"point": [0, 0, 0], "normal": [0, 0, 0]}])").find("volumes[1].clip_planes[0].normal"),
              std::string::npos);
    EXPECT_NE(message(R"("crop": {"planes": [0, 1, 3, 2, 0, 1]})").find("volumes[1].crop.planes[3]"), std::string::npos);
    EXPECT_NE(message(R"("crop": {"planes": [0, 1, 0, 1, 0, 1], "regions": "box"})").find("volumes[1].crop.regions"),
              std::string::npos);
    EXPECT_NE(message(R"("crop": {"planes": [0, 1, 0, 1, 0, 1], "regions": 134217728})").find("volumes[1].crop.regions"),
              std::string::npos);
}

// ---- mixing ----------------------------------------------------------------------------------

// A along z in [0, 4], B along z in [2, 6]; the ray (along -z) crosses B alone for 2, both for 2,
// A alone for 2. With per-unit opacities aA = 0.3 (red), aB = 0.5 (blue), sigma = -ln(1 - a):
//   B alone: alpha1 = 1 - 0.5^2 = 0.75, C = 0.75 blue, T = 0.25;
//   both:    alpha2 = 1 - (0.7 * 0.5)^2 = 0.8775, colour (sA red + sB blue) / (sA + sB);
//   A alone: alpha3 = 1 - 0.7^2 = 0.51; A = 1 - 0.25 * 0.1225 * 0.49.
TEST(MultiVolume, OverlappingConstantBoxesMixByExtinction) {
    Scene s = ortho_scene(0.0, 0.0, 4, 4);
    s.volumes = {constant_box({0, 0, 0}, {5, 5, 5}, {1, 0, 0}, 0.3), constant_box({0, 0, 2}, {5, 5, 5}, {0, 0, 1}, 0.5)};
    const double sA = -std::log(0.7), sB = -std::log(0.5);
    const double T1 = 0.25, T2 = 0.25 * 0.1225;
    const glm::dvec3 mixed = (sA * glm::dvec3(1, 0, 0) + sB * glm::dvec3(0, 0, 1)) / (sA + sB);
    const glm::dvec3 C = 0.75 * glm::dvec3(0, 0, 1) + T1 * 0.8775 * mixed + T2 * 0.51 * glm::dvec3(1, 0, 0);
    const glm::dvec4 want(C, 1.0 - T2 * 0.49);
    for (auto order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
        s.render.order = order;
        const Image im = render1(s);
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) expect_near(rgba(im, x, y), want, 1e-13, "pixel " + std::to_string(x) + "," + std::to_string(y));
    }
}

// render.integrator "adaptive" mixes the volumes in continuous form (issue 18, case 9): the same
// closed form as above, within the pixel's error channel.
TEST(MultiVolume, AdaptiveMixOfOverlappingBoxesClosedForm) {
    Scene s = ortho_scene(0.0, 0.0, 4, 4);
    s.volumes = {constant_box({0, 0, 0}, {5, 5, 5}, {1, 0, 0}, 0.3), constant_box({0, 0, 2}, {5, 5, 5}, {0, 0, 1}, 0.5)};
    s.render.integrator = IntegrationMethod::Adaptive;
    const double sA = -std::log(0.7), sB = -std::log(0.5);
    const double T1 = 0.25, T2 = 0.25 * 0.1225;
    const glm::dvec3 mixed = (sA * glm::dvec3(1, 0, 0) + sB * glm::dvec3(0, 0, 1)) / (sA + sB);
    const glm::dvec3 C = 0.75 * glm::dvec3(0, 0, 1) + T1 * 0.8775 * mixed + T2 * 0.51 * glm::dvec3(1, 0, 0);
    const glm::dvec4 want(C, 1.0 - T2 * 0.49);
    const Image im = render1(s);
    ASSERT_EQ(im.channels.back(), "error");
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            EXPECT_LT(im.at(x, y, 4), 1e-6);
            expect_near(rgba(im, x, y), want, im.at(x, y, 4) + 1e-13, "pixel " + std::to_string(x) + "," + std::to_string(y));
        }
}

// The adaptive mix cuts at every volume's transfer-function rows and at clip planes. A: f = z on
// [0, 4]^3, red, opacity 0.1 below z = 2 and 0.6 above (a jump on a grid plane); B: constant, blue,
// opacity 0.3, on z in [1, 5], clipped to z <= 3.5. Along -z: [3.5, 4] A (0.6) alone, [2, 3.5] A (0.6)
// and B, [1, 2] A (0.1) and B, [0, 1] A (0.1) alone; each part adds T (1 - exp(-sigma L)) c_mix.
TEST(MultiVolume, AdaptiveMixCutsAtRowsAndClipPlanesClosedForm) {
    Scene s = ortho_scene(0.5, 0.5, 3, 3);
    VolumeSpec a;
    a.source.field = linear_field({0, 0, 1, 0}, {5, 5, 5});
    a.origin = glm::dvec3(0.0);
    a.spacing = glm::dvec3(1.0);
    a.transfer.color = {{0.0, 1.0, 0.0, 0.0}};
    a.transfer.opacity = {{0.0, 0.1}, {2.0, 0.1}, {2.0, 0.6}, {4.0, 0.6}};
    VolumeSpec b = constant_box({0, 0, 1}, {5, 5, 5}, {0, 0, 1}, 0.3);
    b.clip_planes = {{{0.0, 0.0, 3.5}, {0.0, 0.0, -1.0}}};
    s.volumes = {a, b};
    s.render.integrator = IntegrationMethod::Adaptive;
    const double sA1 = -std::log(0.9), sA2 = -std::log(0.4), sB = -std::log(0.7);
    const glm::dvec3 red(1, 0, 0), blue(0, 0, 1);
    struct Part { double sigma, L; glm::dvec3 c; };
    const Part parts[4] = {{sA2, 0.5, red},
                           {sA2 + sB, 1.5, (sA2 * red + sB * blue) / (sA2 + sB)},
                           {sA1 + sB, 1.0, (sA1 * red + sB * blue) / (sA1 + sB)},
                           {sA1, 1.0, red}};
    glm::dvec3 C(0.0);
    double T = 1.0;
    for (const Part& p : parts) {
        C += T * -std::expm1(-p.sigma * p.L) * p.c;
        T *= std::exp(-p.sigma * p.L);
    }
    const glm::dvec4 want(C, 1.0 - T);
    const Image im = render1(s);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 3; ++x) {
            EXPECT_LT(im.at(x, y, 4), 1e-6);
            expect_near(rgba(im, x, y), want, im.at(x, y, 4) + 1e-13, "pixel " + std::to_string(x) + "," + std::to_string(y));
        }
    // and the fixed mix converges to it (midpoint segments of the pieces: the jump falls on a piece end
    // only for the adaptive cuts, so the fixed step is off by O(h) there)
    s.render.integrator = IntegrationMethod::Fixed;
    s.render.step = 1e-4;
    const Image fixed = render1(s);
    expect_near(rgba(fixed, 1, 1), want, 1e-4, "fixed step 1e-4");
}

// B in front of A (touching at z = 4): C = alphaB cB + (1 - alphaB) alphaA cA.
TEST(MultiVolume, BoxesInFrontOfEachOther) {
    Scene s = ortho_scene(0.0, 0.0, 4, 4);
    s.volumes = {constant_box({0, 0, 0}, {5, 5, 5}, {1, 0.5, 0}, 0.2), constant_box({0, 0, 4}, {5, 5, 3}, {0, 1, 1}, 0.6)};
    const double aA = alpha_of(0.2, 4.0), aB = alpha_of(0.6, 2.0);
    const glm::dvec4 want(aB * glm::dvec3(0, 1, 1) + (1 - aB) * aA * glm::dvec3(1, 0.5, 0), 1 - (1 - aA) * (1 - aB));
    const Image im = render1(s);
    expect_near(rgba(im, 1, 2), want, 1e-13, "front/back");
}

// Side by side: each pixel sees one volume alone, as if it were the only one.
TEST(MultiVolume, BoxesSideBySide) {
    Scene s = ortho_scene(0.0, 0.0, 8, 4);
    s.volumes = {constant_box({0, 0, 0}, {5, 5, 5}, {1, 0, 0}, 0.3), constant_box({4, 0, 0}, {5, 5, 3}, {0, 1, 0}, 0.4)};
    const Image im = render1(s);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) expect_near(rgba(im, x, y), {alpha_of(0.3, 4), 0, 0, alpha_of(0.3, 4)}, 1e-13, "left");
        for (int x = 4; x < 8; ++x) expect_near(rgba(im, x, y), {0, alpha_of(0.4, 2), 0, alpha_of(0.4, 2)}, 1e-13, "right");
    }
}

// Listing the volumes in another order changes no bit (three overlapping shaded Gaussians).
TEST(MultiVolume, OrderIndependence) {
    Scene s;
    s.image.width = s.image.height = 24;
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = {9, 7, 20};
    s.camera.target = {4, 4, 4};
    s.camera.fov_y = 40;
    std::vector<VolumeSpec> v;
    for (int k = 0; k < 3; ++k) {
        FieldSpec f;
        f.kind = FieldSpec::Kind::Gaussian;
        f.dims = {9, 9, 9};
        f.center = glm::dvec3(3.0 + k, 4.0, 4.0 - k);
        f.sigma = 2.0;
        VolumeSpec vs;
        vs.source.field = f;
        vs.origin = glm::dvec3(0.5 * k, 0.0, 0.25 * k);
        vs.transfer.color = {{0.0, k == 0 ? 1.0 : 0.2, k == 1 ? 1.0 : 0.3, k == 2 ? 1.0 : 0.1}, {1.0, 1, 1, 1}};
        vs.transfer.opacity = {{0.1, 0.0}, {1.0, 0.3 + 0.2 * k}};
        vs.shading = ShadingSpec{};
        v.push_back(vs);
    }
    // The last pass is the adaptive mix (its cuts, terms and opaque colours in canonical order).
    const std::pair<Projection, IntegrationMethod> passes[] = {
        {Projection::Composite, IntegrationMethod::Fixed}, {Projection::Mip, IntegrationMethod::Fixed},
        {Projection::Average, IntegrationMethod::Fixed},   {Projection::Xray, IntegrationMethod::Fixed},
        {Projection::Composite, IntegrationMethod::Adaptive}};
    for (const auto& [projection, integrator] : passes) {
        s.render.projection = projection;
        s.render.integrator = integrator;
        s.volumes = {v[0], v[1], v[2]};
        const Image a = render1(s);
        s.volumes = {v[2], v[0], v[1]};
        const Image b = render1(s);
        s.volumes = {v[1], v[2], v[0]};
        const Image c = render1(s);
        int lit = 0;
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                for (std::size_t ch = 0; ch < 4; ++ch) {
                    ASSERT_EQ(a.at(x, y, ch), b.at(x, y, ch)) << int(projection) << " " << x << "," << y;
                    ASSERT_EQ(a.at(x, y, ch), c.at(x, y, ch)) << int(projection) << " " << x << "," << y;
                }
                lit += a.at(x, y, 3) > 0.05;
            }
        EXPECT_GT(lit, 100) << "the volumes are in view";
    }
}

// MIP over volumes: per-channel maximum of the volumes' own MIP pixels; x-ray: the sum; average: the
// length-weighted mean; first hit: the nearer volume.
TEST(MultiVolume, OtherProjectionsCombineTheVolumes) {
    Scene s = ortho_scene(0.0, 0.0, 4, 4);
    // A: value 1 over z in [0, 4]; B: value 3 over z in [2, 6]. Transfer: grey value / 4, opacity 1.
    VolumeSpec a = constant_box({0, 0, 0}, {5, 5, 5}, {1, 1, 1}, 1.0), b = constant_box({0, 0, 2}, {5, 5, 5}, {1, 1, 1}, 1.0);
    a.source.field->value = 1.0;
    b.source.field->value = 3.0;
    for (VolumeSpec* v : {&a, &b}) {
        v->transfer.color = {{0.0, 0, 0, 0}, {4.0, 1, 0.5, 0.25}};
        v->transfer.opacity = {{0.0, 0.0}, {4.0, 1.0}};
    }
    s.volumes = {a, b};
    s.render.projection = Projection::Mip;  // A: 0.25 (0.25, 0.125, 0.0625); B: 0.75 (0.75, 0.375, 0.1875) premultiplied
    expect_near(rgba(render1(s), 1, 1), {0.75 * 0.75, 0.75 * 0.375, 0.75 * 0.1875, 0.75}, 1e-15, "mip");
    s.render.projection = Projection::Minip;
    expect_near(rgba(render1(s), 1, 1), {0.25 * 0.25, 0.25 * 0.125, 0.25 * 0.0625, 0.25}, 1e-15, "minip");
    s.render.projection = Projection::Xray;  // 1 * 4 + 3 * 4
    expect_near(rgba(render1(s), 1, 1), {16, 16, 16, 1}, 1e-12, "xray");
    s.render.projection = Projection::Average;  // (4 * 1 + 4 * 3) / 8
    expect_near(rgba(render1(s), 1, 1), {2, 2, 2, 1}, 1e-13, "average");
}

TEST(MultiVolume, FirstHitTakesTheNearerVolume) {
    Scene s = ortho_scene(0.0, 0.0, 4, 4);
    // Linear fields A: f = z over z in [0, 4], B: f = z - 4 over z in [4, 8]. Isovalue 2 is crossed by A at
    // z = 2 (depth 18 from the eye plane z = 20) and by B at z = 6 (depth 14): the pixel is B's hit.
    VolumeSpec a, b;
    a.source.field = linear_field({0, 0, 1, 0}, {5, 5, 5});
    a.origin = glm::dvec3(0.0);
    b.source.field = linear_field({0, 0, 1, -4}, {5, 5, 5});
    b.origin = glm::dvec3(0, 0, 4);
    s.volumes = {a, b};
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = 2.0;
    const Image im = render1(s);
    EXPECT_NEAR(im.at(1, 1, 4), 14.0, 1e-9);
    s.volumes = {a};
    EXPECT_NEAR(render1(s).at(1, 1, 4), 18.0, 1e-9);
}

// The memory limit counts the volumes already prepared: two 32^3 fields of doubles (256 KiB each)
// under a 400 KiB limit: the first fits, the second is refused before it is generated, and the
// message names it.
TEST(MultiVolume, MemoryLimitCountsTheEarlierVolumes) {
    const std::size_t saved = memory_limit();
    Scene s = ortho_scene(0.0, 0.0, 1, 1);
    s.volumes = {constant_box({0, 0, 0}, {32, 32, 32}, {1, 0, 0}, 0.1), constant_box({4, 0, 0}, {32, 32, 32}, {0, 0, 1}, 0.1)};
    set_memory_limit(400 << 10);
    std::string message;
    try {
        render1(s);
    } catch (const Error& e) {
        message = e.what();
    }
    set_memory_limit(saved);
    EXPECT_EQ(message, "volumes[1].source.dims: a volume of 32 x 32 x 32: needs 256 KiB besides the 256 KiB the earlier "
                       "volumes hold, more than the memory limit of 400 KiB (--max-memory)");
    s.volumes.pop_back();
    set_memory_limit(400 << 10);
    EXPECT_NO_THROW(render1(s));  // one alone fits
    set_memory_limit(saved);
}

// ---- transforms ------------------------------------------------------------------------------

// A volume rotated by 90 degrees about z equals the same data resampled into the rotated position:
// local (x, y, z) -> world (-y, x, z), so the world grid W(i, j, k) at (-2 + i, j, k) (dims 3 x 4 x 2)
// holds V(j, 2 - i, k). Shaded, so the gradient goes through A^-T.
TEST(Transform, RotationBy90DegreesEqualsTheResampledGrid) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    FieldSpec v;
    v.kind = FieldSpec::Kind::Cells;
    v.dims = {4, 3, 2};
    for (int n = 0; n < 24; ++n) v.values.push_back(u(rng));
    FieldSpec w = v;
    w.dims = {3, 4, 2};
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 3; ++i) w.values[std::size_t(i + 3 * (j + 4 * k))] = v.values[std::size_t(j + 4 * ((2 - i) + 3 * k))];
    auto scene = [&](const FieldSpec& f, glm::dvec3 origin, bool rotate) {
        Scene s;
        s.volume().source.field = f;
        s.volume().origin = origin;
        s.volume().transfer.color = {{0.0, 1, 0.2, 0}, {1.0, 0.1, 0.5, 1}};
        s.volume().transfer.opacity = {{0.0, 0.05}, {1.0, 0.9}};
        s.volume().shading = ShadingSpec{};
        if (rotate) s.volume().transform = glm::dmat4(glm::dmat3(rotation_matrix({0, 0, 1}, 90.0)));
        s.camera.type = CameraSpec::Type::Perspective;
        s.camera.eye = {3, -4, 6};
        s.camera.target = {-1, 1.5, 0.5};
        s.camera.fov_y = 30;
        s.image.width = s.image.height = 20;
        s.render.step = 0.1;
        s.render.step_units = StepUnits::World;
        return s;
    };
    const Image rotated = render1(scene(v, {0, 0, 0}, true));
    const Image resampled = render1(scene(w, {-2, 0, 0}, false));
    int lit = 0;
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            expect_near(rgba(rotated, x, y), rgba(resampled, x, y), 1e-12, std::to_string(x) + "," + std::to_string(y));
            lit += rotated.at(x, y, 3) > 0.01;
        }
    EXPECT_GT(lit, 50);
}

// A translation by (3, -2, 0) world units moves an orthographic image by 3 pixels right and 2 down
// (one unit per pixel; y grows downward in the image): moved(x, y) = base(x - 3, y - 2), and the
// pixels whose source lies outside the base image are empty (the volume is not there).
TEST(Transform, TranslationMovesTheImageByWholePixels) {
    Scene s = ortho_scene(-4.0, -4.0, 16, 16);
    FieldSpec f;
    f.kind = FieldSpec::Kind::Gaussian;
    f.dims = {7, 7, 5};
    f.center = {2.5, 3.0, 2.0};
    f.sigma = 1.5;
    s.volume().source.field = f;
    s.volume().transfer.opacity = {{0.0, 0.0}, {1.0, 0.8}};
    s.volume().shading = ShadingSpec{};
    const Image base = render1(s);
    glm::dmat4 t(1.0);
    t[3] = glm::dvec4(3, -2, 0, 1);
    s.volume().transform = t;
    const Image moved = render1(s);
    int lit = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const bool inside = x - 3 >= 0 && y - 2 >= 0;
            const glm::dvec4 want = inside ? rgba(base, x - 3, y - 2) : glm::dvec4(0.0);
            expect_near(rgba(moved, x, y), want, 1e-12, std::to_string(x) + "," + std::to_string(y));
            lit += moved.at(x, y, 3) > 0.01;
        }
    EXPECT_GT(lit, 30) << "the moved volume is in view";
}

// A scale by powers of two, S = diag(2, 1, 0.5), applied to a unit-spacing grid at origin o equals the
// same grid with spacing (2, 1, 0.5) at origin S o: the local rays are no longer unit (|A^-1 d| != 1),
// the world lengths stay the same, and every division by 2 or 0.5 is exact, so the two renders agree
// to rounding (the gradient comes back through A^-T = S^-1, which a wrong A would not give). Shaded
// (scalar path) and unshaded (SIMD packets of local rays), perspective.
TEST(Transform, ScaleEqualsTheSpacing) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::MarschnerLobb;
    f.dims = {9, 7, 11};
    for (const bool shaded : {false, true}) {
        auto scene = [&](bool transformed) {
            Scene s;
            s.volume().source.field = f;
            if (transformed) {
                s.volume().origin = glm::dvec3(-4, -3, -5);
                s.volume().spacing = glm::dvec3(1.0);
                s.volume().transform = glm::dmat4(glm::dmat3(glm::dvec3(2, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 0.5)));
            } else {
                s.volume().origin = glm::dvec3(-8, -3, -2.5);
                s.volume().spacing = glm::dvec3(2, 1, 0.5);
            }
            s.volume().transfer.color = {{0.0, 1, 0.2, 0}, {1.0, 0.1, 0.5, 1}};
            s.volume().transfer.opacity = {{0.0, 0.0}, {0.4, 0.05}, {1.0, 0.6}};
            if (shaded) s.volume().shading = ShadingSpec{};
            s.camera.type = CameraSpec::Type::Perspective;
            s.camera.eye = {14, -9, 12};
            s.camera.target = {0, 0, 0};
            s.camera.fov_y = 40;
            s.image.width = s.image.height = 24;
            s.render.step = 0.3;
            s.render.step_units = StepUnits::World;
            return s;
        };
        const Image a = render1(scene(true)), b = render1(scene(false));
        int lit = 0;
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                expect_near(rgba(a, x, y), rgba(b, x, y), 1e-12,
                            std::string(shaded ? "shaded " : "unshaded ") + std::to_string(x) + "," + std::to_string(y));
                lit += a.at(x, y, 3) > 0.01;
            }
        EXPECT_GT(lit, 100) << "the volume is in view";
    }
}

// ---- clip planes -----------------------------------------------------------------------------

// A constant-density ball (spherical shell bounds, radius [0, 3]) cut by the plane through its centre
// with normal (0, 1, 1) / sqrt 2: the kept part is y' + z' >= 0 (primes: relative to the centre). A
// ray along -z at (x', y') is inside the ball for z' in [-h, h], h = sqrt(9 - x'^2 - y'^2), so its
// chord is [max(-h, -y'), h], of length L = h - max(-h, -y') when positive; alpha = 1 - 0.6^L.
TEST(ClipPlanes, ChordsOfABallAreCutExactly) {
    Scene s = ortho_scene(-3.0, -3.0, 12, 12);
    s.camera = ortho_down_z(0.0, 0.0, 20.0, 6.0);  // the square [-3, 3]^2, 0.5 units per pixel
    VolumeSpec& v = s.volume();
    v.bounds.type = BoundsSpec::Type::Spherical;
    v.bounds.sphere.r0 = 0.0;
    v.bounds.sphere.r1 = 3.0;
    v.source.field = constant_field(1.0, {4, 8, 5});
    v.origin.reset();
    v.spacing.reset();
    v.transfer.opacity = {{0.0, 0.4}};
    v.clip_planes = {{{0, 0, 0}, glm::normalize(glm::dvec3(0, 1, 1))}};
    const Image im = render1(s);
    int cut = 0;
    for (int py = 0; py < 12; ++py)
        for (int px = 0; px < 12; ++px) {
            const double x = -3.0 + 0.5 * (px + 0.5), y = 3.0 - 0.5 * (py + 0.5);
            const double h2 = 9.0 - x * x - y * y;
            double L = 0.0;
            if (h2 > 0) {
                const double h = std::sqrt(h2);
                L = std::max(0.0, h - std::max(-h, -y));
                cut += -y > -h && -y < h;
            }
            EXPECT_NEAR(im.at(px, py, 3), alpha_of(0.4, L), 1e-12) << px << "," << py;
        }
    EXPECT_GT(cut, 20);  // the plane cuts many chords
}

// ---- crop boxes ------------------------------------------------------------------------------

// A constant box [0, 6]^3 cropped by the planes 2 and 4 on every axis, viewed along -z: the ray at
// pixel (x, y) crosses the three z ranges, each of length 2, so it keeps 2 n units, n = how many of
// the regions (ix, iy, 0..2) are kept. The region maps, from VTK's documentation of the presets
// (c = how many of ix, iy, iz are 1, the middle range): subvolume c = 3, fence c >= 1, inverted
// fence c = 0, cross c >= 2, inverted cross c <= 1.
TEST(Crop, EachPresetKeepsItsRegions) {
    struct Preset {
        const char* name;
        bool (*keeps)(int c);
    };
    const Preset presets[] = {{"subvolume", [](int c) { return c == 3; }},
                              {"fence", [](int c) { return c >= 1; }},
                              {"inverted-fence", [](int c) { return c == 0; }},
                              {"cross", [](int c) { return c >= 2; }},
                              {"inverted-cross", [](int c) { return c <= 1; }}};
    for (const Preset& p : presets) {
        const Scene s = parse_scene(std::string(R"({
          "volume": {"source": {"field": "constant", "dims": [7, 7, 7], "value": 1},
                     "transfer": {"opacity": [[0, 0.3]]},
                     "crop": {"planes": [2, 4, 2, 4, 2, 4], "regions": ")") + p.name + R"("}},
          "camera": {"type": "orthographic", "eye": [3, 3, 20], "target": [3, 3, 0], "height": 6},
          "image": {"width": 6, "height": 6},
          "render": {"step": 0.3, "step_units": "world"}})",
                                    "", "crop.json");
        const Image im = render1(s);
        for (int py = 0; py < 6; ++py)
            for (int px = 0; px < 6; ++px) {
                const int ix = px / 2, iy = (5 - py) / 2;  // image y grows downward
                int n = 0;
                for (int iz = 0; iz < 3; ++iz) n += p.keeps((ix == 1) + (iy == 1) + (iz == 1));
                EXPECT_NEAR(im.at(px, py, 3), alpha_of(0.3, 2.0 * n), 1e-13) << p.name << " " << px << "," << py;
            }
    }
}

TEST(Crop, RegionNumbers) {
    CropSpec c;
    c.planes = {0, 1, 0, 1, 0, 1};
    EXPECT_EQ(crop_region(c, {-1, -1, -1}), 0);
    EXPECT_EQ(crop_region(c, {0.5, 0.5, 0.5}), 13);
    EXPECT_EQ(crop_region(c, {2, -1, -1}), 2);
    EXPECT_EQ(crop_region(c, {-1, 2, -1}), 6);
    EXPECT_EQ(crop_region(c, {2, 2, 2}), 26);
    EXPECT_EQ(crop_region(c, {1, 0, 1}), 13);  // the planes belong to the middle range
}
