// The metrics of one channel as `volref compare --json` writes them (and volref.compare in Python
// returns them): max_abs, mean_abs, rmse, psnr_db, ssim, pixels_over, fraction_over; a number that is
// not finite (PSNR of identical images) is null. One function for both, so they cannot drift apart.
#pragma once
#include <cmath>

#include <nlohmann/json.hpp>

#include "core/compare/ImageMetrics.h"

namespace volref::compare {

inline nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

inline nlohmann::json channel_json(const ChannelMetrics& c, long pixels) {
    return {{"max_abs", json_number(c.max_abs)},
            {"mean_abs", json_number(c.mean_abs)},
            {"rmse", json_number(c.rmse)},
            {"psnr_db", json_number(c.psnr)},
            {"ssim", c.ssim ? json_number(*c.ssim) : nlohmann::json(nullptr)},
            {"pixels_over", c.over},
            {"fraction_over", pixels > 0 ? double(c.over) / double(pixels) : 0.0}};
}

}  // namespace volref::compare
