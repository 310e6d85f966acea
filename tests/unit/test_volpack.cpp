// The volpack profile (issue 55; core/integrate/profiles/VolPack.h, VolPackRenderer.h): VolPack 1.0b3's
// arithmetic piece by piece against numbers derived by hand from its sources (vp_view.c, vp_linalg.c,
// vp_shade.c, vp_warp.c, vp_rle.c; ../shared/notes/volpack.md), and the renderer on volumes small enough
// to work the whole pipeline by hand. The comparison with the real library is tests/volpack (ctest -L
// volpack), not repeated here.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ErrorOf.h"
#include "TempDir.h"
#include "core/Error.h"
#include "core/camera/Camera.h"
#include "core/grid/Volume.h"
#include "core/integrate/profiles/VolPack.h"
#include "core/integrate/profiles/VolPackRenderer.h"
#include "core/render/PreparedScene.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneWriter.h"

using namespace volref;
using namespace volref::volpack;
using nlohmann::json;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A u8 volume of f(x, y, z), x fastest, at the origin with unit spacing.
Volume u8_volume(std::array<std::int64_t, 3> dims, const std::function<int(std::int64_t, std::int64_t, std::int64_t)>& f) {
    Volume v;
    v.dims = dims;
    v.type = ScalarType::U8;
    v.values = VoxelArray(ScalarType::U8, std::size_t(dims[0] * dims[1] * dims[2]));
    for (std::int64_t z = 0; z < dims[2]; ++z)
        for (std::int64_t y = 0; y < dims[1]; ++y)
            for (std::int64_t x = 0; x < dims[0]; ++x) v.values.set(v.index(x, y, z), double(f(x, y, z)));
    return v;
}

// The inputs with every scalar's opacity `a` (no gradient table, unshaded, luminance).
VolPackSpec constant_spec(float a) {
    VolPackSpec s;
    s.scalar_table.entries.assign(256, a);
    return s;
}

// InitNormalTables' layout worked by hand: rows y = -44 .. 44 of 2 (44 - |y|) + 1 points x each, two codes
// per point (+z even, -z odd), from code 2. The points in the rows below y: 1 + 3 + ... for y <= 0, i.e.
// (y + 44)^2; for y > 0, 44^2 plus the rows 0 .. y - 1 of 89, 87, ... points: 89 y - y (y - 1).
int hand_code(int x, int y, bool negative_z) {
    const long before = y <= 0 ? long(y + 44) * long(y + 44) : 1936L + 89L * y - long(y) * long(y - 1);
    return int(2 + 2 * before + 2 * (44 - std::abs(y)) + 2 * x + (negative_z ? 1 : 0));
}

// A pixel's bytes (R, G, B, A): the renderer stores byte / 255.
std::array<int, 4> bytes_of(const PixelValue& p) {
    return {int(std::lround(p.rgba[0] * 255.0)), int(std::lround(p.rgba[1] * 255.0)), int(std::lround(p.rgba[2] * 255.0)),
            int(std::lround(p.rgba[3] * 255.0))};
}

// Front-to-back over, float, as VPCompAC1NB composites a column of samples (opacity a_n, colour c_n on 0..255).
struct Float32Column {
    float color = 0.0f, opacity = 0.0f;
    void add(float a, float c) {
        const float inv = 1.0f - opacity;
        color += c * a * inv;
        opacity += a * inv;
    }
};

using test::error_of;

// A u8 NRRD of `bytes` (x fastest).
void write_u8_nrrd(const test::TempDir& dir, const std::string& name, std::array<int, 3> dims, const std::vector<std::uint8_t>& bytes) {
    std::string text = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: " + std::to_string(dims[0]) + " " + std::to_string(dims[1]) +
                       " " + std::to_string(dims[2]) + "\nencoding: raw\n\n";
    text.append(bytes.begin(), bytes.end());
    dir.write(name, text);
}

// The minimal scene: one u8 volume, VolPack's inputs only.
json minimal_scene() {
    return json::parse(R"({
        "volume": {"source": "v.nrrd"},
        "image": {"width": 2, "height": 2},
        "render": {"profile": "volpack", "profile_options": {"scalar_table": {"ramp": [[0, 0.0], [255, 1.0]]}}}
    })");
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// The view: VPComputeViewTransform and FactorAffineView (vp_view.c)
// ------------------------------------------------------------------------------------------------

// No rotation, the default window [-0.5, 0.5]^3, dims (4, 5, 6), a 32 x 32 image. By hand: maxdim 6, the
// prematrix (i - n/2) / 6; the window x 2; the viewport X = 16 x + 16, Y = 16 y + 16, depth = 0.5 - 0.5 z.
// So X = 32 (i - 2) / 6 + 16 = 16/3 i + 16/3, Y = 32 (j - 2.5) / 6 + 16 = 16/3 j + 8/3,
// depth = 0.5 - (k - 3) / 6 = 1 - k / 6. The object x and y axes map to image directions with no depth:
// z is the principal axis; no shear; t = (1, 1); the warp is X = 16/3 (u - 1) + 16/3 = 16/3 u,
// Y = 16/3 (v - 1) + 8/3 = 16/3 v - 8/3; reverse_slice_order: p20 s_i + p21 s_j - p22 = 1/6 > 0, so false
// (slice 0 has depth 1, the front).
TEST(VolPack, FactorViewUnrotatedIsAxisZWithoutShear) {
    const View v = factor_view(VolPackSpec{}, {4, 5, 6}, 32, 32);
    const double third = 16.0 / 3.0;
    EXPECT_EQ(v.axis, 2);
    EXPECT_EQ(v.icount, 4);
    EXPECT_EQ(v.jcount, 5);
    EXPECT_EQ(v.kcount, 6);
    EXPECT_EQ(v.shear_i, 0.0);
    EXPECT_EQ(v.shear_j, 0.0);
    EXPECT_EQ(v.trans_i, 1.0);
    EXPECT_EQ(v.trans_j, 1.0);
    EXPECT_FALSE(v.reverse_slice_order);
    EXPECT_EQ(v.intermediate_width, 5);
    EXPECT_EQ(v.intermediate_height, 6);
    const double vm[3][4] = {{third, 0, 0, third}, {0, third, 0, 8.0 / 3.0}, {0, 0, -1.0 / 6.0, 1.0}};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(v.view_transform[r][c], vm[r][c], 1e-12) << r << " " << c;
    const double warp[3][3] = {{third, 0, 0}, {0, third, -8.0 / 3.0}, {0, 0, 1}};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.warp[r][c], warp[r][c], 1e-12) << r << " " << c;
    EXPECT_NEAR(v.depth_di, 0.0, 1e-15);
    EXPECT_NEAR(v.depth_dj, 0.0, 1e-15);
    EXPECT_NEAR(v.depth_dk, -1.0 / 6.0, 1e-15);
    EXPECT_NEAR(v.depth_000, 1.0, 1e-15);
    EXPECT_EQ(v.voxel_size, 1.0f);
    EXPECT_EQ(v.slice_dc_ratio, 1.0f);  // no depth cueing
}

// With L = 1 the correction 1 - (1 - q/255)^1 is q/255 itself: every entry is float(q / 255) (1 - (1 - a)
// is a to within 2^-54, far below float's half unit for every q / 255, whose bits repeat with period 8).
TEST(VolPack, FactorViewWithoutShearCorrectsNothing) {
    const View v = factor_view(VolPackSpec{}, {4, 5, 6}, 32, 32);
    for (int q = 0; q <= 255; ++q) EXPECT_EQ(v.opacity_correction[std::size_t(q)], float(q / 255.0)) << q;
}

// A quarter turn about y (VPLoadRotation: m00 = cos, m02 = -sin, m20 = sin, m22 = cos): eye
// (x_e, y_e, z_e) = (c x - s z, y, s x + c z), so the object x axis now points along the view: axis x,
// permuted (i, j, k) = (y, z, x), counts (5, 6, 4). pvm's columns are vm's y, z, x columns:
// p00 = 0, p01 = -16 s / 3, p10 = 16/3, p11 = 0, p02 = 16 c / 3, p12 = 0, so shear_i = 0 and
// shear_j = -(16/3)(16 c/3) / (256 s / 9) = -c / s: cos(pi/2) in double is 6.1e-17, not 0, and VolPack
// adds ceil((kcount - 1) |s_j|) = 1 row to the intermediate image (6 + 1 + 1 = 8). t_j = 1 - 3 s_j.
// The warp: X = -16 s/3 (v - t_j) + p03 with p03 = 32 (3 s - 2 c) / 6 + 16, Y = 16/3 (u - 1) + 8/3.
// Front: p20 s_i + p21 s_j - p22 = c^2 / (6 s) + s / 6 > 0: slice 0 (x = 0, eye z = -1/3, depth 5/6) first.
TEST(VolPack, FactorViewQuarterTurnAboutYMakesXThePrincipalAxis) {
    VolPackSpec spec;
    spec.rotate = {{VolPackSpec::Axis::Y, 90.0}};
    const View v = factor_view(spec, {4, 5, 6}, 32, 32);
    const double c = std::cos(90.0 * kPi / 180.0), s = std::sin(90.0 * kPi / 180.0);
    EXPECT_EQ(v.axis, 0);
    EXPECT_EQ(v.icount, 5);
    EXPECT_EQ(v.jcount, 6);
    EXPECT_EQ(v.kcount, 4);
    EXPECT_NEAR(v.shear_i, 0.0, 1e-30);
    EXPECT_NEAR(v.shear_j, -c / s, 1e-25);
    EXPECT_LT(v.shear_j, 0.0);
    EXPECT_FALSE(v.reverse_slice_order);
    EXPECT_EQ(v.intermediate_width, 5 + 1 + 0);
    EXPECT_EQ(v.intermediate_height, 6 + 1 + int(std::ceil(3 * std::fabs(-c / s))));
    EXPECT_EQ(v.intermediate_height, 8);
    EXPECT_EQ(v.trans_i, 1.0);
    EXPECT_NEAR(v.trans_j, 1.0 + 3 * c / s, 1e-15);
    const double p03 = 32.0 * (3 * s - 2 * c) / 6.0 + 16.0;
    EXPECT_NEAR(v.warp[0][0], 0.0, 1e-14);
    EXPECT_NEAR(v.warp[0][1], -16.0 * s / 3.0, 1e-14);
    EXPECT_NEAR(v.warp[0][2], p03 + 16.0 * s / 3.0 * (1.0 + 3 * c / s), 1e-12);  // 112/3
    EXPECT_NEAR(v.warp[0][2], 112.0 / 3.0, 1e-12);
    EXPECT_NEAR(v.warp[1][0], 16.0 / 3.0, 1e-14);
    EXPECT_NEAR(v.warp[1][1], 0.0, 1e-14);
    EXPECT_NEAR(v.warp[1][2], 8.0 / 3.0 - 16.0 / 3.0, 1e-12);
    EXPECT_NEAR(v.depth_dk, -s / 6.0, 1e-15);   // depth per object x
    EXPECT_NEAR(v.depth_000, 0.5 + (2 * s + 3 * c) / 6.0, 1e-15);
    EXPECT_EQ(v.voxel_size, 1.0f);
}

