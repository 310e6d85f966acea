// VolPack 1.0b3 (Lacroute and Levoy, Stanford, 1994; Debian's libvolpack1-dev): the arithmetic of its
// shear-warp renderer, step by step, in its own precision (double where VolPack computes in double,
// float where it stores float). The `volpack` profile (VolPackRenderer.h) is built from these pieces;
// `volref explain volpack-voxel` and `volpack-warp` print them. Each function names the VolPack
// function it reproduces (the sources: the repository tsughoggr/volpack-9front-ape, read, not copied;
// ../shared/notes/volpack.md), and docs/conventions.md, section "VolPack", states each formula.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"

namespace volref::volpack {

inline constexpr double kEps = 1.0e-11;          // VP_EPS
inline constexpr int kNormN = 44;                // NORM_N: the 13-bit normal code's octahedron subdivision
inline constexpr int kMaxNormal = 7923;          // VP_NORM_MAX
inline constexpr int kGradMax = 221;             // VP_GRAD_MAX
inline constexpr int kOpacityMax = 255;          // VP_OPACITY_MAX
inline constexpr int kWarpWeightEntries = 64;    // WARP_WEIGHT_ENTRIES (2^WARP_WEIGHT_INDEX_BITS)
inline constexpr int kWarpWeightShift = 31 - 6;  // FIX31_TO_WGTIND: the 31-bit fraction's top 6 bits
inline constexpr double kDepthCueQuantization = 1.0 / 255.0;  // DEFAULT_DC_QUANTIZATION
// volref's own: a warped byte "may round either way" (the `error` channel) when its float value before
// truncation lies within this many 8-bit units of an integer (conventions section 9, "VolPack", the error channel).
inline constexpr double kTieWindow = 1.0 / 1024.0;

using Matrix4 = std::array<std::array<double, 4>, 4>;  // vpMatrix4: m[row][column]
using Vector4 = std::array<double, 4>;

Matrix4 identity();
// MatrixMult (vp_linalg.c): p_ij = 0 + a_i0 b_0j + a_i1 b_1j + a_i2 b_2j + a_i3 b_3j, in that order.
Matrix4 multiply(const Matrix4& a, const Matrix4& b);
// vpMatrixVectorMult4.
Vector4 multiply(const Matrix4& m, const Vector4& v);
// vpNormalize3 on the first three components; false when |v|^2 < VP_EPS (VPERROR_SINGULAR).
bool normalize3(double* v);
// VPLoadRotation: VolPack's rotation matrices (x: m11 = m22 = cos, m12 = sin, m21 = -sin; y, z alike).
Matrix4 rotation(VolPackSpec::Axis axis, double degrees);
// vpSolveSystem4: Gaussian elimination with implicit row scaling, each b[l] replaced by a^-1 b[l].
// false when singular.
bool solve_system(Matrix4 a, std::vector<Vector4*> b);

// The view as VolPack factors it (VPComputeViewTransform, FactorAffineView, vp_view.c).
struct View {
    Matrix4 model{}, projection{};  // VP_MODEL (vpRotate in order) and VP_PROJECT (vpWindow on the identity)
    Matrix4 view_transform{};       // viewport . PROJECT . VIEW . MODEL . prematrix: voxel index -> (X, Y, depth)
    int axis = 2;                   // the principal axis: 0 x, 1 y, 2 z (VP_X_AXIS ...)
    int icount = 0, jcount = 0, kcount = 0;  // the slices' size and count (permuted: X -> (y, z, x), Y -> (z, x, y))
    double shear_i = 0.0, shear_j = 0.0, trans_i = 0.0, trans_j = 0.0;
    bool reverse_slice_order = false;  // false: slice 0 is the front one
    int intermediate_width = 0, intermediate_height = 0;
    double depth_di = 0.0, depth_dj = 0.0, depth_dk = 0.0, depth_000 = 0.0;
    double warp[3][3] = {};  // warp_2d: intermediate (u, v, 1) -> image (X, Y, 1)
    float voxel_size = 1.0f;                  // L = sqrt(1 + s_i^2 + s_j^2), the slices' distance along a ray
    std::array<float, 256> opacity_correction{};  // 1 - (1 - q / 255)^L (ComputeAffineOpacityCorrection)
    float slice_dc_ratio = 1.0f;              // VPSliceDepthCueRatio: the depth-cue factor from one slice to the next
};
// Throws volref::Error naming render.profile_options.KEY where VolPack returns an error
// (VPERROR_SINGULAR for a view it cannot factor or an axis override seen edge-on).
View factor_view(const VolPackSpec& spec, const std::array<std::int64_t, 3>& dims, int image_width, int image_height);
// The object-space voxel (x, y, z) of slice voxel (i, j) of slice k for principal axis `axis`.
inline std::array<std::int64_t, 3> object_voxel(int axis, std::int64_t i, std::int64_t j, std::int64_t k) {
    if (axis == 0) return {k, i, j};
    if (axis == 1) return {j, k, i};
    return {i, j, k};
}

// vpNormalIndex: the 13-bit code of a unit vector (x = rint(44 nx / L1), y likewise (Debian's library
// rounds, ties to even), x clamped to the row's limit 44 - |y|, code = NormalPy[y] + 2 x, + 1 for nz < 0).
int normal_index(double nx, double ny, double nz);
// The unit normal of code n as vpShadeTable computes it (codes 0 and 1: the zero vector).
std::array<double, 3> code_normal(int code);

// vpVolumeNormals / vpScanlineNormals over the 8-bit scalars: per voxel the 13-bit normal code and
// the 8-bit gradient magnitude (rint(|Delta| / 2), Debian's library; 0 and code 0 on the volume's
// boundary and for |Delta| < VP_EPS). `delta` (optional) receives the integer central differences.
// The integer central differences of voxel (x, y, z) as vpScanlineNormals takes them; all 0 on the
// volume's boundary (x at 0 or n - 1, or the scanline's y or z at 0 or n - 1).
std::array<int, 3> central_differences(const std::uint8_t* scalars, const std::array<std::int64_t, 3>& dims,
                                       std::int64_t x, std::int64_t y, std::int64_t z);
struct VoxelNormals {
    std::vector<std::uint16_t> code;
    std::vector<std::uint8_t> gradient;
    std::vector<std::array<std::int16_t, 3>> delta;
};
VoxelNormals volume_normals(const std::uint8_t* scalars, const std::array<std::int64_t, 3>& dims, bool keep_delta);

// The lookup shader's table (vpShadeTable, vp_shade.c): channels floats per normal code (0 .. VP_NORM_MAX),
// on VolPack's 0 .. 255 scale, clamped to 255. Unshaded (spec.shaded false): 255 everywhere.
std::vector<float> shade_table(const VolPackSpec& spec, const Matrix4& model);
// One entry of that table for an arbitrary unit normal n (the table's formula; the variant
// normal_code "exact"), `out` channels floats.
void shade_normal(const VolPackSpec& spec, const Matrix4& model, const std::array<double, 3>& n, float* out);

// VPBilirpWeight (VPComputeWarpTables, vp_warp.c): per (y, x) index the weights of the taps (u, v),
// (u + 1, v), (u, v + 1), (u + 1, v + 1): (1 - x/63)(1 - y/63), (x/63)(1 - y/63), (1 - x/63)(y/63) as float,
// the fourth 1 - the other three (in double, then float).
const std::array<std::array<std::array<float, 4>, kWarpWeightEntries>, kWarpWeightEntries>& warp_weights();

// The classification of one voxel (VPClassifyVoxel, CacheVoxel; vpRenderRawVolume's kernels alike).
struct VoxelClass {
    float opacity = 0.0f;     // the tables' product (float)
    bool kept = false;        // opacity > VP_MIN_VOXEL_OPACITY (float compare)
    int opacity_byte = 0;     // (int)(opacity * 255.), clamped to 0 .. 255
    float corrected = 0.0f;   // opacity_correction[opacity_byte] (0 when not kept)
};
VoxelClass classify_voxel(const VolPackSpec& spec, const View& view, int scalar, int gradient);

}  // namespace volref::volpack
