// Pre-integrated segments (Engel, Kraus and Ertl 2001) for the fast profile
// (render.profile_options.preintegration; conventions section 9b, "Pre-integrated segments").
//
// A segment of length d whose transfer-function coordinate runs linearly from x_f (its front end) to
// x_b (its back end), x(u) = x_f + (x_b - x_f) u for u in [0, 1], contributes exactly
//   tau   = d sigma_bar,   sigma_bar = integral_0^1 sigma(x(u)) du,   sigma(x) = -log1p(-a(x)) / l,
//   C     = integral_0^1 c(x(u)) d sigma(x(u)) exp(-d integral_0^u sigma(x(w)) dw) du,
//   alpha = 1 - exp(-tau),  and its effective colour c_bar = C / alpha,
// with a(x) the opacity (clamped to kPreIntegrationMaxOpacity so that sigma stays finite), c(x) the
// colour and l the opacity unit distance. sigma_bar does not depend on d; c_bar does (through the
// attenuation inside the segment).
//
// segment_integral() computes these for any (x_f, x_b, d): the ramp is cut where it crosses a row of
// the opacity or colour function, so that a and c are linear in u on each piece; on a piece the
// optical depth is the closed form
//   integral -log(1 - a(u)) du = (F(a(u1)) - F(a(u0))) / a'(u),  F(a) = (1 - a) log(1 - a) + a,
// (the midpoint value times the length where |a(u1) - a(u0)| < 1e-4), and the colour integral is
// the Gauss-Kronrod K15 rule on the piece with exp(-tau) exact at each node.
//
// PreIntegrationTable holds sigma_bar and c_bar (for d = h, the render's step) at the nodes
// x_i = x0 + i dx, i = 0 .. n, of both ends: n + 1 squared entries of 4 floats (sigma_bar, r, g, b),
// row i the front end, column j the back end. The kernel reads it bilinearly.
#pragma once
#include <vector>

#include <glm/vec3.hpp>

namespace volref {

class TransferFunction;

// The opacity is clamped to 1 - 2^-20 so that the extinction -log1p(-a) / l stays finite (at most
// 13.9 / l: one unit distance at the clamp lets 2^-20 through); the table has 2 to
// conventions::kPreIntegrationMaxIntervals intervals per axis (render.profile_options.preintegration).
inline constexpr double kPreIntegrationMaxOpacity = 1.0 - 0x1p-20;

struct SegmentIntegral {
    double sigma_bar = 0.0;  // mean extinction over the segment (per unit length)
    double alpha = 0.0;      // 1 - exp(-d sigma_bar)
    glm::dvec3 colour{0.0};  // C: the emitted colour that reaches the segment's front end
};

// The exact integrals above for the ramp x_f -> x_b of length d.
SegmentIntegral segment_integral(const TransferFunction& tf, double x_f, double x_b, double d);

struct PreIntegrationTable {
    int n = 0;           // n + 1 nodes per axis
    double x0 = 0.0;     // node i at x0 + i dx (the transfer function's coordinate)
    double dx = 1.0;
    double h = 1.0;      // the segment length c_bar was integrated for
    std::vector<float> entries;  // (n + 1)^2 x 4: [(i (n + 1) + j) 4 + c], c = sigma_bar, r, g, b (c_bar)
};

// The table over [x_lo, x_hi] (covering every coordinate a sample can take) with n + 1 nodes per axis,
// for segments of length h. Computed in parallel (TBB), each entry by segment_integral.
PreIntegrationTable build_preintegration_table(const TransferFunction& tf, double x_lo, double x_hi, double h, int n);

// The table read bilinearly at (x_f, x_b), each clamped to the table's range: the kernel's formula
// (PreIntegration-inl.h) in double, for the tests.
void lookup_preintegration(const PreIntegrationTable& t, double x_f, double x_b, double out[4]);

}  // namespace volref