// 30 degrees about y: the z axis stays principal (its unit vector's normalised depth component
// c / sqrt(1024 s^2 + c^2) = 0.054 against the x axis' s / sqrt(1024 c^2 + s^2) = 0.018: the viewport's
// 32-pixel scale is inside vm). pvm = vm: p00 = 16 c/3, p02 = -16 s/3, p11 = 16/3, the rest of the
// top-left 2 x 3 block 0, so shear_i = p02 p11 / (p00 p11) = -tan 30, shear_j = 0. s_i < 0:
// t_i = 1 - s_i (6 - 1) = 1 + 5 tan 30; width 4 + 1 + ceil(5 tan 30) = 4 + 1 + ceil(2.887) = 8.
// L = sqrt(1 + tan^2) = 1 / cos 30. The warp's X offset p03 - p00 t_i = 16 + 16 (3 s - 2 c)/3 - 16 c/3
// (1 + 5 s / c) = 16 - 16 c - 32 s / 3. Front: p20 s_i - p22 = (-s/6)(-s/c) + c/6 = 1 / (6 c) > 0.
TEST(VolPack, FactorViewThirtyDegreesAboutYShearsByMinusTan30) {
    VolPackSpec spec;
    spec.rotate = {{VolPackSpec::Axis::Y, 30.0}};
    const View v = factor_view(spec, {4, 5, 6}, 32, 32);
    const double c = std::sqrt(3.0) / 2.0, s = 0.5, t = s / c;
    EXPECT_EQ(v.axis, 2);
    EXPECT_NEAR(v.shear_i, -t, 1e-14);
    EXPECT_NEAR(v.shear_j, 0.0, 1e-14);
    EXPECT_EQ(v.intermediate_width, 4 + 1 + int(std::ceil(5 * t)));
    EXPECT_EQ(v.intermediate_width, 8);
    EXPECT_EQ(v.intermediate_height, 6);
    EXPECT_NEAR(v.trans_i, 1.0 + 5 * t, 1e-14);
    EXPECT_EQ(v.trans_j, 1.0);
    EXPECT_FALSE(v.reverse_slice_order);
    EXPECT_NEAR(v.warp[0][0], 16.0 * c / 3.0, 1e-13);
    EXPECT_NEAR(v.warp[0][2], 16.0 - 16.0 * c - 32.0 * s / 3.0, 1e-12);
    EXPECT_NEAR(v.warp[1][1], 16.0 / 3.0, 1e-13);
    EXPECT_NEAR(v.warp[1][2], -8.0 / 3.0, 1e-12);
    EXPECT_NEAR(v.depth_di, -s / 6.0, 1e-15);
    EXPECT_NEAR(v.depth_dk, -c / 6.0, 1e-15);
    EXPECT_NEAR(v.depth_000, 0.5 + (2 * s + 3 * c) / 6.0, 1e-15);
    const double L = 1.0 / c;
    EXPECT_NEAR(v.voxel_size, L, 1e-7);
    EXPECT_EQ(v.opacity_correction[0], 0.0f);
    EXPECT_EQ(v.opacity_correction[255], 1.0f);
    for (int q = 0; q <= 255; ++q)
        EXPECT_NEAR(v.opacity_correction[std::size_t(q)], 1.0 - std::pow(1.0 - q / 255.0, L), 2e-7) << q;
    // More opaque than the uncorrected table: the ray crosses 1 / cos 30 voxels per slice.
    EXPECT_GT(v.opacity_correction[127], 127.0f / 255.0f);
}

// A half turn about y: eye z = -z, the viewer now sees slice k = 5 first: p22 = +1/6 and
// p20 s_i + p21 s_j - p22 = -1/6 + O(1e-33) < 0: reverse_slice_order.
TEST(VolPack, FactorViewHalfTurnReversesTheSliceOrder) {
    VolPackSpec spec;
    spec.rotate = {{VolPackSpec::Axis::Y, 180.0}};
    const View v = factor_view(spec, {4, 5, 6}, 32, 32);
    EXPECT_EQ(v.axis, 2);
    EXPECT_TRUE(v.reverse_slice_order);
    EXPECT_NEAR(v.depth_dk, 1.0 / 6.0, 1e-15);
    EXPECT_NEAR(v.depth_000, 0.0, 1e-15);  // 0.5 + c/2 at k = 0: the back
    EXPECT_NEAR(v.warp[0][0], -16.0 / 3.0, 1e-13);  // mirrored in x
}

// VP_CONCAT_MODE: right (VolPack's default) gives MODEL = Rx Ry for rotate [x 90, y 90], left Ry Rx. By
// hand Rx(90) = [[1,0,0],[0,0,1],[0,-1,0]] and Ry(90) = [[0,0,-1],[0,1,0],[1,0,0]] (the 3 x 3 blocks).
TEST(VolPack, ConcatModeOrdersTheRotations) {
    VolPackSpec spec;
    spec.rotate = {{VolPackSpec::Axis::X, 90.0}, {VolPackSpec::Axis::Y, 90.0}};
    const double right[3][3] = {{0, 0, -1}, {1, 0, 0}, {0, -1, 0}};
    const double left[3][3] = {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}};
    const View r = factor_view(spec, {4, 4, 4}, 16, 16);
    spec.concat_left = true;
    const View l = factor_view(spec, {4, 4, 4}, 16, 16);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            EXPECT_NEAR(r.model[i][j], right[i][j], 1e-15) << i << " " << j;
            EXPECT_NEAR(l.model[i][j], left[i][j], 1e-15) << i << " " << j;
        }
    // Right: eye z = row 2 . (x, y, z) = -y: the y axis is principal. Left: eye z = x: the x axis.
    EXPECT_EQ(r.axis, 1);
    EXPECT_EQ(l.axis, 0);
}

// A window [l, r] of width w scales the image by 1 / w: with [-1, 1] the volume is half the size
// (p00 = 16 * (2/2) / 4 = 4 instead of 8), and [0, 1] moves it by half the image to the left.
TEST(VolPack, WindowScalesAndShiftsTheImage) {
    VolPackSpec spec;
    const View unit = factor_view(spec, {4, 4, 4}, 32, 32);
    spec.window = {-1.0, 1.0, -1.0, 1.0, -1.0, 1.0};
    const View wide = factor_view(spec, {4, 4, 4}, 32, 32);
    spec.window = {0.0, 1.0, -0.5, 0.5, -0.5, 0.5};
    const View shifted = factor_view(spec, {4, 4, 4}, 32, 32);
    EXPECT_NEAR(unit.view_transform[0][0], 8.0, 1e-13);
    EXPECT_NEAR(wide.view_transform[0][0], 4.0, 1e-13);
    // X of voxel index i: unit 8 i (centre i = 2 at X 16); [0, 1]: 32 (i - 2)/4 * 2/1 - 16 + 16 = 8 i - 16.
    EXPECT_NEAR(unit.view_transform[0][3], 0.0, 1e-13);
    EXPECT_NEAR(shifted.view_transform[0][3], -16.0, 1e-13);
    EXPECT_NEAR(wide.view_transform[0][3], 8.0, 1e-13);  // 16 (i - 2) / 4 + 16
}

// ------------------------------------------------------------------------------------------------
// vp_linalg.c
// ------------------------------------------------------------------------------------------------

TEST(VolPack, RotationIsVPLoadRotation) {
    const Matrix4 x = rotation(VolPackSpec::Axis::X, 90.0), y = rotation(VolPackSpec::Axis::Y, 90.0),
                  z = rotation(VolPackSpec::Axis::Z, 90.0);
    // x: m11 = m22 = cos, m12 = sin, m21 = -sin; y: m00 = m22 = cos, m02 = -sin, m20 = sin; z: m01 = sin, m10 = -sin.
    const double ex[4][4] = {{1, 0, 0, 0}, {0, 0, 1, 0}, {0, -1, 0, 0}, {0, 0, 0, 1}};
    const double ey[4][4] = {{0, 0, -1, 0}, {0, 1, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 1}};
    const double ez[4][4] = {{0, 1, 0, 0}, {-1, 0, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            EXPECT_NEAR(x[i][j], ex[i][j], 1e-16) << i << j;
            EXPECT_NEAR(y[i][j], ey[i][j], 1e-16) << i << j;
            EXPECT_NEAR(z[i][j], ez[i][j], 1e-16) << i << j;
        }
    // 30 degrees: the entries themselves.
    const Matrix4 r = rotation(VolPackSpec::Axis::Y, 30.0);
    EXPECT_NEAR(r[0][0], std::sqrt(3.0) / 2.0, 1e-15);
    EXPECT_NEAR(r[0][2], -0.5, 1e-15);
    EXPECT_NEAR(r[2][0], 0.5, 1e-15);
    EXPECT_EQ(r[1][1], 1.0);
    EXPECT_EQ(r[3][3], 1.0);
    // Rotations about one axis add their angles, and R R^T = I.
    for (VolPackSpec::Axis a : {VolPackSpec::Axis::X, VolPackSpec::Axis::Y, VolPackSpec::Axis::Z}) {
        const Matrix4 ab = multiply(rotation(a, 25.0), rotation(a, 47.0)), sum = rotation(a, 72.0);
        Matrix4 rt{};
        const Matrix4 q = rotation(a, 47.0);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) rt[i][j] = q[j][i];
        const Matrix4 id = multiply(q, rt);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                EXPECT_NEAR(ab[i][j], sum[i][j], 1e-15);
                EXPECT_NEAR(id[i][j], i == j ? 1.0 : 0.0, 1e-15);
            }
    }
}

