// Differences between two images of the same size and channels, per channel and overall
// (used by `volref compare` and `volref sweep`). With d = a - b over the N values of a channel:
//   max abs = max |d|,  mean abs = sum |d| / N,  RMSE = sqrt(sum d^2 / N),
//   PSNR = 10 log10(peak^2 / MSE) dB (peak 1; +infinity when MSE = 0),
//   SSIM (core/compare/Ssim.h), over = pixels with |d| > tol in that channel.
// Overall: the same over every channel's values (N = pixels x channels); SSIM = the mean of the
// channels' SSIMs; over = pixels over the tolerance in any channel. Sums are accumulated in double.
// Non-finite values (vtk.js's float framebuffer holds NaN where alpha is 0): a value pair
// (a, b) with a non-finite member never enters the sums, the maxima or SSIM (N counts finite pairs;
// SSIM and the fits see such pixels as 0 in both images, finite_copies). The pair agrees when both are
// NaN or both the same infinity, and is then within any tolerance; otherwise it is over the tolerance.
// The pixels with a non-finite value in a, in b, and with a disagreeing pair are counted.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/film/Image.h"

namespace volref::compare {

struct ChannelMetrics {
    std::string name;
    double max_abs = 0.0, mean_abs = 0.0, rmse = 0.0;
    double psnr = 0.0;              // dB; +infinity for identical values
    std::optional<double> ssim;     // none when the image is smaller than the SSIM window
    long over = 0;                  // pixels over the tolerance (in this channel; overall: in any)
};

struct ImageMetrics {
    std::vector<ChannelMetrics> channels;
    ChannelMetrics overall;
    long pixels = 0;
    long non_finite_a = 0, non_finite_b = 0;  // pixels with a non-finite value in a (b)
    long non_finite_disagree = 0;             // pixels with a non-finite pair that does not agree
    double fraction_over() const { return pixels > 0 ? double(overall.over) / double(pixels) : 0.0; }
};

// PSNR in dB of a mean squared error: 10 log10(kPsnrPeak^2 / mse); +infinity for mse = 0.
double psnr_db(double mse);

// The metrics of a against b. `tolerance` holds tol(p, c) interleaved like the pixels (width * height *
// channels) or is empty (tolerance 0). Throws volref::Error if sizes or channel counts differ.
// `with_ssim` = false skips SSIM (the sweep does not report it).
ImageMetrics measure_difference(const Image& a, const Image& b, const std::vector<double>& tolerance = {},
                                bool with_ssim = true);

// Copies of a and b with every pixel that has a non-finite value in either set to 0 in both.
void finite_copies(const Image& a, const Image& b, Image& a_out, Image& b_out);

// Per pixel: max over channels of |a - b| (width * height, row 0 at the top); NaN (the heat map's
// white) where a non-finite pair disagrees; agreeing non-finite pairs add nothing.
std::vector<double> max_abs_difference_map(const Image& a, const Image& b);

}  // namespace volref::compare
