// GaussKronrod: the Gauss-Kronrod G7/K15 pair on [-1, 1] and its integration matrices.
//
// K15 (15 nodes x_0 < ... < x_14, exact for polynomials of degree 22) contains the 7 Gauss-Legendre
// nodes of G7 (exact to degree 13) at the odd indices 1, 3, ..., 13; |K15 - G7| estimates the error of
// the pair (QUADPACK's qk15, Piessens et al. 1983). Node values and weights are QUADPACK's.
//
// Emission-absorption needs the optical depth at every node, tau(x_i) = integral from -1 to x_i of
// sigma. The integration matrix S (Gauss-Kronrod collocation) gives it from the node values alone:
//   integral_{-1}^{x_i} p(s) ds = sum_j S_ij sigma_j,   S_ij = integral_{-1}^{x_i} l_j(s) ds,
// with p the degree-14 interpolant of sigma at the 15 nodes and l_j its Lagrange basis. The G7
// matrix is the same over the 7 Gauss nodes (degree-6 interpolant). Both are computed once, in long
// double, by K15 itself on [-1, x_i] (exact: l_j has degree <= 14 <= 22).
#pragma once
#include <array>

namespace volref::gauss_kronrod {

inline constexpr int kNodes = 15;       // K15
inline constexpr int kGaussNodes = 7;   // G7, at K15 indices 2 g + 1

struct Tables {
    std::array<double, kNodes> x;       // ascending, on [-1, 1]
    std::array<double, kNodes> wk;      // K15 weights
    std::array<double, kGaussNodes> wg; // G7 weights (nodes x[2 g + 1])
    std::array<std::array<double, kNodes>, kNodes> sk;                 // S of K15
    std::array<std::array<double, kGaussNodes>, kGaussNodes> sg;       // S of G7
};

// The tables (built on first use, thread-safe).
const Tables& tables();

}  // namespace volref::gauss_kronrod