TEST(VolPack, MultiplyIsTheMatrixProduct) {
    const Matrix4 a = {{{1, 2, 0, 1}, {0, 1, 3, 0}, {2, 0, 1, 0}, {0, 0, 0, 1}}};
    const Matrix4 b = {{{0, 1, 0, 0}, {1, 0, 0, 2}, {0, 0, 2, 1}, {0, 0, 0, 1}}};
    // a b by hand: row 0: (2, 1, 0, 4 + 1); row 1: (1, 0, 6, 2 + 3); row 2: (0, 2, 2, 1); row 3: (0, 0, 0, 1).
    const double ab[4][4] = {{2, 1, 0, 5}, {1, 0, 6, 5}, {0, 2, 2, 1}, {0, 0, 0, 1}};
    const Matrix4 p = multiply(a, b);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) EXPECT_EQ(p[i][j], ab[i][j]) << i << j;
    // Associativity and the identity (small integers: exact).
    const Matrix4 c = {{{1, 0, 0, 3}, {0, 0, 1, 0}, {0, 1, 0, -1}, {0, 0, 0, 1}}};
    EXPECT_EQ(multiply(multiply(a, b), c), multiply(a, multiply(b, c)));
    EXPECT_EQ(multiply(identity(), a), a);
    EXPECT_EQ(multiply(a, identity()), a);
    // m v: a (1, 1, 1, 1) = the row sums (4, 4, 3, 1); a e_2 = column 2.
    EXPECT_EQ(multiply(a, Vector4{1, 1, 1, 1}), (Vector4{4, 4, 3, 1}));
    EXPECT_EQ(multiply(a, Vector4{0, 0, 1, 0}), (Vector4{0, 3, 1, 0}));
}

