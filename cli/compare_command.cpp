// volref compare A B: metrics of the difference of two images, pixels over a tolerance, a heat map and
// (--fit) the convention parameters that best explain the difference (docs/compare.md).
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/CompareCommand.h"
#include "core/Error.h"
#include "core/compare/ComparedImage.h"
#include "core/compare/Fits.h"
#include "core/compare/HeatMap.h"
#include "core/compare/ImageMetrics.h"
#include "core/compare/MetricsJson.h"
#include "core/compare/Tolerance.h"

namespace volref::cli {

namespace {

using namespace volref::compare;

// "R,G,B,A" (each in [0, 1]) -> RGBA; throws naming --background.
glm::dvec4 parse_background(const std::string& text) {
    glm::dvec4 v(0.0);
    std::stringstream ss(text);
    std::string item;
    int n = 0;
    while (std::getline(ss, item, ',')) {
        double x = 0.0;
        std::size_t used = 0;
        try {
            x = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != item.size() || n >= 4 || !(x >= 0.0 && x <= 1.0))
            throw Error("--background: expected R,G,B,A, four numbers in [0, 1], got '" + text + "'");
        v[n++] = x;
    }
    if (n != 4) throw Error("--background: expected R,G,B,A, four numbers in [0, 1], got '" + text + "'");
    return v;
}

std::string number(double v, const char* fmt = "%.6g") {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, fmt, v);
    return buf;
}


void print_row(const ChannelMetrics& c) {
    std::printf("%-7s %12s %12s %12s %9s %9s %10ld\n", c.name.c_str(), number(c.max_abs, "%.4e").c_str(),
                number(c.mean_abs, "%.4e").c_str(), number(c.rmse, "%.4e").c_str(), number(c.psnr, "%.2f").c_str(),
                c.ssim ? number(*c.ssim, "%.6f").c_str() : "n/a", c.over);
}

}  // namespace

int run_compare(const CompareArgs& args) {
    if (!args.heatmap.empty()) check_heatmap_path(args.heatmap);  // fail before any work
    if (!(args.heatmap_scale >= 0.0) || !std::isfinite(args.heatmap_scale))
        throw Error("--heatmap-scale: expected a number >= 0");
    std::optional<glm::dvec4> background;
    if (!args.background.empty()) background = parse_background(args.background);

    const ComparedImage a = read_compared_image(args.a, background);
    const ComparedImage b = read_compared_image(args.b, background);
    if (a.rgba.width != b.rgba.width || a.rgba.height != b.rgba.height)
        throw Error(args.a.string() + " is " + std::to_string(a.rgba.width) + "x" + std::to_string(a.rgba.height) +
                    " but " + args.b.string() + " is " + std::to_string(b.rgba.width) + "x" +
                    std::to_string(b.rgba.height) + ": compare needs images of the same size");

    const ToleranceSpec tspec{args.tolerance, args.tolerance_from_error};
    const std::vector<double> tolerance = tolerance_map(a, b, tspec);
    const ImageMetrics m = measure_difference(a.rgba, b.rgba, tolerance);
    const bool within = m.overall.over == 0;

    double scale = 0.0;
    if (!args.heatmap.empty()) {
        scale = args.heatmap_scale > 0.0 ? args.heatmap_scale : m.overall.max_abs;
        if (std::isnan(scale)) scale = 0.0;
        write_heatmap(max_abs_difference_map(a.rgba, b.rgba), a.rgba.width, a.rgba.height, scale, args.heatmap);
    }
    std::optional<DifferenceExplanation> fit;
    if (args.fit) fit = explain_difference(a.rgba, b.rgba);

    if (args.json) {
        nlohmann::json j;
        j["a"] = {{"path", a.path.string()}, {"description", a.description()}};
        j["b"] = {{"path", b.path.string()}, {"description", b.description()}};
        j["width"] = a.rgba.width;
        j["height"] = a.rgba.height;
        j["tolerance"] = describe_tolerance(a, b, tspec);
        for (const ChannelMetrics& c : m.channels) j["channels"][c.name] = channel_json(c, m.pixels);
        j["overall"] = channel_json(m.overall, m.pixels);
        j["pixels"] = m.pixels;
        j["pixels_over"] = m.overall.over;
        j["fraction_over"] = m.fraction_over();
        j["within_tolerance"] = within;
        if (!args.heatmap.empty()) j["heatmap"] = {{"path", args.heatmap.string()}, {"scale", scale}};
        if (fit) {
            for (const ModelFit& f : fit->fits)
                j["fit"][f.model] = {{"fitted", f.fitted},
                                     {"values", f.values},
                                     {"judged_on", f.judged_on},
                                     {"residual_before", f.residual_before},
                                     {"residual_after", f.residual_after},
                                     {"rgba_residual_before", f.rgba_before},
                                     {"rgba_residual_after", f.rgba_after},
                                     {"note", f.note}};
            j["fit"]["verdict"] = fit->verdict;
        }
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("A: %s (%s)\n", a.path.string().c_str(), a.description().c_str());
        std::printf("B: %s (%s)\n", b.path.string().c_str(), b.description().c_str());
        std::printf("compared as linear premultiplied RGBA; tolerance per pixel and channel: %s\n",
                    describe_tolerance(a, b, tspec).c_str());
        std::printf("%-7s %12s %12s %12s %9s %9s %10s\n", "channel", "max abs", "mean abs", "RMSE", "PSNR dB",
                    "SSIM", "over tol");
        for (const ChannelMetrics& c : m.channels) print_row(c);
        print_row(m.overall);
        std::printf("pixels over tolerance: %ld of %ld (%s)\n", m.overall.over, m.pixels,
                    number(m.fraction_over()).c_str());
        if (!args.heatmap.empty())
            std::printf("heat map: %s (max abs difference per pixel, 0 black -> %s white)\n",
                        args.heatmap.string().c_str(), number(scale).c_str());
        if (fit) {
            for (const ModelFit& f : fit->fits) {
                if (!f.fitted)
                    std::printf("fit %-8s not fitted: %s\n", f.model.c_str(), f.note.c_str());
                else if (f.judged_on == "RGBA")
                    std::printf("fit %-8s %s; RMS residual %s -> %s\n", f.model.c_str(), f.parameters.c_str(),
                                number(f.residual_before, "%.4e").c_str(), number(f.residual_after, "%.4e").c_str());
                else
                    std::printf("fit %-8s %s; RMS residual in %s %s -> %s (RGBA %s -> %s)\n", f.model.c_str(),
                                f.parameters.c_str(), f.judged_on.c_str(), number(f.residual_before, "%.4e").c_str(),
                                number(f.residual_after, "%.4e").c_str(), number(f.rgba_before, "%.4e").c_str(),
                                number(f.rgba_after, "%.4e").c_str());
            }
            std::printf("%s\n", fit->verdict.c_str());
        }
        std::printf("%s\n", within ? "within tolerance" : "NOT within tolerance");
    }
    return within ? 0 : 1;
}

}  // namespace volref::cli
