// The structural similarity index of one channel of two images (Wang et al. 2004), with the window,
// constants and placement of core/compare/CompareConstants.h:
//   SSIM = mean over window positions of
//          (2 mu_a mu_b + C1)(2 sigma_ab + C2) / ((mu_a^2 + mu_b^2 + C1)(sigma_a^2 + sigma_b^2 + C2)),
//   mu = sum w x, sigma_a^2 = sum w a^2 - mu_a^2, sigma_ab = sum w a b - mu_a mu_b (w the Gaussian window).
#pragma once
#include <cstddef>
#include <optional>
#include <vector>

#include "core/film/Image.h"

namespace volref::compare {

// The normalised 1-D Gaussian weights g_k, k = -(n-1)/2 .. (n-1)/2, sum 1; the 2-D window is g_i g_j.
std::vector<double> ssim_window_1d();

// SSIM of channel `channel` of a and b (same size). nullopt when the image is smaller than the window.
std::optional<double> ssim(const Image& a, const Image& b, std::size_t channel);

}  // namespace volref::compare