// vpSolveSystem4 replaces each right-hand side b by a^-1 b: for a rotation R^T b; for a scale and
// translation (x0 = (b0 - b3)/2, x1 = (b1 - 2 b3)/4, x2 = (b2 - 3 b3)/8, x3 = b3); false when singular.
TEST(VolPack, SolveSystemInvertsByHand) {
    const Matrix4 r = multiply(rotation(VolPackSpec::Axis::X, 35.0), rotation(VolPackSpec::Axis::Z, -70.0));
    Vector4 b1{0.0, 0.0, 1.0, 1.0}, b2{0.3, -0.2, 0.9, 1.0};
    const Vector4 o1 = b1, o2 = b2;
    ASSERT_TRUE(solve_system(r, {&b1, &b2}));
    for (int i = 0; i < 3; ++i) {
        double t1 = 0.0, t2 = 0.0;
        for (int k = 0; k < 3; ++k) {
            t1 += r[std::size_t(k)][std::size_t(i)] * o1[std::size_t(k)];
            t2 += r[std::size_t(k)][std::size_t(i)] * o2[std::size_t(k)];
        }
        EXPECT_NEAR(b1[std::size_t(i)], t1, 1e-14) << i;
        EXPECT_NEAR(b2[std::size_t(i)], t2, 1e-14) << i;
    }
    EXPECT_NEAR(b1[3], 1.0, 1e-15);
    const Matrix4 a = {{{2, 0, 0, 1}, {0, 4, 0, 2}, {0, 0, 8, 3}, {0, 0, 0, 1}}};
    Vector4 b{5.0, 6.0, 27.0, 1.0};
    ASSERT_TRUE(solve_system(a, {&b}));
    EXPECT_NEAR(b[0], 2.0, 1e-15);
    EXPECT_NEAR(b[1], 1.0, 1e-15);
    EXPECT_NEAR(b[2], 3.0, 1e-15);
    EXPECT_NEAR(b[3], 1.0, 1e-15);
    // A permutation with a sign: rows swapped, solved exactly.
    const Matrix4 p = {{{0, 1, 0, 0}, {-1, 0, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    Vector4 q{7.0, 3.0, -2.0, 1.0};
    ASSERT_TRUE(solve_system(p, {&q}));
    EXPECT_EQ(q, (Vector4{-3.0, 7.0, -2.0, 1.0}));
    Matrix4 singular = identity();
    singular[2] = singular[1];
    Vector4 s{1, 1, 1, 1};
    EXPECT_FALSE(solve_system(singular, {&s}));
}

// ------------------------------------------------------------------------------------------------
// The 13-bit normal code (vp_shade.c: InitNormalTables, vpNormalIndex, vpShadeTable's decoding)
// ------------------------------------------------------------------------------------------------

TEST(VolPack, NormalIndexOfTheAxesFollowsInitNormalTables) {
    // Row y = 0 starts after 44^2 = 1936 points: code 2 + 3872 = 3874 at x = -44, +z (x = 0) at 3874 + 88 = 3962.
    EXPECT_EQ(hand_code(0, 0, false), 3962);
    EXPECT_EQ(normal_index(0, 0, 1), 3962);
    EXPECT_EQ(normal_index(0, 0, -1), 3963);
    EXPECT_EQ(normal_index(1, 0, 0), 3962 + 88);   // x = 44
    EXPECT_EQ(normal_index(-1, 0, 0), 3962 - 88);  // x = -44
    EXPECT_EQ(normal_index(0, -1, 0), 2);          // row -44, one point, the first code
    EXPECT_EQ(normal_index(0, 1, 0), 7922);        // row 44: 2 + 2 (1936 + 89 * 44 - 44 * 43) = 7922
    EXPECT_EQ(hand_code(0, 44, false), 7922);
    EXPECT_EQ(kMaxNormal, 7923);                   // 2 + 2 * 3961 points - 1
    // (1, 1, 0) / sqrt 2: x = y = 22; (1, -1, -1): x = 14.67 -> 15, y = -15, nz < 0.
    EXPECT_EQ(normal_index(std::sqrt(0.5), std::sqrt(0.5), 0.0), hand_code(22, 22, false));
    EXPECT_EQ(normal_index(1, 1, 0), 6954);
    EXPECT_EQ(normal_index(1.0, -1.0, -1.0), hand_code(15, -15, true));
    EXPECT_EQ(normal_index(-0.2, 0.3, 0.5), hand_code(-9, 13, false));  // -8.8 -> -9, 13.2 -> 13
}

// Debian's library rounds 44 n / L1 with rint (ties to even), where the 1.0b3 sources truncate.
TEST(VolPack, NormalIndexRoundsTiesToEven) {
    // L1 = 44: the coordinates are the given numbers themselves.
    EXPECT_EQ(normal_index(2.5, 0.0, 41.5), hand_code(2, 0, false));    // tie: 2 (truncation 2 too)
    EXPECT_EQ(normal_index(3.5, 0.0, 40.5), hand_code(4, 0, false));    // tie: 4 (truncation 3)
    EXPECT_EQ(normal_index(-2.5, 0.0, 41.5), hand_code(-2, 0, false));  // tie: -2
    EXPECT_EQ(normal_index(-3.5, 0.0, -40.5), hand_code(-4, 0, true));  // tie: -4, -z
    EXPECT_EQ(normal_index(0.0, 1.5, 42.5), hand_code(0, 2, false));    // tie in y: 2 (truncation 1)
    EXPECT_EQ(normal_index(0.0, -0.5, 43.5), hand_code(0, 0, false));   // tie: 0
    EXPECT_EQ(normal_index(2.6, 0.0, 41.4), hand_code(3, 0, false));    // 2.6 -> 3 (truncation 2)
    EXPECT_EQ(normal_index(0.0, -7.7, 36.3), hand_code(0, -8, false));  // -7.7 -> -8 (truncation -7)
}

// Decoding: code -> (px, py, +-(44 - |px| - |py|)) normalised; codes 0 and 1 the zero vector; every code
// off the equator's odd ones (which no normal produces: their nz = -0 is not < 0) is encoded back to itself.
TEST(VolPack, CodeNormalIsTheOctahedronPoint) {
    auto near3 = [](const std::array<double, 3>& a, double x, double y, double z) {
        const double l = std::sqrt(x * x + y * y + z * z);
        EXPECT_NEAR(a[0], x / l, 1e-15);
        EXPECT_NEAR(a[1], y / l, 1e-15);
        EXPECT_NEAR(a[2], z / l, 1e-15);
    };
    near3(code_normal(3962), 0, 0, 1);
    near3(code_normal(3963), 0, 0, -1);
    near3(code_normal(4050), 1, 0, 0);
    near3(code_normal(2), 0, -1, 0);
    near3(code_normal(7922), 0, 1, 0);
    near3(code_normal(hand_code(22, -10, false)), 22, -10, 12);
    near3(code_normal(hand_code(-5, 30, true)), -5, 30, -9);
    for (int code : {0, 1}) EXPECT_EQ(code_normal(code), (std::array<double, 3>{0.0, 0.0, 0.0}));
    int checked = 0;
    for (int y = -44; y <= 44; ++y)
        for (int x = -(44 - std::abs(y)); x <= 44 - std::abs(y); ++x)
            for (bool neg : {false, true}) {
                const int code = hand_code(x, y, neg);
                const bool equator = 44 - std::abs(x) - std::abs(y) == 0;
                if (equator && neg) continue;
                const std::array<double, 3> n = code_normal(code);
                ASSERT_EQ(normal_index(n[0], n[1], n[2]), code) << x << " " << y << " " << neg;
                ++checked;
            }
    EXPECT_EQ(checked, 3961 + 3961 - 4 * 44);  // the equator |x| + |y| = 44 has 4 * 44 points
}

// The quantisation error of a unit normal n: its octahedron point p = 44 n / L1 and the code's point q
// differ by at most 0.5 in x and y and 1 in z, |p - q| <= sqrt(1.5), and |p| >= 44 / sqrt(3) (a face's
// centre), so the angle is at most asin(sqrt(1.5) sqrt(3) / 44) = 2.76 degrees (the notes' "about 1.3
// degrees between codes" is the typical spacing, not this bound).
TEST(VolPack, NormalIndexQuantisesWithinTheCellBound) {
    std::mt19937_64 rng(55);
    std::normal_distribution<double> g(0.0, 1.0);
    const double bound = std::asin(std::sqrt(1.5) * std::sqrt(3.0) / 44.0);
    double worst = 0.0, sum = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        double v[3] = {g(rng), g(rng), g(rng)};
        const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (double& c : v) c /= l;
        const std::array<double, 3> q = code_normal(normal_index(v[0], v[1], v[2]));
        const double angle = std::acos(std::min(1.0, v[0] * q[0] + v[1] * q[1] + v[2] * q[2]));
        worst = std::max(worst, angle);
        sum += angle;
        ASSERT_LE(angle, bound) << v[0] << " " << v[1] << " " << v[2];
    }
    EXPECT_GT(worst, 0.01 * kPi / 180.0);   // a quantisation, not the identity
    EXPECT_LT(sum / n, 1.3 * kPi / 180.0);  // the typical error is below the notes' 1.3 degrees
}

// ------------------------------------------------------------------------------------------------
// vpVolumeNormals / vpScanlineNormals
// ------------------------------------------------------------------------------------------------

// f = 3x + 2y on 5 x 5 x 5: every interior voxel has Delta = (6, 4, 0), |Delta| / 2 = sqrt(13) = 3.606 -> 4,
// n = (6, 4, 0) / sqrt 52, L1 = 10 / sqrt 52: x = rint(26.4) = 26, y = rint(17.6) = 18 (at row 18's limit 26).
// The boundary voxels (any index 0 or 4) get gradient 0 and code 0.
TEST(VolPack, VolumeNormalsOfALinearRamp) {
    const Volume v = u8_volume({5, 5, 5}, [](std::int64_t x, std::int64_t y, std::int64_t) { return int(3 * x + 2 * y); });
    std::vector<std::uint8_t> s(125);
    for (std::size_t i = 0; i < 125; ++i) s[i] = std::uint8_t(v.values[i]);
    const VoxelNormals n = volume_normals(s.data(), v.dims, true);
    const int code = hand_code(26, 18, false);
    EXPECT_EQ(code, 6570);
    int interior = 0;
    for (std::int64_t z = 0; z < 5; ++z)
        for (std::int64_t y = 0; y < 5; ++y)
            for (std::int64_t x = 0; x < 5; ++x) {
                const std::size_t i = v.index(x, y, z);
                const bool inside = x > 0 && x < 4 && y > 0 && y < 4 && z > 0 && z < 4;
                EXPECT_EQ(n.gradient[i], inside ? 4 : 0) << x << y << z;
                EXPECT_EQ(n.code[i], inside ? code : 0) << x << y << z;
                if (inside) {
                    EXPECT_EQ(n.delta[i], (std::array<std::int16_t, 3>{6, 4, 0}));
                    ++interior;
                }
            }
    EXPECT_EQ(interior, 27);
}

// One interior voxel (3 x 3 x 3) with Delta = (3, 4, 0): |Delta| / 2 = 2.5 -> 2 (ties to even; rounding half
// up would give 3); Delta = (2, 3, 6): 3.5 -> 4 (truncation would give 3). Codes: (3, 4, 0)/5, L1 = 7/5:
// x = rint(18.86) = 19, y = rint(25.14) = 25; (2, 3, 6)/7, L1 = 11/7: x = 8, y = 12, z > 0.
TEST(VolPack, VolumeNormalsRoundTheHalfGradientToEven) {
    struct Case {
        int dx, dy, dz, gradient, code;
    };
    for (const Case& c : {Case{3, 4, 0, 2, hand_code(19, 25, false)}, Case{2, 3, 6, 4, hand_code(8, 12, false)},
                          Case{-2, 0, 0, 1, hand_code(-44, 0, false)}}) {
        // f = 10 + the differences on the centre's +-x, +-y, +-z neighbours, 10 elsewhere.
        const Volume v = u8_volume({3, 3, 3}, [&](std::int64_t x, std::int64_t y, std::int64_t z) {
            int f = 10;
            if (y == 1 && z == 1 && x == 2) f += c.dx;
            if (x == 1 && z == 1 && y == 2) f += c.dy;
            if (x == 1 && y == 1 && z == 2) f += c.dz;
            return f;
        });
        std::vector<std::uint8_t> s(27);
        for (std::size_t i = 0; i < 27; ++i) s[i] = std::uint8_t(v.values[i]);
        const VoxelNormals n = volume_normals(s.data(), v.dims, false);
        const std::size_t centre = v.index(1, 1, 1);
        EXPECT_EQ(n.gradient[centre], c.gradient) << c.dx << c.dy << c.dz;
        EXPECT_EQ(n.code[centre], c.code) << c.dx << c.dy << c.dz;
        for (std::size_t i = 0; i < 27; ++i) {
            if (i != centre) {
                EXPECT_EQ(n.code[i], 0);
            }
        }
    }
}

TEST(VolPack, VolumeNormalsOfAConstantVolumeAreZero) {
    std::vector<std::uint8_t> s(6 * 5 * 4, 77);
    const VoxelNormals n = volume_normals(s.data(), {6, 5, 4}, false);
    for (std::size_t i = 0; i < s.size(); ++i) {
        EXPECT_EQ(n.code[i], 0);
        EXPECT_EQ(n.gradient[i], 0);
    }
}

// ------------------------------------------------------------------------------------------------
// vpShadeTable
// ------------------------------------------------------------------------------------------------

TEST(VolPack, ShadeTableUnshadedIsWhite) {
    VolPackSpec spec;
    spec.channels = 3;
    const std::vector<float> t = shade_table(spec, identity());
    ASSERT_EQ(t.size(), std::size_t(7924 * 3));
    for (float e : t) ASSERT_EQ(e, 255.0f);
}

// One light along +z, identity model, the default material (0.1, 0.4, 0.5, shininess 10): V = (0, 0, 1) = L,
// H = (0, 0, 1); the +z normal is exterior (n.V = 1 >= 0) with n.L = n.H = 1: 25.5 + 102 + 127.5 = 255.
// -z faces away: interior, -n.L = -n.H = 1: 255 too (one material for both sides). Diffuse 0.6: 306, clamped.
TEST(VolPack, ShadeTableOneLightAlongZ) {
    VolPackSpec spec;
    spec.shaded = true;
    spec.lights = std::vector<VolPackLight>{VolPackLight{{0.0, 0.0, 2.0}, glm::dvec3(1.0)}};  // normalised by VolPack
    std::vector<float> t = shade_table(spec, identity());
    EXPECT_FLOAT_EQ(t[3962], 255.0f);
    EXPECT_FLOAT_EQ(t[3963], 255.0f);
    EXPECT_FLOAT_EQ(t[0], 25.5f);
    EXPECT_FLOAT_EQ(t[1], 25.5f);
    // +x: exterior (n.V = 0), n.L = 0, n.H = 0: ambient only.
    EXPECT_FLOAT_EQ(t[4050], 25.5f);
    spec.diffuse = glm::dvec3(0.6);
    t = shade_table(spec, identity());
    EXPECT_EQ(t[3962], 255.0f);
    float raw = 0.0f;
    VolPackSpec unclamped = spec;
    unclamped.diffuse = glm::dvec3(0.2);
    shade_normal(unclamped, identity(), {0.0, 0.0, 1.0}, &raw);
    EXPECT_FLOAT_EQ(raw, 25.5f + 51.0f + 127.5f);  // 204: below 255, no clamp
    // Three channels: each its own material.
    spec.channels = 3;
    spec.ambient = {0.1, 0.2, 0.3};
    spec.diffuse = {0.1, 0.1, 0.1};
    spec.specular = {0.0, 0.1, 0.2};
    t = shade_table(spec, identity());
    EXPECT_FLOAT_EQ(t[1 * 3 + 1], 51.0f);  // code 1, green: the ambient
    EXPECT_FLOAT_EQ(t[3962 * 3 + 0], 25.5f + 25.5f);
    EXPECT_FLOAT_EQ(t[3962 * 3 + 1], 51.0f + 25.5f + 25.5f);
    EXPECT_FLOAT_EQ(t[3962 * 3 + 2], 76.5f + 25.5f + 51.0f);
}

// The side rule with the light along +x: V = +z, L = +x, H = (1, 0, 1) / sqrt 2, (n.H)^10 = 1/32 where n.H = 1/sqrt 2.
//   +z: exterior, n.L = 0, n.H = 1/sqrt 2: 25.5 + 127.5 / 32 = 29.484375
//   +x: exterior (n.V = 0), n.L = 1: 25.5 + 102 + 3.984375 = 131.484375
//   -x: exterior, n.L = -1, n.H < 0: both clamped to 0: 25.5; two-sided: |n.L| = 1, |n.H|: 131.484375
//   -z: interior (n.V = -1): -n.L = 0, -n.H = 1/sqrt 2: 29.484375
TEST(VolPack, ShadeTableSideRule) {
    VolPackSpec spec;
    spec.shaded = true;
    spec.lights = std::vector<VolPackLight>{VolPackLight{{1.0, 0.0, 0.0}, glm::dvec3(1.0)}};
    const std::vector<float> t = shade_table(spec, identity());
    EXPECT_FLOAT_EQ(t[3962], 29.484375f);
    EXPECT_FLOAT_EQ(t[4050], 131.484375f);
    EXPECT_FLOAT_EQ(t[3874], 25.5f);
    EXPECT_FLOAT_EQ(t[3963], 29.484375f);
    spec.two_sided = true;
    const std::vector<float> two = shade_table(spec, identity());
    EXPECT_FLOAT_EQ(two[3874], 131.484375f);
    EXPECT_FLOAT_EQ(two[4050], 131.484375f);
    EXPECT_FLOAT_EQ(two[3962], 29.484375f);
    // A light's colour scales its terms (not the ambient): red 0.5 on +x: 25.5 + 0.5 (102 + 3.984375).
    spec.two_sided = false;
    spec.lights = std::vector<VolPackLight>{VolPackLight{{1.0, 0.0, 0.0}, glm::dvec3(0.5)}};
    EXPECT_FLOAT_EQ(shade_table(spec, identity())[4050], 25.5f + 0.5f * 105.984375f);
}

// The lights and the viewer are brought into object space by MODEL^-1 (vpShadeTable): after a quarter
// turn about y, V = R^T (0, 0, 1) = (R20, R21, R22) = (1, 0, 0) and a light set along eye +z is object +x.
// Material (0.1, 0.2, 0.3): +x gets 25.5 + 51 + 76.5 = 153; +z (n.V = cos 90 = 6e-17 >= 0: exterior,
// n.L = n.H = 0 to 1e-16): 25.5.
TEST(VolPack, ShadeTableLightsAreBroughtIntoObjectSpace) {
    VolPackSpec spec;
    spec.shaded = true;
    spec.diffuse = glm::dvec3(0.2);
    spec.specular = glm::dvec3(0.3);
    spec.lights = std::vector<VolPackLight>{VolPackLight{{0.0, 0.0, 1.0}, glm::dvec3(1.0)}};
    const std::vector<float> t = shade_table(spec, rotation(VolPackSpec::Axis::Y, 90.0));
    EXPECT_FLOAT_EQ(t[4050], 153.0f);
    EXPECT_FLOAT_EQ(t[3962], 25.5f);
    // -x: n.V = -1, interior, lit through -n: -n.L = -n.H = 1: 153 as well.
    EXPECT_FLOAT_EQ(t[3874], 153.0f);
    // The default light (0.57735, 0.57735, 0.57735) and the table's entries at the codes' own normals.
    VolPackSpec d;
    d.shaded = true;
    const Matrix4 m = multiply(rotation(VolPackSpec::Axis::X, 20.0), rotation(VolPackSpec::Axis::Y, -35.0));
    const std::vector<float> td = shade_table(d, m);
    for (int code : {2, 3, 3962, 3963, 4050, 6954, hand_code(-5, 30, true), 7922, 7923}) {
        float e = 0.0f;
        shade_normal(d, m, code_normal(code), &e);
        EXPECT_FLOAT_EQ(td[std::size_t(code)], e) << code;
    }
}

// ------------------------------------------------------------------------------------------------
// VPComputeWarpTables, VPClassifyVoxel
// ------------------------------------------------------------------------------------------------

TEST(VolPack, WarpWeightsAreTheBilinearTable) {
    const auto& t = warp_weights();
    EXPECT_EQ(t[0][0], (std::array<float, 4>{1.0f, 0.0f, 0.0f, 0.0f}));
    EXPECT_EQ(t[0][63], (std::array<float, 4>{0.0f, 1.0f, 0.0f, 0.0f}));  // x = 63 / 63
    EXPECT_EQ(t[63][0], (std::array<float, 4>{0.0f, 0.0f, 1.0f, 0.0f}));
    EXPECT_EQ(t[63][63], (std::array<float, 4>{0.0f, 0.0f, 0.0f, 1.0f}));
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const auto& w = t[std::size_t(y)][std::size_t(x)];
            const double fx = x / 63.0, fy = y / 63.0;
            EXPECT_NEAR(w[0], (1 - fx) * (1 - fy), 1e-7);
            EXPECT_NEAR(w[1], fx * (1 - fy), 1e-7);
            EXPECT_NEAR(w[2], (1 - fx) * fy, 1e-7);
            EXPECT_NEAR(w[3], fx * fy, 2e-7);
            EXPECT_NEAR(double(w[0]) + w[1] + w[2] + w[3], 1.0, 1e-7);
        }
    // The middle index 32 is 32/63, not 1/2: the table's fractions are index / 63.
    EXPECT_NEAR(t[0][32][1], 32.0 / 63.0, 1e-7);
}

TEST(VolPack, ClassifyVoxelTruncatesAndThresholds) {
    VolPackSpec spec = constant_spec(0.0f);
    spec.scalar_table.entries[10] = 0.5f;
    spec.scalar_table.entries[20] = 1.0f;
    spec.scalar_table.entries[30] = 0.7f;
    const View v = factor_view(spec, {4, 4, 4}, 8, 8);
    VoxelClass c = classify_voxel(spec, v, 10, 0);
    EXPECT_EQ(c.opacity, 0.5f);
    EXPECT_TRUE(c.kept);
    EXPECT_EQ(c.opacity_byte, 127);  // (int)(127.5): truncated
    EXPECT_EQ(c.corrected, float(127 / 255.0));
    EXPECT_EQ(classify_voxel(spec, v, 20, 0).opacity_byte, 255);
    EXPECT_EQ(classify_voxel(spec, v, 30, 0).opacity_byte, 178);  // float(0.7) * 255 = 178.49999
    c = classify_voxel(spec, v, 0, 0);
    EXPECT_FALSE(c.kept);  // 0 > 0 is false
    EXPECT_EQ(c.corrected, 0.0f);
    // The threshold is strict: opacity 0.5 is not > 0.5.
    spec.min_voxel_opacity = 0.5;
    c = classify_voxel(spec, v, 10, 0);
    EXPECT_FALSE(c.kept);
    EXPECT_EQ(c.corrected, 0.0f);
    EXPECT_EQ(c.opacity_byte, 127);
    spec.min_voxel_opacity = -1.0;  // keeps every voxel, even transparent ones
    EXPECT_TRUE(classify_voxel(spec, v, 0, 0).kept);
    // The product of the tables: 0.5 * 0.5 = 0.25 -> (int)(63.75) = 63.
    spec.min_voxel_opacity = 0.0;
    spec.gradient_table = VolPackTable{};
    spec.gradient_table->entries.assign(256, 0.0f);
    spec.gradient_table->entries[7] = 0.5f;
    c = classify_voxel(spec, v, 10, 7);
    EXPECT_EQ(c.opacity, 0.25f);
    EXPECT_EQ(c.opacity_byte, 63);
    EXPECT_EQ(c.corrected, float(63 / 255.0));
    EXPECT_FALSE(classify_voxel(spec, v, 10, 6).kept);  // gradient entry 0
}

// ------------------------------------------------------------------------------------------------
// The renderer worked by hand
// ------------------------------------------------------------------------------------------------

// A 1 x 1 x 3 column, no rotation, a 3 x 3 image: maxdim 3, p00 = 1.5 * 2 / 3 = 1, p03 = 1.5 (2 (-1/2)/3) + 1.5
// = 1, so X = u (warp offset p03 - p00 t_i = 0): the column's intermediate pixel (1, 1) is output pixel
// (1, 1), exactly (fraction 0, weights (1, 0, 0, 0)). Each slice contributes its voxel with weight
// f_u f_v = 1 (slice_u = 1). Opacity 0.5 -> byte 127 -> a = 127/255, three slices: 1 - (1 - a)^3 =
// 0.8735 -> 222.75 -> 222, colour 255 times that (unshaded, premultiplied), 222. Every other pixel: 0.
TEST(VolPack, RendererColumnOfThreeSlices) {
    const Volume vol = u8_volume({1, 1, 3}, [](std::int64_t, std::int64_t, std::int64_t) { return 100; });
    const VolPackRenderer r(vol, constant_spec(0.5f), 3, 3);
    EXPECT_EQ(r.view().axis, 2);
    EXPECT_EQ(r.view().intermediate_width, 2);
    EXPECT_EQ(r.view().intermediate_height, 2);
    EXPECT_NEAR(r.view().warp[0][2], 0.0, 1e-15);
    EXPECT_NEAR(r.view().warp[1][2], 0.0, 1e-15);
    const float a = float(127 / 255.0);
    Float32Column col;
    for (int k = 0; k < 3; ++k) col.add(a, 255.0f);
    const double closed = 1.0 - std::pow(1.0 - 127.0 / 255.0, 3);
    EXPECT_NEAR(col.opacity, closed, 1e-6);
    EXPECT_NEAR(r.intermediate(1, 1).opacity, closed, 1e-6);
    EXPECT_EQ(r.intermediate(1, 1).opacity, col.opacity);
    EXPECT_EQ(r.intermediate(1, 1).color[0], col.color);
    EXPECT_EQ(r.intermediate(0, 0).opacity, 0.0f);
    const VolPackRenderer::Warp w = r.warp(1, 1);
    EXPECT_TRUE(w.covered);
    EXPECT_EQ(w.u, 1);
    EXPECT_EQ(w.v, 1);
    EXPECT_EQ(w.xfrac, 0);
    EXPECT_EQ(w.yfrac, 0);
    EXPECT_EQ(int(std::floor(closed * 255.0)), 222);
    EXPECT_EQ(bytes_of(r.pixel(1, 1, nullptr)), (std::array<int, 4>{222, 222, 222, 222}));
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 3; ++x) {
            if (x != 1 || y != 1) {
                EXPECT_EQ(bytes_of(r.pixel(x, y, nullptr)), (std::array<int, 4>{0, 0, 0, 0})) << x << y;
            }
        }
    // One slice (a 1 x 1 x 1 volume on a 1 x 1 image: p00 = 0.5 * 2 = 1, p03 = 0.5 (2 (-1/2)) + 0.5 = 0, X = u - 1):
    // a * 255 = 127 exactly (float(127/255) * 255 rounds to 127).
    const Volume one = u8_volume({1, 1, 1}, [](std::int64_t, std::int64_t, std::int64_t) { return 100; });
    EXPECT_EQ(bytes_of(VolPackRenderer(one, constant_spec(0.5f), 1, 1).pixel(0, 0, nullptr)), (std::array<int, 4>{127, 127, 127, 127}));
}

