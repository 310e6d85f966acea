// The plot of `volref sweep`: error against the reference versus median wall time per render, on
// log-log axes, drawn by gnuplot (run as a child process; Debian package gnuplot-nox) as PNG (pngcairo)
// and SVG. Max abs error: solid lines with filled points, each labelled with its parameter values;
// RMSE: dashed lines; the tolerance: a dotted grey line. Points with error 0 cannot sit on a log axis
// and are left out (the CSV keeps them).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace volref::compare {

struct PlotSeries {
    std::string label;                  // e.g. "volume.transfer.opacity_unit_distance=4", "" for one group
    std::vector<double> time, max_abs, rmse;
    std::vector<std::string> point_labels;  // e.g. "0.5" (the varying values of each point)
};

struct PlotSpec {
    std::string title;
    double tolerance = 0.0;             // drawn when > 0
    std::vector<PlotSeries> series;
};

// Writes the gnuplot data and script into `work_dir`, runs gnuplot, which writes `png` and `svg`.
// Throws volref::Error when gnuplot fails or nothing can be plotted.
void plot_error_against_time(const PlotSpec& spec, const std::filesystem::path& work_dir,
                             const std::filesystem::path& png, const std::filesystem::path& svg);

}  // namespace volref::compare
