// TextureUnit: how a GPU's linearly filtered texture fetch differs from exact interpolation (issue 17,
// part 4), as measured on an NVIDIA H100 (../shared/gpu/README.md). The profiles vtk-gpu, glsl-basic
// and cuda-curvilinear read it (render.profile_options.texture_unit, texture_band; ProfileIntegrator);
// docs/conventions.md section 9, "The texture unit", states each rule.
//
//   exact:    the weight of the upper texel is the fraction f of the texel position (llvmpipe, volref).
//   hardware: 1D weight q(f) = floor(f * 256 + 0.5) / 256 (matched 65,537 of 65,537 measured points);
//             normalised 1D tables read at n u - 0.5 clamped to [0, n - 1] with that weight;
//             3D (the best model the measurements support, about 87% of one-hot fetches exactly):
//             per-axis weights q(f_x), q(f_y), q(f_z), each corner's product rounded to 1/256.
//   band:     a bound on |fetch - exact| for any texture unit within the model's tolerances: per-axis
//             weights within 1/512 of exact, each corner weight within 1/512 of the product of those
//             (the rounding the model does, of either sign), whatever the unexplained 13% do inside them:
//             |W^_c - W_c| <= e_c = (1/512) sum_axis prod_{other axes} (w + 1/512) + 1/512, and
//             |fetch - exact| <= sum_c e_c |v_c| (the corner weights need not sum to 1).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace volref::texture_unit {

enum class Model { Exact, Hardware };

inline constexpr double kWeightStep = 1.0 / 256.0;           // 8 fractional bits
inline constexpr double kWeightError = 0.5 * kWeightStep;     // 1/512: round to nearest

// The weight of the upper texel for the fraction f in [0, 1].
inline double weight(double f, Model m) {
    return m == Model::Exact ? f : std::floor(f * 256.0 + 0.5) / 256.0;
}

// A 1D texture of n >= 1 texels read at unnormalised coordinate x (texel i centred at i + 0.5), clamped
// to the edge texels (cudaAddressModeClamp, GL_CLAMP_TO_EDGE).
template <class Texels>
double fetch_1d(const Texels& t, int n, double x, Model m) {
    const double p = std::clamp(x - 0.5, 0.0, double(n - 1));
    const int i = n > 1 ? std::min(int(std::floor(p)), n - 2) : 0;
    if (n == 1) return t[0];
    const double w = weight(p - double(i), m);
    return t[i] + w * (t[i + 1] - t[i]);
}

// A normalised 1D table (coordinate u in [0, 1] over n texels): texel position n u - 0.5.
template <class Texels>
double fetch_1d_normalized(const Texels& t, int n, double u, Model m) {
    return fetch_1d(t, n, u * double(n), m);
}

// The eight corner weights of a 3D fetch with fractions (fx, fy, fz), corner c = x + 2 y + 4 z.
inline std::array<double, 8> corner_weights(double fx, double fy, double fz, Model m) {
    const double a[3] = {weight(fx, m), weight(fy, m), weight(fz, m)};
    std::array<double, 8> w{};
    for (int c = 0; c < 8; ++c) {
        double p = 1.0;
        for (int k = 0; k < 3; ++k) p *= ((c >> k) & 1) ? a[k] : 1.0 - a[k];
        w[std::size_t(c)] = m == Model::Exact ? p : std::floor(p * 256.0 + 0.5) / 256.0;
    }
    return w;
}

// sum_c w_c v_c.
inline double fetch_3d(const std::array<double, 8>& v, double fx, double fy, double fz, Model m) {
    const std::array<double, 8> w = corner_weights(fx, fy, fz, m);
    double s = 0.0;
    for (int c = 0; c < 8; ++c) s += w[std::size_t(c)] * v[std::size_t(c)];
    return s;
}

// The band: a bound on |fetch - exact trilinear| for any texture unit within the model (above).
inline double fetch_error_band_3d(const std::array<double, 8>& v, double fx, double fy, double fz) {
    const double e = kWeightError;
    const double f[3] = {fx, fy, fz};
    double band = 0.0;
    for (int c = 0; c < 8; ++c) {
        double w[3];
        for (int k = 0; k < 3; ++k) w[k] = (((c >> k) & 1) ? f[k] : 1.0 - f[k]) + e;
        const double ec = e * (w[1] * w[2] + w[0] * w[2] + w[0] * w[1]) + e;
        band += ec * std::fabs(v[std::size_t(c)]);
    }
    return band;
}

// --- admissible units (tests: the Monte Carlo of the units the band covers) ------------------------
// A deterministic stream of numbers in [-1, 1] from a key (splitmix64): a quarter of them exactly -1 or
// +1 (the extremes of the tolerance), the rest uniform.
struct Admissible {
    std::uint64_t state;
    static std::uint64_t mix(std::uint64_t z) {
        z += 0x9e3779b97f4a7c15ull;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    static std::uint64_t bits(double x) {
        std::uint64_t b;
        std::memcpy(&b, &x, sizeof b);
        return b;
    }
    Admissible(std::uint64_t seed, double a, double b, double c)
        : state(mix(mix(mix(mix(seed) ^ bits(a)) ^ bits(b)) ^ bits(c))) {}
    double next() {
        state = mix(state);
        if ((state & 3u) == 0u) return (state & 4u) ? 1.0 : -1.0;
        return double(state >> 11) * 0x1.0p-53 * 2.0 - 1.0;
    }
};

// A 1D weight within kWeightError of f.
inline double admissible_weight(double f, Admissible& r) { return f + kWeightError * r.next(); }

// Corner weights within the model's tolerances: per-axis weights within kWeightError of exact, each
// corner's product moved by at most kWeightError.
inline std::array<double, 8> admissible_corner_weights(double fx, double fy, double fz, Admissible& r) {
    const double a[3] = {admissible_weight(fx, r), admissible_weight(fy, r), admissible_weight(fz, r)};
    std::array<double, 8> w{};
    for (int c = 0; c < 8; ++c) {
        double p = 1.0;
        for (int k = 0; k < 3; ++k) p *= ((c >> k) & 1) ? a[k] : 1.0 - a[k];
        w[std::size_t(c)] = p + kWeightError * r.next();
    }
    return w;
}

}  // namespace volref::texture_unit