// Four columns of two voxels, opacities 0.2, 0.4, 0.6, 0.8 (bytes 51, 102, 153, 204: float(e) * 255 lies
// just above each), a 2 x 2 image: p00 = 1, X = u - 1, Y = v - 1: pixel (x, y) is column (x, y). Each
// pixel is 1 - (1 - a)^2: 0.36, 0.64, 0.84, 0.96 -> 91.8, 163.2, 214.2, 244.8 -> 91, 163, 214, 244.
TEST(VolPack, RendererMapsVoxelColumnsToPixels) {
    const Volume vol = u8_volume({2, 2, 2}, [](std::int64_t x, std::int64_t y, std::int64_t) { return int(10 + 10 * x + 20 * y); });
    VolPackSpec spec = constant_spec(0.0f);
    spec.scalar_table.entries[10] = 0.2f;
    spec.scalar_table.entries[20] = 0.4f;
    spec.scalar_table.entries[30] = 0.6f;
    spec.scalar_table.entries[40] = 0.8f;
    const VolPackRenderer r(vol, spec, 2, 2);
    const int expect[2][2] = {{91, 163}, {214, 244}};  // [y][x]
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            const double a = (1 + x + 2 * y) * 0.2;
            Float32Column col;
            col.add(float(a), 255.0f);
            col.add(float(a), 255.0f);
            EXPECT_NEAR(col.opacity, 1.0 - (1.0 - a) * (1.0 - a), 1e-6);
            EXPECT_EQ(int(col.opacity * 255.0f), expect[y][x]);
            const int b = expect[y][x];
            EXPECT_EQ(bytes_of(r.pixel(x, y, nullptr)), (std::array<int, 4>{b, b, b, b})) << x << " " << y;
            EXPECT_EQ(r.pixel(x, y, nullptr).error, 0.0);  // no byte near a rounding tie
        }
}

