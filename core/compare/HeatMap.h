// The heat map of a difference image: per pixel d = max over channels |A - B| (ImageMetrics.h),
// t = clamp(d / scale, 0, 1), colour by the "hot" map of core/compare/CompareConstants.h
// (black 0 -> red 1/3 -> yellow 2/3 -> white 1), written as an opaque 8-bit RGBA PNG by volref's image
// writer (atomically).
#pragma once
#include <array>
#include <filesystem>
#include <vector>

namespace volref::compare {

// The colour of t in [0, 1] (clamped): r = min(1, 3t), g = clamp(3t - 1, 0, 1), b = clamp(3t - 2, 0, 1).
std::array<double, 3> hot_colour(double t);

// Throws volref::Error unless `path` ends in .png and its folder exists and is writable.
void check_heatmap_path(const std::filesystem::path& path);

// Writes the map (width * height values, row 0 at the top). scale <= 0: every pixel black, except
// NaN differences, which are white.
void write_heatmap(const std::vector<double>& difference, int width, int height, double scale,
                   const std::filesystem::path& path);

}  // namespace volref::compare
