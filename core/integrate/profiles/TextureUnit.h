// TextureUnit: an NVIDIA texture unit's linear filter, bit for bit, and the band that bounds
// what any unit of its family can return against exact trilinear filtering. The profiles vtk-gpu,
// glsl-basic and cuda-curvilinear read it (render.profile_options.texture_unit "h100", texture_band;
// ProfileIntegrator); `volref explain texture-fetch` prints its steps; docs/conventions.md section 9,
// "The texture unit", states each rule with its source.
//
// Source: ../shared/gpu/README.md, "The 3D rule", fitted to every fetch that ../shared/gpu/dump_fetches.cu
// recorded on an NVIDIA H100 80GB HBM3 (CUDA 13, 2026-11-26; the CSVs are in tests/data/h100-fetches/).
// The rule, for a texture of n texels per axis, clamp addressing, texel i centred at i + 0.5:
//   1. per axis: t = clamp(x - 0.5, 0, n - 1), i0 = floor(t), i1 = min(i0 + 1, n - 1),
//      a = floor((t - i0) 256 + 0.5) in 0..256 (8 fractional bits, ties up). Normalised coordinates:
//      x = floor(u 2^20) 2^-20 n (u cut to 20 fractional bits first).
//   2. integer corner weights summing to 256, corner c = i + 2 j + 4 k, rnd(p) = (p + 128) >> 8:
//      Z1 = az, Z0 = 256 - az; in slice k: X1 = rnd(ax Zk), X0 = Zk - X1;
//      w(1,1,k) = rnd(ay X1), w(1,0,k) = X1 - w(1,1,k); w(0,0,k) = rnd((256 - ay) X0), w(0,1,k) = X0 - w(0,0,k).
//      1D: (256 - a, a).
//   3. float32 texels: in each z slice (1D: the two texels) every texel is truncated (toward zero) to a
//      multiple of 2^(E - 28), 2^(E-1) <= the largest |texel| with a non-zero weight < 2^E; the sum
//      sum_c w_c v'_c / 256 is exact and rounded once to float32, ties away from zero.
//      unorm16 texels (read as normalised float): N = (sum_c w_c q_c + 128) >> 8, fetch = float32(N / 65535).
// Not pinned down by the measurements (docs/conventions.md says what is chosen): whether a = 256 carries
// into i0 + 1 (it does not here: the weight 256 goes to i1, the same fetch), 20 or 21 bits of u (20),
// negative, huge, subnormal or NaN texels (truncation toward zero, ties away from zero; non-finite
// texels give the plain double sum), 1D unorm16 (as 3D).
//
// The family and its band (ProfileIntegrator's error channel): a unit of the family reads at a position
// within `delta` texels per axis of the exact one (float32 coordinates, the 20-bit cut), weighs the
// corners of that position's cell with weights w_c summing to 1 and within L1 distance kL1Max of the
// exact trilinear weights e_c there, and rounds as the rule does (texel conversion to float32, 28-bit
// truncation, the float32 result). Then, since both weight sets sum to 1,
//   |sum w_c v_c - sum e_c v_c| = |sum (w_c - e_c)(v_c - m)| <= (L1 / 2)(max v_c - min v_c)   (m the mid-range),
// the move of the position adds at most sum_axis delta_axis (max - min) over the cells it crosses, and
//   |fetch - exact| <= (kL1Max / 2 + sum delta)(max - min) + rounding,
// rounding = 2^-22 max |v_c| for float32 texels (texel to float32 2^-24, truncation 2^-27, the result 2^-24,
// with room), 0.5 / 65535 + 2^-24 for unorm16 (in units of the normalised value).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace volref::texture_unit {

inline constexpr int kWeightOne = 256;                  // 8 fractional bits of weight
inline constexpr int kTexelMantissaBits = 28;           // bits kept per float32 texel, aligned to its slice
inline constexpr int kNormalizedFractionBits = 20;      // fractional bits kept of a normalised coordinate
// The largest L1 distance sum_c |w_c / 256 - e_c| of the rule's corner weights from exact trilinear
// weights, over every point (the maximum lies at a vertex of a weight box, L1 being convex in the
// fractions): 7.574 / 256. Test TextureUnit.L1MaxIsTheRulesLargest recomputes it.
inline constexpr double kL1Max = 0.0295867919921875;
// The rounding terms of the band (header comment).
inline constexpr double kFloatRounding = 0x1p-22;                     // times max |v_c|
inline constexpr double kUnorm16Rounding = 0.5 / 65535.0 + 0x1p-24;   // normalised units
// A float32 coordinate is within 2^-24 |x| of the double one; a normalised one is also cut to 2^-20.
inline constexpr double kNormalizedDelta = 0x1p-20 + 0x1p-24;          // times n texels
inline constexpr double kCoordinateDelta = 0x1p-24;                    // times |x| texels (+ 2^-149)

// A value s normalised over the data range as seed 001's host stores it: round(clamp(s, 0, 1) 65535), to
// nearest, ties to even (its readVtk's rounding is not in its report; lrint is the host's).
inline std::uint16_t unorm16(double s) { return static_cast<std::uint16_t>(std::lrint(std::clamp(s, 0.0, 1.0) * 65535.0)); }

// x rounded to float32 (to nearest, ties to even), as a double. Through a volatile: GCC 12.2 at -O2/-O3
// drops the rounding of double(float(x)) when it vectorises two such conversions side by side (seen
// on the H100 fetch tests: an aggregate {double(float(x)), double(float(y)), ...} kept x and y unrounded).
inline double to_float32(double x) {
    volatile float f = static_cast<float>(x);
    return double(f);
}

