// Every numerical choice of `volref compare` and `volref sweep`, in one place, each with its formula.
// docs/compare.md states the same choices for users; change both together.
#pragma once

namespace volref::compare {

// PSNR = 10 log10(kPsnrPeak^2 / MSE) dB, MSE the mean of squared differences. The peak is 1: images
// are compared as linear values in [0, 1] (8-bit 255 -> 1), whatever their file type. A constant
// difference of 0.01 gives 40 dB; identical images give +infinity.
inline constexpr double kPsnrPeak = 1.0;

// SSIM (Wang, Bovik, Sheikh, Simoncelli 2004, "Image quality assessment: from error visibility to
// structural similarity"), as their reference code ssim_index.m computes it, on each channel:
//   SSIM(x, y) = (2 mu_x mu_y + C1)(2 sigma_xy + C2) / ((mu_x^2 + mu_y^2 + C1)(sigma_x^2 + sigma_y^2 + C2))
// with mu, sigma^2, sigma_xy the weighted mean, variance and covariance over a kSsimWindow x kSsimWindow
// Gaussian window of standard deviation kSsimSigma pixels (weights exp(-(dx^2 + dy^2) / (2 sigma^2)),
// normalised to sum 1), placed at every position where it lies wholly inside the image ("valid");
// the channel's SSIM is the mean over those positions. C1 = (K1 L)^2, C2 = (K2 L)^2, dynamic range L = 1.
// No downsampling. An image smaller than the window in either direction has no SSIM (reported n/a).
inline constexpr int kSsimWindow = 11;
inline constexpr double kSsimSigma = 1.5;
inline constexpr double kSsimK1 = 0.01;
inline constexpr double kSsimK2 = 0.03;
inline constexpr double kSsimDynamicRange = 1.0;

// Quantisation of an integer image of b bits (PNG 8, TIFF 16): a stored value s = round(v (2^b - 1))
// is within q = kQuantisationHalfStep / (2^b - 1) of v (0.5 / 255 for 8 bits). After converting its
// unassociated colour u_s and alpha a_s to premultiplied u_s a_s, the bound on |u_s a_s - u a| is
//   colour: q (a_s + u_s) + q^2   (u = u_s - e1, a = a_s - e2, |e1|, |e2| <= q),   alpha: q,
// and q on every channel of an image without unassociated alpha. Each integer input adds its own bound
// to the tolerance, pixel by pixel.
inline constexpr double kQuantisationHalfStep = 0.5;

// Heat map: pixel value d = max over the compared channels of |A - B|, mapped by t = clamp(d / S, 0, 1)
// (S = --heatmap-scale, default the image's max abs difference; S = 0 maps everything to black) through
// the "hot" colour map: black (t = 0) -> red (1/3) -> yellow (2/3) -> white (1), linear in each third:
//   r = min(1, 3t), g = clamp(3t - 1, 0, 1), b = clamp(3t - 2, 0, 1); stored as an opaque 8-bit RGBA PNG
// (each value round(255 v)). (core/compare/HeatMap.cpp)

// (--fit) At most kFitMaxPixels pixels enter a fit, every k-th in scan order with k = ceil(N / max);
// residuals before and after are computed over all pixels.
inline constexpr long kFitMaxPixels = 65536;

// (--fit) A model is the "likely cause" when it brings the RMS residual down to at most this fraction of
// the RMS difference before the fit (0.5 in RMS = three quarters of the squared difference explained).
inline constexpr double kExplainedResidualRatio = 0.5;

// (--fit) The sub-pixel shift is searched within +-kMaxShiftPixels; the residual is taken over the
// pixels at least kMaxShiftPixels from every border (so every shifted source stays inside the image).
inline constexpr double kMaxShiftPixels = 2.0;

// (--fit --scene, volref.fit: ConventionSearch.h) A pixel is explained by a set of rules when every
// channel of the re-rendered image is within kSearchTolerance (or --tolerance when > 0) of the other
// renderer's, plus the render's own error channel and the image's quantisation: 1e-4 is 30x the float32
// rounding of a 60-sample shader measured against volref (3.3e-6, tests/python/test_external_caster.py)
// and below every convention's effect on the test scenes (>= 3.3e-4). The set explains the image when at
// most kSearchUnexplainedFraction of its pixels stay unexplained (grazing rays, where float32 and double
// disagree on whether a ray enters the box). Every pair of single rules is rendered when (pairs x pixels)
// <= kSearchAllPairsPixels (about 250 pairs of a 256 x 256 image); above that, the pairs of the
// kSearchPairsOf single rules of smallest RMS residual. Sets grow to at most kSearchMaxRules rules.
inline constexpr double kSearchTolerance = 1e-4;
inline constexpr double kSearchUnexplainedFraction = 1e-3;
inline constexpr int kSearchPairsOf = 8;
inline constexpr double kSearchAllPairsPixels = 16777216.0;  // 2^24
inline constexpr int kSearchMaxRules = 4;

// (sweep) error = C h^p is fitted in log space, r_i = log e_i - log C - p log h_i, under the Cauchy loss
// rho(r^2) = s^2 log(1 + r^2 / s^2) with s = kPowerLawLossScale (a factor of about e^0.1 = 1.105 in the
// error): points far off the power law (a step too coarse for the asymptotic regime, an error at the
// reference's own level) weigh little. The start is the ordinary least-squares line through the logs.
inline constexpr double kPowerLawLossScale = 0.1;

// (sweep) The "fine" reference is the fixed-step render at the smallest swept render.step divided by
// this factor (16: a midpoint-rule error 256 times below the smallest swept step's).
inline constexpr double kFineReferenceDivisor = 16.0;

}  // namespace volref::compare
