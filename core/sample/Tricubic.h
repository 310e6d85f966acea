// Tricubic reconstruction: the tensor product of a 1-D cubic filter over the 4 x 4 x 4 voxels
// around a point (conventions section 2), with its analytic gradient.
//
// 1-D: a point with continuous index u lies in the cell [i, i + 1] (chosen as for trilinear:
// i = min(floor(u), n - 2), 0 when n = 1) at fraction t = u - i in [0, 1]. The reconstruction is
//   f(u) = w0(t) f[i-1] + w1(t) f[i] + w2(t) f[i+1] + w3(t) f[i+2],
// and its derivative with respect to u (dt/du = 1) is
//   f'(u) = w0'(t) f[i-1] + w1'(t) f[i] + w2'(t) f[i+1] + w3'(t) f[i+2].
// Tap indices are clamped to [0, n - 1] ("on the border, indices clamp"), so at the low border the
// taps of the cell [0, 1] are f[0], f[0], f[1], f[2] and at the high border of [n-2, n-1] they are
// f[n-3], f[n-2], f[n-1], f[n-1].
//
// Kernels (both are piecewise cubics with support [-2, 2]; the weights of one cell are the kernel
// evaluated at the distances t + 1, t, 1 - t, 2 - t):
//   uniform cubic B-spline (C2, approximating; reproduces polynomials of degree <= 1, and blurs
//   higher ones: for f = u^2 it gives u^2 + 1/3, the kernel's variance):
//     w0 = (1-t)^3 / 6                     w0' = -(1-t)^2 / 2
//     w1 = (3t^3 - 6t^2 + 4) / 6           w1' = (3t^2 - 4t) / 2
//     w2 = (-3t^3 + 3t^2 + 3t + 1) / 6     w2' = (-3t^2 + 2t + 1) / 2
//     w3 = t^3 / 6                         w3' = t^2 / 2
//   Catmull-Rom (the a = -1/2 cardinal cubic; C1, interpolating: weights (0, 1, 0, 0) at t = 0;
//   reproduces polynomials of degree <= 2):
//     w0 = (-t^3 + 2t^2 - t) / 2           w0' = (-3t^2 + 4t - 1) / 2
//     w1 = (3t^3 - 5t^2 + 2) / 2           w1' = (9t^2 - 10t) / 2
//     w2 = (-3t^3 + 4t^2 + t) / 2          w2' = (-9t^2 + 8t + 1) / 2
//     w3 = (t^3 - t^2) / 2                 w3' = (3t^2 - 2t) / 2
// For every t the weights sum to 1 and the derivative weights to 0 (up to rounding).
//
// 3-D: f(u) = sum_{a,b,c} wx_a(tx) wy_b(ty) wz_c(tz) f[ix-1+a, iy-1+b, iz-1+c], and each gradient
// component replaces that axis's weights by their derivatives. The gradient is with respect to the
// continuous index; divide by the spacing for world units.
//
// Summation order (fixed, so results are reproducible bit for bit): nested 1-D passes.
//   1. along i: for each of the 16 rows (k outer, j inner) the 4 taps i-1..i+2 are summed left to
//      right, ((w0 f0 + w1 f1) + w2 f2) + w3 f3, with wx (value) and with wx' (d/du_x);
//   2. along j: for each k, the 4 row results j-1..j+2 are summed the same way with wy (value and
//      d/du_x) and wy' (d/du_y);
//   3. along k: the 4 plane results k-1..k+2 with wz (value, d/du_x, d/du_y) and wz' (d/du_z).
// The value is computed by exactly the same operations in tricubic() and in
// tricubic_value_and_index_gradient(), so the two agree bit for bit (and likewise the gradients).
//
// Clamping: each component of u is clamped to [0, n - 1] first (NaN is treated as 0); outside the
// domain the value is that of the clamped point and the gradient is the cubic's derivative there
// (the one-sided derivative from inside).
// An axis with n = 1 uses its single layer: its weights are taken as (0, 1, 0, 0) (all four taps
// clamp to index 0 and the weights sum to 1, so this is the same value, exactly) and its derivative
// weights as 0, so that gradient component is exactly 0.
#pragma once
#include <array>
#include <cstdint>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"

namespace volref {

enum class CubicKernel { BSpline, CatmullRom };

// Weights w of the 4 taps i-1, i, i+1, i+2 at fraction t in [0, 1] of the cell [i, i+1], and their
// derivatives dw = dw/dt (formulas above).
void cubic_weights(CubicKernel k, double t, std::array<double, 4>& w, std::array<double, 4>& dw);

// One axis of the tensor product: the 4 weights, their derivatives and the tap indices (IndexSpace.h's
// cubic_axis: clamped taps on a Cartesian axis, wrapped ones on a shell's periodic axis). The default is
// the single layer of an axis with n = 1.
struct CubicAxis {
    std::array<double, 4> w{0.0, 1.0, 0.0, 0.0};
    std::array<double, 4> dw{0.0, 0.0, 0.0, 0.0};
    std::array<std::int64_t, 4> idx{0, 0, 0, 0};
};

// The tensor-product cubic over the taps of three axes (the nested passes above); the functions below
// are it on clamped axes, ShellSampler on its own.
double tricubic(const Volume& v, const CubicAxis& x, const CubicAxis& y, const CubicAxis& z);

// The tensor-product cubic at continuous index u (each component clamped to [0, n - 1]).
double tricubic(const Volume& v, CubicKernel k, const glm::dvec3& u);

// Analytic gradient with respect to the continuous index (d/du_x, d/du_y, d/du_z). Zero on an axis
// with n = 1.
glm::dvec3 tricubic_index_gradient(const Volume& v, CubicKernel k, const glm::dvec3& u);

// Value and index gradient at once (shares the 64 fetches); the renderer's hot path.
double tricubic_value_and_index_gradient(const Volume& v, CubicKernel k, const glm::dvec3& u,
                                         glm::dvec3& gradient);

}  // namespace volref