// One axis of a fetch: the clamped texel position t, the two texels and the integer weight a of i1.
struct AxisRead {
    double x = 0.0;          // the unnormalised coordinate the unit uses
    double t = 0.0;          // clamp(x - 0.5, 0, n - 1)
    std::int64_t i0 = 0, i1 = 0;
    int a = 0;               // floor((t - i0) 256 + 0.5), 0..256
};

// x: an unnormalised coordinate as the unit receives it (a float32, given as double).
AxisRead axis_read(double x, std::int64_t n);
// A normalised coordinate u (a float32) over n texels as the unit sees it: floor(u 2^20) 2^-20 n.
double unnormalized(double u, std::int64_t n);

// The eight integer corner weights (sum 256), corner c = i + 2 j + 4 k, from the axis weights.
std::array<int, 8> corner_weights(int ax, int ay, int az);

// What filter_float did, for `explain texture-fetch`.
struct FloatSteps {
    std::array<double, 8> truncated{};  // each texel after the slice's truncation
    std::array<int, 2> exponent{};      // E of each slice (0 when its weights are all 0)
    double exact_sum = 0.0;             // sum_c w_c v'_c / 256 to double precision (hi)
    double exact_sum_lo = 0.0;          // and the rest (hi + lo is exact)
};
// float32 texels v[0..count) with weights w (sum 256), split into `slices` equal groups (3D: 2 slices
// of 4; 1D: 1 slice of 2) that each truncate to their own largest used texel.
float filter_float(const int* w, const float* v, int count, int slices, FloatSteps* steps = nullptr);

// unorm16 texels q[0..count): N = (sum w q + 128) >> 8, float32(N / 65535). `sum`/`n`: the steps.
float filter_unorm16(const int* w, const std::uint16_t* q, int count, std::int64_t* sum = nullptr,
                     std::int64_t* n = nullptr);

// A whole fetch of a 3D texture of dims n (x fastest), texel(i, j, k) returning a float or a uint16.
struct Fetch3d {
    std::array<AxisRead, 3> axis;
    std::array<int, 8> w{};
    std::array<std::int64_t, 3> corner_index(int c) const {
        return {(c & 1) ? axis[0].i1 : axis[0].i0, (c & 2) ? axis[1].i1 : axis[1].i0, (c & 4) ? axis[2].i1 : axis[2].i0};
    }
};
Fetch3d locate_3d(const std::array<double, 3>& x, const std::array<std::int64_t, 3>& n);

// The exact trilinear weights e_c of the clamped position (t - i0 per axis), corner c = i + 2 j + 4 k.
std::array<double, 8> exact_weights(const std::array<AxisRead, 3>& axis);

// The band's weight term factor for values spread max - min: kL1Max / 2 + sum delta.
inline double weight_factor(double delta_sum) { return 0.5 * kL1Max + delta_sum; }

// The band of a 1D table read (one channel): every value a unit of the family returns reading n texels
// t(0) .. t(n - 1) (texel(j) gives t(j)) at a position in [plo, phi] (0 <= plo <= phi <= n - 1): the hull of
// the table's piecewise-linear curve there (its extremes lie at the ends and the texel centres between),
// widened by the largest over the segments it can read of |t(i+1) - t(i)| / 512 (the 8-bit weight) +
// kFloatRounding max(|t(i)|, |t(i+1)|) (the texels in float32, truncated, the result rounded).
template <class Texel>
void table_hull(const Texel& texel, int n, double plo, double phi, double& lo, double& hi) {
    auto curve = [&](double p) {
        const int i = std::min(int(p), n - 2);
        const double w = p - double(i), a = texel(i);
        return a + w * (texel(i + 1) - a);
    };
    lo = std::min(curve(plo), curve(phi));
    hi = std::max(curve(plo), curve(phi));
    for (int j = int(std::ceil(plo)); j <= int(std::floor(phi)) && j < n; ++j) {
        lo = std::min(lo, texel(j));
        hi = std::max(hi, texel(j));
    }
    double slack = 0.0;
    const int s0 = std::clamp(int(std::ceil(plo)) - 1, 0, n - 2), s1 = std::clamp(int(std::floor(phi)), 0, n - 2);
    for (int i = s0; i <= s1; ++i) {
        const double a = texel(i), e = texel(i + 1);
        slack = std::max(slack, std::fabs(e - a) / 512.0 + kFloatRounding * std::max(std::fabs(a), std::fabs(e)));
    }
    lo -= slack;
    hi += slack;
}

// --- simulated units of the family (tests: a Monte Carlo of the units the band covers) -------------
// A deterministic stream of numbers in [-1, 1] from a key (splitmix64): a quarter of them exactly -1 or
// +1 (the extremes of the tolerance), the rest uniform.
struct Admissible {
    std::uint64_t state;
    static std::uint64_t mix(std::uint64_t z);
    Admissible(std::uint64_t seed, double a, double b, double c);
    double next();
};
// Weights summing to 1 within L1 distance kL1Max of `exact` (a zero-sum move, its L1 norm drawn up to
// kL1Max, a quarter of the time kL1Max exactly).
std::array<double, 8> admissible_weights(const std::array<double, 8>& exact, Admissible& r);

}  // namespace volref::texture_unit
