// Shading against hand calculations and the analytic sphere (conventions section 8).
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "TestScenes.h"
#include "transfer/Shader.h"

using namespace volref;
using namespace volref::test;

namespace {
LightSpec headlight(glm::dvec3 color = glm::dvec3(1.0)) {
    LightSpec l;
    l.type = LightSpec::Type::Headlight;
    l.color = color;
    return l;
}
LightSpec directional(glm::dvec3 dir, glm::dvec3 color = glm::dvec3(1.0)) {
    LightSpec l;
    l.type = LightSpec::Type::Directional;
    l.direction = glm::normalize(dir);
    l.color = color;
    return l;
}
void expect_near(const glm::dvec3& a, const glm::dvec3& b, double tol) {
    EXPECT_NEAR(a.r, b.r, tol);
    EXPECT_NEAR(a.g, b.g, tol);
    EXPECT_NEAR(a.b, b.b, tol);
}
}  // namespace

// Hand calculation: gradient (0, 0, -2) -> N = (0, 0, 1); V = (0, 0, 1); a directional light from
// L = (0, 0.6, 0.8): N.L = 0.8, H = normalize(L + V) = (0, 0.6, 1.8) / sqrt(3.6), N.H = 1.8 / sqrt(3.6).
TEST(Shader, BlinnPhongByHand) {
    ShadingSpec spec;  // ka 0.1, kd 0.7, ks 0.2, n 10
    const Shader sh(spec, {directional({0, 0.6, 0.8})}, 0.0);
    const glm::dvec3 m(0.5, 0.25, 1.0);
    const double nh = 1.8 / std::sqrt(3.6);
    const glm::dvec3 expected = 0.1 * m + 0.7 * m * 0.8 + glm::dvec3(0.2 * std::pow(nh, 10));
    expect_near(sh.shade(m, {0, 0, -2}, {0, 0, 1}, 3.0), expected, 1e-15);
}

TEST(Shader, PhongUsesTheReflection) {
    ShadingSpec spec;
    spec.model = ShadingSpec::Model::Phong;
    const Shader sh(spec, {directional({0, 0.6, 0.8})}, 0.0);
    // R = 2 (N.L) N - L = (0, -0.6, 0.8); R.V = 0.8.
    const glm::dvec3 m(1.0);
    expect_near(sh.shade(m, {0, 0, -1}, {0, 0, 1}, 0.0), glm::dvec3(0.1 + 0.7 * 0.8 + 0.2 * std::pow(0.8, 10)), 1e-15);
}

TEST(Shader, NodalHasNoSpecular) {
    ShadingSpec spec;
    spec.model = ShadingSpec::Model::Nodal;
    const Shader sh(spec, {headlight()}, 0.0);
    expect_near(sh.shade(glm::dvec3(0.5), {0, 0, -1}, {0, 0, 1}, 0.0), glm::dvec3(0.5 * (0.1 + 0.7)), 1e-15);
}

// Depth cueing divides the diffuse and specular terms by kc + kl d; coloured lights multiply every
// term; several lights add (each with its own ambient term).
TEST(Shader, DepthCueColouredAndSeveralLights) {
    ShadingSpec spec;
    spec.kc = 0.5;
    spec.kl = 0.25;
    const glm::dvec3 m(0.4, 0.6, 0.8), I1(1.0, 0.5, 0.0), I2(0.0, 0.0, 2.0);
    const Shader sh(spec, {headlight(I1), directional({1, 0, 0}, I2)}, 0.0);
    const double cue = 1.0 / (0.5 + 0.25 * 6.0);
    // Headlight: N.L = N.H = 1. Directional (1, 0, 0): N.L = 0, H = normalize(1, 0, 1): N.H = 1/sqrt(2).
    const glm::dvec3 c1 = I1 * (0.1 * m + (0.7 * m + glm::dvec3(0.2)) * cue);
    const glm::dvec3 c2 = I2 * (0.1 * m + glm::dvec3(0.2 * std::pow(1.0 / std::sqrt(2.0), 10)) * cue);
    expect_near(sh.shade(m, {0, 0, -1}, {0, 0, 1}, 6.0), c1 + c2, 1e-15);
}

TEST(Shader, TwoSidedAndZeroGradient) {
    ShadingSpec spec;
    const Shader one(spec, {headlight()}, 1e-9);
    spec.two_sided = true;
    const Shader two(spec, {headlight()}, 1e-9);
    const glm::dvec3 m(0.5);
    // N = (0, 0, -1) faces away from V = (0, 0, 1): one-sided leaves only the ambient term.
    expect_near(one.shade(m, {0, 0, 1}, {0, 0, 1}, 0.0), 0.1 * m, 1e-15);
    expect_near(two.shade(m, {0, 0, 1}, {0, 0, 1}, 0.0), 0.1 * m + 0.7 * m + glm::dvec3(0.2), 1e-15);
    // A gradient at or below the tolerance is unshaded: the colour comes back exactly.
    EXPECT_EQ(one.shade(m, {0, 0, 1e-10}, {0, 0, 1}, 0.0), m);
    EXPECT_EQ(one.shade(m, {0, 0, 0}, {0, 0, 1}, 0.0), m);
}

namespace {
// A Gaussian blob (dense at the centre) or a radial distance field, seen orthographically along -z,
// first hit at the isovalue, a headlight, Blinn-Phong.
Scene blob_scene(FieldSpec::Kind kind, double iso) {
    FieldSpec f;
    f.kind = kind;
    f.dims = {65, 65, 65};
    f.center = {0.0, 0.0, 0.0};
    f.sigma = 0.5;
    f.amplitude = 1.0;
    Scene s = field_scene(f, glm::dvec3(-1.0), glm::dvec3(2.0 / 64.0));
    s.volume().transfer.color = {{0.0, 0.8, 0.6, 0.4}};
    s.volume().shading = ShadingSpec{};
    s.camera = ortho_down_z(0.0, 0.0, 5.0, 2.0);
    s.image.width = s.image.height = 32;
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = iso;
    s.render.step = 0.5;
    return s;
}
}  // namespace