// max_ray_opacity 0.7: after two slices the opacity 0.748 >= 0.7 stops the ray: 1 - (1 - a)^2 with a = 127/255
// -> 190.75 -> 190 (instead of 222 with all three slices).
TEST(VolPack, RendererMaxRayOpacityStopsTheRay) {
    const Volume vol = u8_volume({1, 1, 3}, [](std::int64_t, std::int64_t, std::int64_t) { return 100; });
    VolPackSpec spec = constant_spec(0.5f);
    spec.max_ray_opacity = 0.7;
    const VolPackRenderer r(vol, spec, 3, 3);
    EXPECT_NEAR(r.intermediate(1, 1).opacity, 1.0 - std::pow(128.0 / 255.0, 2), 1e-6);
    EXPECT_EQ(bytes_of(r.pixel(1, 1, nullptr)), (std::array<int, 4>{190, 190, 190, 190}));
    spec.max_ray_opacity = 0.9;  // above 0.8735: all three slices
    EXPECT_EQ(bytes_of(VolPackRenderer(vol, spec, 3, 3).pixel(1, 1, nullptr))[3], 222);
}

// min_voxel_opacity drops voxels whose opacity is not above it (and samples whose resampled opacity is
// not): 0.2 with minimum 0.2 leaves nothing; with 0.19 all three slices: 1 - 0.8^3 = 0.488 -> 124.44 -> 124.
TEST(VolPack, RendererMinVoxelOpacityDropsVoxels) {
    const Volume vol = u8_volume({1, 1, 3}, [](std::int64_t, std::int64_t, std::int64_t) { return 100; });
    VolPackSpec spec = constant_spec(0.2f);
    spec.min_voxel_opacity = 0.2;
    EXPECT_EQ(bytes_of(VolPackRenderer(vol, spec, 3, 3).pixel(1, 1, nullptr)), (std::array<int, 4>{0, 0, 0, 0}));
    spec.min_voxel_opacity = 0.19;
    EXPECT_EQ(bytes_of(VolPackRenderer(vol, spec, 3, 3).pixel(1, 1, nullptr)), (std::array<int, 4>{124, 124, 124, 124}));
}

// Depth cueing (front 1, density 1.5) on the column: the slices' depths are 1, 2/3, 1/3 (depth = 1 - k/3),
// VolPack's fog front exp(-density (1 - depth)) = 1, e^-0.5, e^-1 on the slices' colours (the per-slice
// ratio), then the front slice's depth 1 quantised (255 / 255) gives the fix-up factor 1. Colour =
// 255 a (1 + (1 - a) e^-0.5 + (1 - a)^2 e^-1) = 177.44 -> 177; the opacity is not cued: 222.
// Front 2 doubles the colour: 354.9, clamped to 255.
TEST(VolPack, RendererDepthCueIsExponentialFog) {
    const Volume vol = u8_volume({1, 1, 3}, [](std::int64_t, std::int64_t, std::int64_t) { return 100; });
    VolPackSpec spec = constant_spec(0.5f);
    spec.depth_cue = std::array<double, 2>{1.0, 1.5};
    const VolPackRenderer r(vol, spec, 3, 3);
    EXPECT_NEAR(r.view().slice_dc_ratio, std::exp(-0.5), 1e-7);
    const double a = 127.0 / 255.0;
    const double color = 255 * a * (1 + (1 - a) * std::exp(-0.5) + (1 - a) * (1 - a) * std::exp(-1.0));
    EXPECT_NEAR(r.intermediate(1, 1).color[0], color, 1e-4);
    EXPECT_EQ(int(color), 177);
    EXPECT_EQ(bytes_of(r.pixel(1, 1, nullptr)), (std::array<int, 4>{177, 177, 177, 222}));
    spec.depth_cue = std::array<double, 2>{2.0, 1.5};
    EXPECT_EQ(bytes_of(VolPackRenderer(vol, spec, 3, 3).pixel(1, 1, nullptr)), (std::array<int, 4>{255, 255, 255, 222}));
}

// The same column seen from behind (rotate y 180): eye z = -(k - 1.5) / 3, so the slices' depths are
// 0.5 + (k - 1.5) / 3 = 0, 1/3, 2/3 for k = 0, 1, 2 (the volume's centre is at n / 2 = 1.5, not 1): the
// front slice is k = 2 at depth 2/3, composited first (reverse_slice_order). The per-slice ratio is
// exp(1.5 (-1/3)) again, and the fix-up factor is the front slice's, exp(-1.5 (1 - 170 / 255)) = e^-0.5:
// 177.44 e^-0.5 = 107.62 -> 107, alpha 222. X = 1.5 (2 e_x) + 1.5 with e_x = -(x - 0.5) / 3: the column
// (x = 0) is at X = 2, mirrored from pixel 1 to pixel 2.
TEST(VolPack, RendererDepthCueOfTheReversedView) {
    const Volume vol = u8_volume({1, 1, 3}, [](std::int64_t, std::int64_t, std::int64_t) { return 100; });
    VolPackSpec spec = constant_spec(0.5f);
    spec.depth_cue = std::array<double, 2>{1.0, 1.5};
    spec.rotate = {{VolPackSpec::Axis::Y, 180.0}};
    const VolPackRenderer r(vol, spec, 3, 3);
    EXPECT_TRUE(r.view().reverse_slice_order);
    EXPECT_NEAR(r.view().depth_000 + 2 * r.view().depth_dk, 2.0 / 3.0, 1e-15);
    const double a = 127.0 / 255.0;
    const double color = 255 * a * (1 + (1 - a) * std::exp(-0.5) + (1 - a) * (1 - a) * std::exp(-1.0)) * std::exp(-0.5);
    EXPECT_EQ(int(color), 107);
    EXPECT_EQ(bytes_of(r.pixel(2, 1, nullptr)), (std::array<int, 4>{107, 107, 107, 222}));
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 2; ++x) EXPECT_EQ(bytes_of(r.pixel(x, y, nullptr))[3], 0) << x << y;
}

// Shaded, three channels: every voxel of a 2 x 2 x 2 volume lies on the boundary (code 0), so each is
// its material's ambient (0.1, 0.2, 0.3) x 255 = (25.5, 51, 76.5); with the voxel opacity 0.8 (byte 204)
// and two slices, 0.96 of each: 24.48, 48.96, 73.44 -> 24, 48, 73; alpha 244.
TEST(VolPack, RendererShadesBoundaryVoxelsWithTheAmbient) {
    const Volume vol = u8_volume({2, 2, 2}, [](std::int64_t, std::int64_t, std::int64_t) { return 40; });
    VolPackSpec spec = constant_spec(0.8f);
    spec.shaded = true;
    spec.channels = 3;
    spec.ambient = {0.1, 0.2, 0.3};
    const VolPackRenderer r(vol, spec, 2, 2);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) EXPECT_EQ(bytes_of(r.pixel(x, y, nullptr)), (std::array<int, 4>{24, 48, 73, 244})) << x << y;
}

// The renderer's camera is VolPack's view: the ray of every pixel of a rotated view goes through that
// pixel's (X, Y) = (x, y) (pixel_of), and along the ray X and Y stay constant while the depth decreases
// (away from the viewer), on a volume placed off the origin with non-unit spacing.
TEST(VolPack, CameraRaysAreThePixels) {
    for (const bool placed : {false, true}) {
        Volume vol = u8_volume({6, 7, 8}, [](std::int64_t x, std::int64_t y, std::int64_t z) { return int(x + y + z); });
        if (placed) {
            vol.origin = {1.0, -2.0, 3.0};
            vol.spacing = {0.5, 0.25, 2.0};
        }
        VolPackSpec spec = constant_spec(0.3f);
        spec.rotate = {{VolPackSpec::Axis::Y, 30.0}, {VolPackSpec::Axis::X, 20.0}};
        const int W = 20, H = 16;
        const VolPackRenderer r(vol, spec, W, H);
        const Camera cam(r.camera(), W, H, vol.domain_min(), vol.domain_max());
        const Matrix4& vm = r.view().view_transform;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const Ray ray = cam.pixel_ray(x, y);
                ASSERT_EQ(r.pixel_of(ray), (std::array<int, 2>{x, y})) << x << " " << y << " placed " << placed;
                const glm::dvec3 d = ray.direction / vol.spacing;  // in voxel indices
                const double dX = vm[0][0] * d.x + vm[0][1] * d.y + vm[0][2] * d.z;
                const double dY = vm[1][0] * d.x + vm[1][1] * d.y + vm[1][2] * d.z;
                const double dD = vm[2][0] * d.x + vm[2][1] * d.y + vm[2][2] * d.z;
                ASSERT_NEAR(dX, 0.0, 1e-9);
                ASSERT_NEAR(dY, 0.0, 1e-9);
                ASSERT_LT(dD, 0.0);
                // And the origin is (x, y) itself, not just rounded to it.
                const glm::dvec3 i = (ray.origin - vol.origin) / vol.spacing;
                EXPECT_NEAR(vm[0][0] * i.x + vm[0][1] * i.y + vm[0][2] * i.z + vm[0][3], x, 1e-9);
                EXPECT_NEAR(vm[1][0] * i.x + vm[1][1] * i.y + vm[1][2] * i.z + vm[1][3], y, 1e-9);
            }
    }
}

// ------------------------------------------------------------------------------------------------
// The scene file
// ------------------------------------------------------------------------------------------------

