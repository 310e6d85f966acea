// Least-squares fits (Ceres) behind `volref compare --fit` and `volref sweep`'s order of accuracy.
//
// compare --fit: each model predicts B from A (premultiplied RGBA, ComparedImage.h) with a few
// convention parameters, fitted by least squares over the pixels' R, G, B, A:
//   gain       B_rgb = g A_rgb,  B_a = A_a                                   (one parameter g)
//   opacity    B_a = 1 - (1 - A_a)^k,  B_rgb = A_rgb B_a / A_a                (one parameter k > 0)
//              (k multiplies the optical depth: a step, opacity unit distance or density scale k times
//              A's. Alpha follows exactly for any ray, since T_B = exp(-k tau) = T_A^k, so k is fitted to
//              alpha and the model is judged by the alpha residual; the colour prediction is exact only
//              for a constant colour along the ray and is reported as the RGBA residual. Pixels with
//              A_a = 0 or A_a >= 1 do not depend on k and are left out of the fit.)
//   shift      B(x, y) = A(x - sx, y - sy)                                   (two parameters, pixels)
//              (A interpolated by Ceres' bicubic (Catmull-Rom) interpolator; |s| <= kMaxShiftPixels;
//              residual over pixels at least kMaxShiftPixels from the border)
//   conventions (`--scene`): B re-rendered by volref with one convention changed (a flipped
//              normal under one-sided lighting, a ray box half a voxel larger or smaller, opacity correction
//              applied to MIP or not; no parameter), judged on R, G, B, A: before = RMS(B - A), after =
//              RMS(B' - A), B' the re-rendered image.
// Pixels with a non-finite value in either image never reach a fit (ImageMetrics.h, finite_copies: they
// are 0 in both images the fits see).
// Residuals are reported as RMS over every value the model is judged on (gain, shift: R, G, B, A; opacity:
// A), before (B - A) and after (B - model); rgba_before/after are over R, G, B, A for every model.
//
// sweep: error = C h^p, fitted in log space with the Cauchy loss (CompareConstants.h).
#pragma once
#include <string>
#include <vector>

#include "core/film/Image.h"

namespace volref::compare {

struct ModelFit {
    std::string model;                 // "gain", "opacity", "shift"
    std::vector<double> values;        // g | k | sx, sy
    std::string parameters;            // e.g. "g = 1.1"
    std::string judged_on;             // "RGBA" or "alpha": the values residual_* are over
    double residual_before = 0.0;      // RMS of B - A over the values the model is judged on
    double residual_after = 0.0;       // RMS of B - model(A) over the same
    double rgba_before = 0.0, rgba_after = 0.0;  // the same over R, G, B, A
    bool fitted = false;               // false: not applicable (see note)
    std::string note;                  // why not applicable
    double ratio() const { return residual_before > 0.0 ? residual_after / residual_before : 1.0; }
};

ModelFit fit_gain(const Image& a, const Image& b);
ModelFit fit_opacity_exponent(const Image& a, const Image& b);
ModelFit fit_shift(const Image& a, const Image& b);

// A convention B might differ in: B re-rendered with it changed (`image`), or not applicable (`note`).
struct ConventionVariant {
    std::string model;        // "normal", "ray-box", "mip-opacity"
    std::string description;  // for the verdict, e.g. "a flipped normal under one-sided lighting"
    bool applicable = false;
    std::string note;         // why not applicable
    Image image;              // B with the convention changed
};

// The convention model: before = RMS(B - A), after = RMS(variant - A) over R, G, B, A.
ModelFit fit_convention(const ConventionVariant& v, const Image& a, const Image& b);

struct DifferenceExplanation {
    std::vector<ModelFit> fits;  // gain, opacity, shift, then the conventions
    std::string verdict;         // one line: "likely cause: ..."
};

// All three fits and the verdict: the model with the smallest residual ratio after/before is the likely
// cause when that ratio is <= kExplainedResidualRatio; identical images have nothing to explain.
// Non-finite pixels are left out (finite_copies). `conventions`: B re-rendered with each convention
// changed (compare --scene), fitted after the three models and judged the same way.
DifferenceExplanation explain_difference(const Image& a, const Image& b,
                                         const std::vector<ConventionVariant>& conventions = {});

struct PowerLawFit {
    double c = 0.0, p = 0.0;   // error = c h^p
    int points = 0;            // points used (h > 0, error > 0)
    bool ok = false;           // false with fewer than 2 usable points (or equal h)
};

// Fits error = c h^p (robust, in log space). Points with h <= 0 or error <= 0 (or not finite) are dropped.
PowerLawFit fit_power_law(const std::vector<double>& h, const std::vector<double>& error);

// The h with c h^p = tolerance: (tolerance / c)^(1 / p).
double step_for_error(const PowerLawFit& fit, double tolerance);

}  // namespace volref::compare
