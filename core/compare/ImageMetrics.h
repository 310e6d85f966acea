// Differences between two images of the same size and channels, per channel and overall
// (used by `volref compare` and `volref sweep`). With d = a - b over the N values of a channel:
//   max abs = max |d|,  mean abs = sum |d| / N,  RMSE = sqrt(sum d^2 / N),
//   PSNR = 10 log10(peak^2 / MSE) dB (peak 1; +infinity when MSE = 0),
//   SSIM (core/compare/Ssim.h), over = pixels with |d| > tol in that channel.
// Overall: the same over every channel's values (N = pixels x channels); SSIM = the mean of the
// channels' SSIMs; over = pixels over the tolerance in any channel. Sums are accumulated in double.
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
    double fraction_over() const { return pixels > 0 ? double(overall.over) / double(pixels) : 0.0; }
};

// PSNR in dB of a mean squared error: 10 log10(kPsnrPeak^2 / mse); +infinity for mse = 0.
double psnr_db(double mse);

// The metrics of a against b. `tolerance` holds tol(p, c) interleaved like the pixels (width * height *
// channels) or is empty (tolerance 0). Throws volref::Error if sizes or channel counts differ.
// `with_ssim` = false skips SSIM (the sweep does not report it).
ImageMetrics measure_difference(const Image& a, const Image& b, const std::vector<double>& tolerance = {},
                                bool with_ssim = true);

// Per pixel: max over channels of |a - b| (width * height, row 0 at the top).
std::vector<double> max_abs_difference_map(const Image& a, const Image& b);

}  // namespace volref::compare