// The minimal scene (one u8 volume, a ramp) parses to VolPack's defaults and renders the hand bytes: the 2 x 2
// x 2 volume of scalars 51, 102, 153, 204 per column (the ramp 0 -> 1 over 0 .. 255 gives float(q / 255),
// bytes q), pixel (x, y) = 1 - (1 - q/255)^2.
TEST(VolPack, MinimalSceneParsesAndRenders) {
    const test::TempDir dir("volpack");
    std::vector<std::uint8_t> bytes;
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) bytes.push_back(std::uint8_t(51 * (1 + x + 2 * y)));
    write_u8_nrrd(dir, "v.nrrd", {2, 2, 2}, bytes);
    const Scene s = parse_scene(minimal_scene().dump(), dir.path, "scene.json");
    ASSERT_EQ(s.render.profile, ProfileId::VolPack);
    ASSERT_TRUE(s.render.profile_options.volpack);
    const VolPackSpec& v = *s.render.profile_options.volpack;
    EXPECT_TRUE(v.rotate.empty());
    EXPECT_FALSE(v.concat_left);
    EXPECT_EQ(v.window, (std::array<double, 6>{-0.5, 0.5, -0.5, 0.5, -0.5, 0.5}));
    EXPECT_FALSE(v.gradient_table);
    EXPECT_FALSE(v.shaded);
    EXPECT_EQ(v.min_voxel_opacity, 0.0);
    EXPECT_EQ(v.max_ray_opacity, 1.0);
    EXPECT_FALSE(v.depth_cue);
    EXPECT_EQ(v.channels, 1);
    EXPECT_EQ(v.path, VolPackSpec::Path::Classified);
    EXPECT_FALSE(v.axis);
    ASSERT_EQ(v.scalar_table.entries.size(), 256u);
    // vpRamp: y += 1/255 from 0, in double: within a float's rounding of q / 255 (and above its 8-bit truncation).
    for (int q = 0; q < 256; ++q) EXPECT_NEAR(v.scalar_table.entries[std::size_t(q)], q / 255.0, 1e-7) << q;
    for (int q : {51, 102, 153, 204}) EXPECT_EQ(int(double(v.scalar_table.entries[std::size_t(q)]) * 255.0), q) << q;
    const Image im = render_scene(s, {.threads = 1});
    ASSERT_EQ(im.width, 2);
    ASSERT_EQ(im.height, 2);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            const double a = 51 * (1 + x + 2 * y) / 255.0;
            const int b = int(std::floor((1 - (1 - a) * (1 - a)) * 255.0));
            for (int c = 0; c < 4; ++c) EXPECT_NEAR(im.at(x, y, std::size_t(c)) * 255.0, b, 1e-9) << x << y << c;
        }
}

// scene_json writes every input; reading it back gives the same VolPackSpec and the same image bytes.
TEST(VolPack, SceneWriterRoundTrips) {
    const test::TempDir dir("volpack");
    std::vector<std::uint8_t> bytes;
    for (int z = 0; z < 9; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 7; ++x) {
                const double r = std::sqrt((x - 3.0) * (x - 3.0) + (y - 3.5) * (y - 3.5) + (z - 4.0) * (z - 4.0));
                bytes.push_back(std::uint8_t(std::clamp(250.0 - 55.0 * r, 0.0, 255.0)));
            }
    write_u8_nrrd(dir, "v.nrrd", {7, 8, 9}, bytes);
    json j = minimal_scene();
    j["image"] = {{"width", 24}, {"height", 20}};
    j["render"]["profile_options"] = json::parse(R"({
        "rotate": [["y", 30], ["x", -20], ["z", 10]],
        "concat": "left",
        "window": [-0.6, 0.5, -0.55, 0.6, -1, 1],
        "scalar_table": {"ramp": [[0, 0], [60, 0], [120, 0.6], [255, 0.9]]},
        "gradient_table": {"ramp": [[0, 0.2], [10, 1], [221, 1]]},
        "shading": {"material": {"ambient": [0.1, 0.15, 0.2], "diffuse": 0.45, "specular": [0.3, 0.2, 0.1], "shininess": 7},
                    "lights": [{"direction": [0.3, 0.3, 1]}, {"direction": [-1, 0.2, 0.5], "color": [0.5, 0.6, 0.7]}],
                    "two_sided": true},
        "min_voxel_opacity": 0.02,
        "max_ray_opacity": 0.95,
        "depth_cue": {"front": 1.2, "density": 0.8},
        "channels": 3,
        "path": "raw",
        "axis": "z"
    })");
    const Scene s = parse_scene(j.dump(), dir.path, "scene.json");
    const json written = scene_json(s);
    const Scene t = parse_scene(written.dump(), dir.path, "written.json");
    const VolPackSpec &a = *s.render.profile_options.volpack, &b = *t.render.profile_options.volpack;
    EXPECT_EQ(a.rotate, b.rotate);
    ASSERT_EQ(a.rotate.size(), 3u);
    EXPECT_TRUE(b.concat_left);
    EXPECT_EQ(a.window, b.window);
    EXPECT_EQ(a.scalar_table.entries, b.scalar_table.entries);
    EXPECT_EQ(a.scalar_table.ramp, b.scalar_table.ramp);
    ASSERT_TRUE(b.gradient_table);
    EXPECT_EQ(a.gradient_table->entries, b.gradient_table->entries);
    EXPECT_TRUE(b.shaded);
    EXPECT_EQ(a.ambient, b.ambient);
    EXPECT_EQ(a.diffuse, b.diffuse);
    EXPECT_EQ(a.specular, b.specular);
    EXPECT_EQ(a.shininess, b.shininess);
    ASSERT_TRUE(b.lights);
    ASSERT_EQ(b.lights->size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ((*a.lights)[i].direction, (*b.lights)[i].direction);
        EXPECT_EQ((*a.lights)[i].color, (*b.lights)[i].color);
    }
    EXPECT_TRUE(b.two_sided);
    EXPECT_EQ(a.min_voxel_opacity, b.min_voxel_opacity);
    EXPECT_EQ(a.max_ray_opacity, b.max_ray_opacity);
    EXPECT_EQ(a.depth_cue, b.depth_cue);
    EXPECT_EQ(b.channels, 3);
    EXPECT_EQ(b.path, VolPackSpec::Path::Raw);
    ASSERT_TRUE(b.axis);
    EXPECT_EQ(*b.axis, VolPackSpec::Axis::Z);
    EXPECT_EQ(s.image.width, t.image.width);
    EXPECT_EQ(s.image.height, t.image.height);
    const Image x = render_scene(s, {.threads = 1}), y = render_scene(t, {.threads = 1});
    EXPECT_EQ(x.channels, y.channels);
    EXPECT_EQ(x.pixels, y.pixels);
    double total = 0.0;
    for (double p : x.pixels) total += p;
    EXPECT_GT(total, 1.0);  // the blob is in view
    // The variants are written too.
    json k = j;
    k["render"]["profile_options"]["warp_weights"] = "exact";
    k["render"]["profile_options"]["normal_code"] = "exact";
    k["render"]["profile_options"]["correction_order"] = "sample";
    const Scene u = parse_scene(scene_json(parse_scene(k.dump(), dir.path, "k.json")).dump(), dir.path, "k2.json");
    EXPECT_EQ(u.render.profile_options.volpack->warp_weights, VolPackSpec::WarpWeights::Exact);
    EXPECT_EQ(u.render.profile_options.volpack->normal_code, VolPackSpec::NormalCode::Exact);
    EXPECT_EQ(u.render.profile_options.volpack->correction_order, VolPackSpec::CorrectionOrder::Sample);
}

