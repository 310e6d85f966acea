// volref compare A B: metrics of the difference of two images, pixels over a tolerance, a heat map and
// (--fit) the convention parameters that best explain the difference (docs/compare.md).
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/CompareCommand.h"
#include "core/Error.h"
#include "core/compare/ComparedImage.h"
#include "core/compare/ConventionSearch.h"
#include "core/compare/Fits.h"
#include "core/compare/HeatMap.h"
#include "core/compare/ImageMetrics.h"
#include "core/compare/MetricsJson.h"
#include "core/compare/Tolerance.h"
#include "core/film/Background.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

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

// B's scene re-rendered with each convention changed: the vtk-js profile's options
// flip_normal (shaded composite, one-sided lighting), ray_box and mip_correction (mip/minip). Other
// profiles: not applicable (no such option).
std::vector<ConventionVariant> convention_variants(const std::filesystem::path& path,
                                                   const std::optional<glm::dvec4>& background) {
    const Scene base = load_scene(path);
    std::vector<ConventionVariant> out(3);
    out[0].model = "normal";
    out[1].model = "ray-box";
    out[2].model = "mip-opacity";
    const ProfileOptions& o = base.render.profile_options;
    out[0].description = "a flipped normal under one-sided lighting";
    out[1].description = o.ray_box_domain ? "a ray box half a voxel larger (the texel box)"
                                          : "a ray box half a voxel smaller (the grid's domain, not the texel box)";
    out[2].description = o.mip_correction ? "MIP without opacity correction" : "opacity correction applied to MIP";
    const bool vtk_js = base.render.profile == ProfileId::VtkJs;
    const bool mip = is_extremum(base.render.projection);
    const VolumeSpec& vs = base.volumes.front();
    const bool one_sided_shaded = is_composite(base.render.projection) && vs.shading && !vs.shading->two_sided;
    for (ConventionVariant& v : out) v.note = "only the vtk-js profile's conventions are re-rendered (render.profile)";
    if (!vtk_js) return out;
    out[0].applicable = one_sided_shaded;
    if (!one_sided_shaded) out[0].note = "the scene is not a shaded composite with one-sided lighting";
    out[1].applicable = true;
    out[2].applicable = mip;
    if (!mip) out[2].note = "the scene's projection is not mip or minip";
    for (int k = 0; k < 3; ++k) {
        if (!out[std::size_t(k)].applicable) continue;
        Scene s = base;
        ProfileOptions& po = s.render.profile_options;
        if (k == 0) po.flip_normal = !po.flip_normal;
        if (k == 1) po.ray_box_domain = !po.ray_box_domain;
        if (k == 2) po.mip_correction = !po.mip_correction;
        Image im = render_scene(s);
        if (background)  // as read_compared_image composites an associated input
            for (std::size_t p = 0; p < im.pixels.size(); p += im.channels.size()) composite_over_background(&im.pixels[p], *background);
        out[std::size_t(k)].image = std::move(im);
    }
    return out;
}

}  // namespace

namespace {

// The report as JSON (--json).
void print_json(const CompareArgs& args, const ComparedImage& a, const ComparedImage& b, const ToleranceSpec& tspec,
                 const ImageMetrics& m, const std::vector<std::array<int, 2>>& faults, bool within,
                 const std::optional<DifferenceExplanation>& fit, const std::optional<SearchResult>& search, double scale) {
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
    j["non_finite"] = {{"a", m.non_finite_a}, {"b", m.non_finite_b}, {"disagree", m.non_finite_disagree}};
    j["fault"] = nlohmann::json::array();
    for (const auto& f : faults) j["fault"].push_back({f[0], f[1]});
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
                                 {"note", f.note},
                                 {"parameters", f.parameters}};
        j["fit"]["verdict"] = fit->verdict;
    }
    if (search) {  // {"explained", "rules", "unexplained_pixels", "residual_max", ...} at the top level
        const nlohmann::json sj = search->to_json();  // compare's own "tolerance", "pixels" kept: the search's are search_*
        for (auto it = sj.begin(); it != sj.end(); ++it) j[j.contains(it.key()) ? "search_" + it.key() : it.key()] = it.value();
    }
    std::printf("%s\n", j.dump(2).c_str());
}

// The report as text.
void print_text(const CompareArgs& args, const ComparedImage& a, const ComparedImage& b, const ToleranceSpec& tspec,
                 const ImageMetrics& m, const std::vector<std::array<int, 2>>& faults, bool within,
                 const std::optional<DifferenceExplanation>& fit, const std::optional<SearchResult>& search, double scale) {
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
    if (!faults.empty())
        std::printf("%zu pixels where the mirrored program does not finish (fault channel): left out of the metrics "
                    "and the tolerance test\n", faults.size());
    if (m.non_finite_a > 0 || m.non_finite_b > 0)
        std::printf("non-finite pixels: %ld in A, %ld in B, %ld disagreeing (those are over the tolerance); all left "
                    "out of the metrics and the fit\n", m.non_finite_a, m.non_finite_b, m.non_finite_disagree);
    if (!args.heatmap.empty())
        std::printf("heat map: %s (%s per pixel, 0 black -> %s white)\n", args.heatmap.string().c_str(),
                    search ? "the residual the search's best set leaves" : "max abs difference", number(scale).c_str());
    if (fit) {
        for (const ModelFit& f : fit->fits) {
            if (!f.fitted)
                std::printf("fit %-8s not fitted: %s\n", f.model.c_str(), f.note.c_str());
            else if (f.judged_on == "RGBA" && f.model != "gain" && f.model != "shift")
                std::printf("fit %-8s %s: RMS residual %s -> %s\n", f.model.c_str(), f.parameters.c_str(),
                            number(f.residual_before, "%.4e").c_str(), number(f.residual_after, "%.4e").c_str());
            else if (f.judged_on == "RGBA")
                std::printf("fit %-8s %s; RMS residual %s -> %s\n", f.model.c_str(), f.parameters.c_str(),
                            number(f.residual_before, "%.4e").c_str(), number(f.residual_after, "%.4e").c_str());
            else
                std::printf("fit %-8s %s; RMS residual in %s %s -> %s (RGBA %s -> %s)\n", f.model.c_str(),
                            f.parameters.c_str(), f.judged_on.c_str(), number(f.residual_before, "%.4e").c_str(),
                            number(f.residual_after, "%.4e").c_str(), number(f.rgba_before, "%.4e").c_str(),
                            number(f.rgba_after, "%.4e").c_str());
        }
        if (!search) std::printf("%s\n", fit->verdict.c_str());  // with --scene the search's verdict is the answer
    }
    if (search) {
        std::printf("convention search: %zu sets rendered (rules of render.profile, image models); tolerance %s per channel\n",
                    search->tried.size(), number(search->tolerance).c_str());
        std::printf("%s\n", search->verdict.c_str());
    }
    if (search)  // the exit status is the search's
        std::printf("A against B: %s; %s\n", within ? "within tolerance" : "NOT within tolerance",
                    search->explained ? "explained (exit 0)" : "NOT explained (exit 1)");
    else
        std::printf("%s\n", within ? "within tolerance" : "NOT within tolerance");
}

}  // namespace