// First hit on a Gaussian blob with a headlight along -z: the isosurface is the sphere of radius
// R = sigma sqrt(2 ln(A / iso)); at a pixel whose ray passes at distance rho from the centre the
// outward normal has N.L = N.H = sqrt(R^2 - rho^2) / R (L = V = H = +z), so the colour is
// ka m + kd m (N.L) + ks (N.L)^n. Tolerance: with h = 1/32 and sigma = 0.5 (16 voxels), trilinear
// reconstruction moves the surface by at most h^2 |f''| / (8 |f'|) ~ 1e-3 R and central differences
// tilt the normal by O(h^2 / sigma^2) ~ 4e-3, so N.L is within 0.01 where N.L >= 0.3 (away from the
// silhouette); the specular term's error is n (N.L)^(n-1) times that.
TEST(Shading, FirstHitOnAGaussianMatchesTheAnalyticSphere) {
    const double iso = 0.5, sigma = 0.5;
    const Image im = render_scene(blob_scene(FieldSpec::Kind::Gaussian, iso), {0, false});
    const double R = sigma * std::sqrt(2.0 * std::log(1.0 / iso));
    const glm::dvec3 m(0.8, 0.6, 0.4);
    int checked = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            const double px = -1.0 + (x + 0.5) / 16.0, py = 1.0 - (y + 0.5) / 16.0;
            const double rho2 = px * px + py * py;
            if (rho2 >= R * R) continue;
            const double nl = std::sqrt(R * R - rho2) / R;
            if (nl < 0.3) continue;
            const double eps = 0.01;
            const glm::dvec3 expected = 0.1 * m + 0.7 * m * nl + glm::dvec3(0.2 * std::pow(nl, 10));
            const double tol_spec = 0.2 * 10 * std::pow(std::min(nl + eps, 1.0), 9) * eps;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(im.at(x, y, std::size_t(c)), expected[c], 0.7 * m[c] * eps + tol_spec) << x << "," << y;
            ++checked;
        }
    EXPECT_GT(checked, 200);
}

// The sign convention: normals point from dense to thin. A blob dense at its centre is lit from
// outside; a distance field (dense outside) shows only its ambient term unless lighting is two-sided.
TEST(Shading, NormalsPointFromDenseToThin) {
    const glm::dvec3 m(0.8, 0.6, 0.4);
    const Image blob = render_scene(blob_scene(FieldSpec::Kind::Gaussian, 0.5), {0, false});
    Scene dist = blob_scene(FieldSpec::Kind::Radial, 0.5);
    const Image one_sided = render_scene(dist, {0, false});
    dist.volume().shading->two_sided = true;
    const Image two_sided = render_scene(dist, {0, false});
    // The centre pixels (15..16): N is (nearly) the view direction for the blob, its opposite for the
    // distance field.
    for (int y = 15; y <= 16; ++y)
        for (int x = 15; x <= 16; ++x) {
            EXPECT_GT(blob.at(x, y, 0), (0.1 + 0.7 * 0.99) * m.r);
            EXPECT_NEAR(one_sided.at(x, y, 0), 0.1 * m.r, 1e-12);
            EXPECT_GT(two_sided.at(x, y, 0), (0.1 + 0.7 * 0.99) * m.r);
        }
}

// A constant field has a zero gradient: a shaded render equals the unshaded one bit for bit.
TEST(Shading, ZeroGradientIsUnshadedExactly) {
    Scene s = field_scene(constant_field(3.0, {5, 5, 5}));
    s.volume().transfer.opacity = {{0, 0.3}};
    s.volume().transfer.color = {{0, 0.2, 0.5, 0.7}};
    s.image.width = s.image.height = 8;
    // Both through the scalar path (the unshaded scene would otherwise take the SIMD path, whose
    // exp/log1p differ in the last bits).
    const Image plain = render_scene(s, {.threads = 1, .simd = false});
    s.volume().shading = ShadingSpec{};
    const Image shaded = render_scene(s, {.threads = 1, .simd = false});
    EXPECT_EQ(plain.pixels, shaded.pixels);
}

// Depth cueing in a render: first hit on the plane z = 2.7 of f = z at t = 7.3 (orthographic from
// z = 10), normal +z facing the headlight: c = ka m + (kd m + ks) / (kc + kl t).
TEST(Shading, DepthCueInARender) {
    Scene s = field_scene(linear_field({0, 0, -1, 0}, {5, 5, 5}));  // dense at the bottom: N = +z
    s.volume().transfer.color = {{-10, 0.5, 0.5, 0.5}};
    ShadingSpec spec;
    spec.kc = 1.0;
    spec.kl = 0.5;
    s.volume().shading = spec;
    s.camera = ortho_down_z(2.0, 2.0, 10.0, 2.0);
    s.image.width = s.image.height = 2;
    s.render.projection = Projection::FirstHit;
    s.render.isovalue = -2.7;
    s.render.step = 0.3;
    s.render.step_units = StepUnits::World;
    const Image im = render_scene(s, {1, false});
    const double expected = 0.1 * 0.5 + (0.7 * 0.5 + 0.2) / (1.0 + 0.5 * 7.3);
    EXPECT_NEAR(im.at(0, 0, 0), expected, 1e-8);
}
