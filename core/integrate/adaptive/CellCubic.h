// CellCubic: the trilinear field along a ray inside one cell is a cubic in the ray parameter.
//
// In the cell with lower corner (i, j, k), the fractional position along the ray is affine in the
// local parameter x = t - t_a (t_a the cell's entry): p(x) = p0 + dp x, q(x) = q0 + dq x,
// r(x) = r0 + dr x, with (p0, q0, r0) = u(t_a) - (i, j, k) and (dp, dq, dr) = direction / spacing.
// Each of Levoy's weights (1-p)(1-q)(1-r), p(1-q)(1-r), ... is a product of three affine factors, so
//   f(x) = sum_n f_n w_n(x) = c0 + c1 x + c2 x^2 + c3 x^3.
// Its extrema are the roots of f'(x) = c1 + 2 c2 x + 3 c3 x^2; between them f is monotone, so a
// value is crossed at most once there and bisection isolates that crossing (Marmitt et al. 2004,
// "Fast and accurate ray-voxel intersection techniques for iso-surface ray tracing").
#pragma once
#include <array>
#include <cmath>
#include <utility>

#include <glm/vec3.hpp>

namespace volref {

struct Cubic {
    std::array<double, 4> c{0.0, 0.0, 0.0, 0.0};  // c0 + c1 x + c2 x^2 + c3 x^3
    double operator()(double x) const { return ((c[3] * x + c[2]) * x + c[1]) * x + c[0]; }
    double derivative(double x) const { return (3.0 * c[3] * x + 2.0 * c[2]) * x + c[1]; }
    // a f + b (an affine map of the values, e.g. the transfer function's normalised coordinate).
    Cubic affine(double scale, double offset) const {
        return {{c[0] * scale + offset, c[1] * scale, c[2] * scale, c[3] * scale}};
    }
};

// The value of f at the end t of a piece (a part of the ray inside one cell), read in the piece's own
// cell: f(t), or f one double inside the piece (towards `toward`) where f(t) is not finite. At a grid
// plane the sampler reads the cell above it, which may have a non-finite corner while the piece's cell
// is finite (a NaN layer would otherwise hide the finite cell's maximum and crossing). Returns (t used, value).
template <class F>
std::pair<double, double> piece_end(const F& f, double t, double toward) {
    const double v = f(t);
    if (std::isfinite(v)) return {t, v};
    const double inside = std::nextafter(t, toward);
    return {inside, f(inside)};
}

// The cubic of Levoy's trilinear sum (corner order f1..f8, Trilinear.h) along p = p0 + dp x, etc.
inline Cubic trilinear_cubic(const std::array<double, 8>& f, const glm::dvec3& frac0, const glm::dvec3& dfrac) {
    // The affine factors (value at x = 0, slope) of p and 1 - p per axis.
    using Affine = std::pair<double, double>;
    auto times = [](const std::array<double, 3>& a, const Affine& b) {  // quadratic * affine -> cubic
        return std::array<double, 4>{a[0] * b.first, a[0] * b.second + a[1] * b.first,
                                     a[1] * b.second + a[2] * b.first, a[2] * b.second};
    };
    auto quad = [](const Affine& a, const Affine& b) {
        return std::array<double, 3>{a.first * b.first, a.first * b.second + a.second * b.first, a.second * b.second};
    };
    const Affine P1{frac0.x, dfrac.x}, P0{1.0 - frac0.x, -dfrac.x};
    const Affine Q1{frac0.y, dfrac.y}, Q0{1.0 - frac0.y, -dfrac.y};
    const Affine R1{frac0.z, dfrac.z}, R0{1.0 - frac0.z, -dfrac.z};
    // Corners f1..f8: (0,0,0) (1,0,0) (1,1,0) (0,1,0) (0,0,1) (1,0,1) (1,1,1) (0,1,1).
    const std::array<std::array<double, 4>, 8> w{
        times(quad(P0, Q0), R0), times(quad(P1, Q0), R0), times(quad(P1, Q1), R0), times(quad(P0, Q1), R0),
        times(quad(P0, Q0), R1), times(quad(P1, Q0), R1), times(quad(P1, Q1), R1), times(quad(P0, Q1), R1)};
    Cubic out;
    for (int n = 0; n < 8; ++n)
        for (int k = 0; k < 4; ++k) out.c[std::size_t(k)] += f[std::size_t(n)] * w[std::size_t(n)][std::size_t(k)];
    return out;
}

// The roots of f' in the open interval (0, L), ascending; returns how many (0, 1 or 2).
// Quadratic A x^2 + B x + C with A = 3 c3, B = 2 c2, C = c1, by the stable formula
// q = -(B + sign(B) sqrt(B^2 - 4 A C)) / 2, roots q / A and C / q.
inline int cubic_extrema(const Cubic& f, double L, double out[2]) {
    const double A = 3.0 * f.c[3], B = 2.0 * f.c[2], C = f.c[1];
    double r[2];
    int n = 0;
    if (A == 0.0) {
        if (B != 0.0) r[n++] = -C / B;
    } else {
        const double disc = B * B - 4.0 * A * C;
        if (disc >= 0.0) {
            const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
            r[n++] = q / A;
            if (q != 0.0) r[n++] = C / q;
        }
    }
    if (n == 2 && r[1] < r[0]) std::swap(r[0], r[1]);
    int m = 0;
    for (int k = 0; k < n; ++k)
        if (r[k] > 0.0 && r[k] < L && (m == 0 || r[k] > out[m - 1])) out[m++] = r[k];
    return m;
}

// Bisection of [lo, hi] where g(lo) has sign `s_lo` (+1 or -1) and g(hi) the other sign, until no
// double lies strictly between the ends (the crossing to rounding of t). Returns the end with the
// smaller |g| (lo on a tie). An exact zero found on the way is returned at once.
template <class G>
double bisect_to_rounding(G&& g, double lo, double hi, int s_lo) {
    for (int it = 0; it < 2200; ++it) {  // 2200 > the 2098 halvings between the extreme doubles
        const double m = 0.5 * (lo + hi);
        if (!(m > lo && m < hi)) break;
        const double gm = g(m);
        if (gm == 0.0) return m;
        ((gm > 0.0 ? 1 : -1) == s_lo ? lo : hi) = m;
    }
    return std::fabs(g(hi)) < std::fabs(g(lo)) ? hi : lo;
}

}  // namespace volref