int run_compare(const CompareArgs& args) {
    if (!args.heatmap.empty()) check_heatmap_path(args.heatmap);  // fail before any work
    if (!(args.heatmap_scale >= 0.0) || !std::isfinite(args.heatmap_scale))
        throw Error("--heatmap-scale: expected a number >= 0");
    std::optional<glm::dvec4> background;
    if (!args.background.empty()) background = parse_background(args.background);

    if (!args.scene.empty() && !args.fit) throw Error("--scene: only with --fit");
    if (args.b.empty() && args.scene.empty()) throw Error("b: required (image B), unless --fit --scene SCENE renders it");
    ComparedImage a = read_compared_image(args.a, background);
    std::optional<Scene> scene;
    if (!args.scene.empty()) scene = load_scene(args.scene);
    ComparedImage b;
    Image scene_render;  // B when compare renders it: the search's base render too
    if (!args.b.empty()) {
        b = read_compared_image(args.b, background);
    } else {  // B is the scene rendered, composited as read_compared_image composites an EXR
        b.path = args.scene.string() + " (rendered)";
        scene_render = render_scene(*scene);
        const Image& im = scene_render;
        b.rgba = Image(im.width, im.height, {"R", "G", "B", "A"});
        const std::size_t C = im.channels.size();
        for (std::size_t p = 0; p < std::size_t(im.width) * std::size_t(im.height); ++p) {
            for (std::size_t c = 0; c < 4; ++c) b.rgba.pixels[p * 4 + c] = im.pixels[p * C + c];
            for (std::size_t c = 4; c < C; ++c)
                if (im.channels[c] == "error") b.error.push_back(im.pixels[p * C + c]);
            if (background) composite_over_background(&b.rgba.pixels[p * 4], *background);
        }
    }
    if (a.rgba.width != b.rgba.width || a.rgba.height != b.rgba.height)
        throw Error(args.a.string() + " is " + std::to_string(a.rgba.width) + "x" + std::to_string(a.rgba.height) +
                    " but " + args.b.string() + " is " + std::to_string(b.rgba.width) + "x" +
                    std::to_string(b.rgba.height) + ": compare needs images of the same size");

    // Pixels where a mirrored program does not finish (either image's `fault` channel) are
    // reported apart and left out of the metrics and the tolerance test (0 in both).
    const std::vector<std::array<int, 2>> faults = exclude_faults(a, b);
    const ToleranceSpec tspec{args.tolerance, args.tolerance_from_error};
    const std::vector<double> tolerance = tolerance_map(a, b, tspec);
    const ImageMetrics m = measure_difference(a.rgba, b.rgba, tolerance);
    const bool within = m.overall.over == 0;

    std::optional<DifferenceExplanation> fit;
    if (args.fit)
        fit = explain_difference(a.rgba, b.rgba,
                                 args.scene.empty() ? std::vector<ConventionVariant>{} : convention_variants(args.scene, background));
    // The rules of the scene's profile and the image models that explain A (ConventionSearch.h)
    std::optional<SearchResult> search;
    if (scene) {
        SearchOptions so;
        so.tolerance = args.tolerance > 0.0 ? args.tolerance : -1.0;
        so.background = background;
        if (args.b.empty()) so.base_render = &scene_render;
        search = search_conventions(a, *scene, so);
    }
    double scale = 0.0;
    if (!args.heatmap.empty()) {  // with a search: the residual its best set leaves (the unexplained pixels)
        const std::vector<double> map = search ? search->residual : max_abs_difference_map(a.rgba, b.rgba);
        double largest = 0.0;
        for (double x : map) largest = std::max(largest, x);
        scale = args.heatmap_scale > 0.0 ? args.heatmap_scale : (search ? largest : m.overall.max_abs);
        if (std::isnan(scale)) scale = 0.0;
        write_heatmap(map, a.rgba.width, a.rgba.height, scale, args.heatmap);
    }

    if (args.json) print_json(args, a, b, tspec, m, faults, within, fit, search, scale);
    else print_text(args, a, b, tspec, m, faults, within, fit, search, scale);
    // With --scene: 0 when the search explains A (ConventionSearch.h), 1 when it does not.
    if (search) return search->explained ? 0 : 1;
    return within ? 0 : 1;
}

}  // namespace volref::cli