// Each bad input is refused with one line naming its key, at parse time or (the volume's type, an edge-on
// axis override) when the render is set up.
TEST(VolPack, BadInputsNameTheirKey) {
    const test::TempDir dir("volpack");
    write_u8_nrrd(dir, "v.nrrd", {3, 3, 3}, std::vector<std::uint8_t>(27, 100));
    {
        std::string text = "NRRD0004\ntype: unsigned short\ndimension: 3\nsizes: 3 3 3\nendian: little\nencoding: raw\n\n";
        text.append(std::string(54, '\x01'));
        dir.write("u16.nrrd", text);
    }
    const std::string po = "render.profile_options.";
    struct Case {
        std::string what, key;
        std::function<void(json&)> edit;
        bool at_render = false;
    };
    auto opt = [](json& j) -> json& { return j["render"]["profile_options"]; };
    const std::vector<Case> cases = {
        {"255 entries", po + "scalar_table", [&](json& j) { opt(j)["scalar_table"] = std::vector<double>(255, 0.5); }},
        {"an entry 1.5", po + "scalar_table[3]",
         [&](json& j) {
             std::vector<double> t(256, 0.5);
             t[3] = 1.5;
             opt(j)["scalar_table"] = t;
         }},
        {"ramp from 1", po + "scalar_table.ramp[0][0]", [&](json& j) { opt(j)["scalar_table"] = json::parse(R"({"ramp": [[1, 0], [255, 1]]})"); }},
        {"ramp to 200", po + "scalar_table.ramp[1]", [&](json& j) { opt(j)["scalar_table"] = json::parse(R"({"ramp": [[0, 0], [200, 1]]})"); }},
        {"ramp x repeated", po + "scalar_table.ramp[2][0]",
         [&](json& j) { opt(j)["scalar_table"] = json::parse(R"({"ramp": [[0, 0], [100, 0.5], [100, 0.7], [255, 1]]})"); }},
        {"ramp y 2", po + "scalar_table.ramp[1][1]", [&](json& j) { opt(j)["scalar_table"] = json::parse(R"({"ramp": [[0, 0], [255, 2]]})"); }},
        {"gradient ramp to 255", po + "gradient_table.ramp[1][0]",
         [&](json& j) { opt(j)["gradient_table"] = json::parse(R"({"ramp": [[0, 0], [255, 1]]})"); }},
        {"gradient ramp to 200", po + "gradient_table.ramp[1]",
         [&](json& j) { opt(j)["gradient_table"] = json::parse(R"({"ramp": [[0, 0], [200, 1]]})"); }},
        {"left >= right", po + "window[1]", [&](json& j) { opt(j)["window"] = {0.5, 0.5, -0.5, 0.5, -0.5, 0.5}; }},
        {"bottom >= top", po + "window[3]", [&](json& j) { opt(j)["window"] = {-0.5, 0.5, 0.6, 0.5, -0.5, 0.5}; }},
        {"near >= far", po + "window[5]", [&](json& j) { opt(j)["window"] = {-0.5, 0.5, -0.5, 0.5, 0.5, -0.5}; }},
        {"window of 5", po + "window", [&](json& j) { opt(j)["window"] = {-0.5, 0.5, -0.5, 0.5, -0.5}; }},
        {"channels 2", po + "channels", [&](json& j) { opt(j)["channels"] = 2; }},
        {"channels 4", po + "channels", [&](json& j) { opt(j)["channels"] = 4; }},
        {"max_ray_opacity 0", po + "max_ray_opacity", [&](json& j) { opt(j)["max_ray_opacity"] = 0; }},
        {"max_ray_opacity 1.5", po + "max_ray_opacity", [&](json& j) { opt(j)["max_ray_opacity"] = 1.5; }},
        {"min_voxel_opacity 2", po + "min_voxel_opacity", [&](json& j) { opt(j)["min_voxel_opacity"] = 2; }},
        // vpSetd takes [0, 1] or exactly -1
        {"min_voxel_opacity -0.5", po + "min_voxel_opacity", [&](json& j) { opt(j)["min_voxel_opacity"] = -0.5; }},
        {"depth cue front 0", po + "depth_cue.front", [&](json& j) { opt(j)["depth_cue"] = {{"front", 0}}; }},
        {"7 lights", po + "shading.lights",
         [&](json& j) { opt(j)["shading"] = {{"lights", json::array()}};
             for (int i = 0; i < 7; ++i) opt(j)["shading"]["lights"].push_back({{"direction", {0, 0, 1}}}); }},
        {"zero light", po + "shading.lights[0].direction",
         [&](json& j) { opt(j)["shading"] = json::parse(R"({"lights": [{"direction": [0, 0, 0]}]})"); }},
        {"light colour 2", po + "shading.lights[0].color",
         [&](json& j) { opt(j)["shading"] = json::parse(R"({"lights": [{"direction": [0, 0, 1], "color": [2, 1, 1]}]})"); }},
        {"negative ambient", po + "shading.material.ambient", [&](json& j) { opt(j)["shading"] = json::parse(R"({"material": {"ambient": -0.1}})"); }},
        {"unknown key", po + "bogus", [&](json& j) { opt(j)["bogus"] = 1; }},
        {"unknown shading key", po + "shading.colour", [&](json& j) { opt(j)["shading"] = {{"colour", 1}}; }},
        {"rotate axis w", po + "rotate[0][0]", [&](json& j) { opt(j)["rotate"] = json::parse(R"([["w", 30]])"); }},
        {"rotate not a pair", po + "rotate[0]", [&](json& j) { opt(j)["rotate"] = json::parse(R"([["y"]])"); }},
        {"axis w", po + "axis", [&](json& j) { opt(j)["axis"] = "w"; }},
        {"path other", po + "path", [&](json& j) { opt(j)["path"] = "octree"; }},
        {"no scalar_table", po + "scalar_table", [&](json& j) { opt(j).erase("scalar_table"); }},
        {"no profile_options", "render.profile_options", [&](json& j) { j["render"].erase("profile_options"); }},
        {"render.step", "render.step", [&](json& j) { j["render"]["step"] = 0.5; }},
        {"render.projection", "render.projection", [&](json& j) { j["render"]["projection"] = "mip"; }},
        {"volume.transfer", "volume.transfer", [&](json& j) { j["volume"]["transfer"] = json::parse(R"({"opacity": [[0, 0], [255, 1]]})"); }},
        {"volume.spacing", "volume.spacing", [&](json& j) { j["volume"]["spacing"] = {1, 1, 2}; }},
        {"camera", "camera", [&](json& j) { j["camera"] = json::parse(R"({"type": "orthographic", "eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "height": 2})"); }},
        {"lights", "lights", [&](json& j) { j["lights"] = json::array(); }},
        {"background", "image.background", [&](json& j) { j["image"]["background"] = {0, 0, 0, 1}; }},
        {"two volumes", "volumes",
         [&](json& j) {
             j["volumes"] = json::array({j["volume"], j["volume"]});
             j.erase("volume");
         }},
        {"u16 volume", "volume.source", [&](json& j) { j["volume"]["source"] = "u16.nrrd"; }, true},
        {"axis x seen edge-on", po + "axis", [&](json& j) { opt(j)["axis"] = "x"; }, true},
        {"rotated, axis z seen edge-on", po + "axis",
         [&](json& j) {
             opt(j)["rotate"] = json::parse(R"([["x", 90]])");  // eye z = c z - s y: the y axis is the view, z edge-on
             opt(j)["axis"] = "z";
         },
         true},
        // Nearly edge-on but past VolPack's test (it scales by the 2 x 2 viewport): the shear
        // (k - 1) |tan| would make an intermediate image of about 10^9 x 3 pixels.
        {"axis z nearly edge-on", po + "axis",
         [&](json& j) {
             j["image"] = {{"width", 2}, {"height", 2}};
             opt(j)["rotate"] = json::parse(R"([["y", 89.9999999]])");
             opt(j)["axis"] = "z";
         },
         true},
    };
    for (const Case& c : cases) {
        json j = minimal_scene();
        c.edit(j);
        std::string msg;
        if (c.at_render) {
            Scene s;
            ASSERT_NO_THROW(s = parse_scene(j.dump(), dir.path, "scene.json")) << c.what;
            msg = error_of([&] { render_scene(s, {.threads = 1}); });
        } else {
            msg = error_of([&] { parse_scene(j.dump(), dir.path, "scene.json"); });
        }
        // The key itself (followed by ": " or by an index into it), not a longer key that starts with it.
        const std::size_t at = msg.find(c.key);
        const char next = at == std::string::npos || at + c.key.size() >= msg.size() ? '\0' : msg[at + c.key.size()];
        EXPECT_TRUE(next == ':' || next == '[') << c.what << ": " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << c.what << ": " << msg;
    }
    // The same edge-on override through factor_view itself.
    VolPackSpec spec;
    spec.axis = VolPackSpec::Axis::Y;
    EXPECT_NE(error_of([&] { factor_view(spec, {4, 4, 4}, 8, 8); }).find("render.profile_options.axis"), std::string::npos);
    spec.axis = VolPackSpec::Axis::Z;  // the principal axis itself: fine
    EXPECT_EQ(factor_view(spec, {4, 4, 4}, 8, 8).axis, 2);
}

// The intermediate image's rows are composited on TBB threads: 1 and 2 threads give the same bytes, for
// the classified and the raw path, shaded and depth-cued, on a rotated view.
TEST(VolPack, ThreadCountDoesNotChangeTheImage) {
    const test::TempDir dir("volpack");
    std::vector<std::uint8_t> bytes;
    for (int z = 0; z < 12; ++z)
        for (int y = 0; y < 11; ++y)
            for (int x = 0; x < 10; ++x) bytes.push_back(std::uint8_t((x * 37 + y * 11 + z * z * 5) % 256));
    write_u8_nrrd(dir, "v.nrrd", {10, 11, 12}, bytes);
    json j = minimal_scene();
    j["image"] = {{"width", 40}, {"height", 36}};
    j["render"]["profile_options"] = json::parse(R"({
        "rotate": [["x", 25], ["y", -40]],
        "scalar_table": {"ramp": [[0, 0], [80, 0.1], [200, 0.8], [255, 0.3]]},
        "shading": {},
        "depth_cue": {"front": 1.3, "density": 1.1},
        "channels": 3
    })");
    for (const char* path : {"classified", "raw"}) {
        j["render"]["profile_options"]["path"] = path;
        const Scene s = parse_scene(j.dump(), dir.path, "scene.json");
        const Image one = render_scene(s, {.threads = 1}), two = render_scene(s, {.threads = 2}), all = render_scene(s, {.threads = 0});
        EXPECT_EQ(one.pixels, two.pixels) << path;
        EXPECT_EQ(one.pixels, all.pixels) << path;
        int lit = 0;
        for (int y = 0; y < one.height; ++y)
            for (int x = 0; x < one.width; ++x) lit += one.at(x, y, 3) > 0.0;
        EXPECT_GT(lit, 100) << path;
    }
}

// The continuous scene of a VolPack scene (`explain volpack-scene`): its lights are VolPack's only (not
// the default headlight), each towards -(M^-1 l): with no rotation, a light set along (0, 0, 2) is the
// volref light towards (0, 0, -1); the tables become rows at the integer values; unshaded: no lights.
TEST(VolPack, ContinuousSceneTakesVolPacksLightsAndTables) {
    const test::TempDir dir("volpack");
    write_u8_nrrd(dir, "v.nrrd", {4, 4, 4}, std::vector<std::uint8_t>(64, 100));
    json j = minimal_scene();
    j["render"]["profile_options"]["shading"] =
        json::parse(R"({"material": {"ambient": 0.2, "diffuse": 0.5, "specular": 0.3, "shininess": 8},
                        "lights": [{"direction": [0, 0, 2], "color": [1, 1, 1]}], "two_sided": true})");
    const Scene s = parse_scene(j.dump(), dir.path, "scene.json");
    const PreparedScene prepared(s, RenderOptions{});
    const auto& r = dynamic_cast<const VolPackRenderer&>(*prepared.image_space());
    const Scene c = volpack_continuous_scene(s, r, 0.125);
    ASSERT_EQ(c.lights.size(), 1u);
    EXPECT_EQ(c.lights[0].type, LightSpec::Type::Directional);
    EXPECT_NEAR(c.lights[0].direction.x, 0.0, 1e-15);
    EXPECT_NEAR(c.lights[0].direction.y, 0.0, 1e-15);
    EXPECT_NEAR(c.lights[0].direction.z, -1.0, 1e-15);
    ASSERT_TRUE(c.volumes.front().shading);
    EXPECT_EQ(c.volumes.front().shading->ka, 0.2);
    EXPECT_EQ(c.volumes.front().shading->kd, 0.5);
    EXPECT_EQ(c.volumes.front().shading->ks, 0.3);
    EXPECT_EQ(c.volumes.front().shading->n, 8.0);
    EXPECT_TRUE(c.volumes.front().shading->two_sided);
    ASSERT_EQ(c.volumes.front().transfer.opacity.size(), 256u);
    EXPECT_EQ(c.volumes.front().transfer.opacity[51][0], 51.0);
    EXPECT_NEAR(c.volumes.front().transfer.opacity[51][1], 51.0 / 255.0, 1e-7);
    EXPECT_EQ(c.render.step, 0.125);
    EXPECT_EQ(c.camera.type, CameraSpec::Type::Matrices);
    json u = minimal_scene();
    const Scene su = parse_scene(u.dump(), dir.path, "scene.json");
    const PreparedScene pu(su, RenderOptions{});
    EXPECT_TRUE(volpack_continuous_scene(su, dynamic_cast<const VolPackRenderer&>(*pu.image_space()), 0.5).lights.empty());
}
