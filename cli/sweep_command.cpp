// volref sweep: speed against error over a grid of scene parameters (docs/compare.md, docs/accuracy.md).
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <system_error>

#include "cli/SweepCommand.h"
#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/compare/ChildProcess.h"
#include "core/compare/CompareConstants.h"
#include "core/compare/ComparedImage.h"
#include "core/compare/Fits.h"
#include "core/compare/ImageMetrics.h"
#include "core/compare/SweepGrid.h"
#include "core/compare/SweepPlot.h"
#include "core/io/OutputFile.h"
#include "core/scene/SceneLoader.h"

namespace volref::cli {

namespace fs = std::filesystem;
using namespace volref::compare;

namespace {

constexpr const char* kStepPath = "render.step";

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
    return s;
}

// The value of "PATH=VALUE".
std::string value_of(const std::string& assignment) { return assignment.substr(assignment.find('=') + 1); }

double parse_step(const std::string& text) {
    std::size_t used = 0;
    double v = 0.0;
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !(v > 0.0) || !std::isfinite(v))
        throw Error(std::string("--param ") + kStepPath + ": expected numbers > 0, got '" + text + "'");
    return v;
}

std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

// A temporary folder for the renders, removed when the sweep ends (also on errors).
struct WorkDir {
    fs::path path;
    WorkDir() {
        std::string templ = (fs::temp_directory_path() / "volref-sweep-XXXXXX").string();
        if (!::mkdtemp(templ.data())) throw Error("sweep: cannot create a temporary folder in " +
                                                  fs::temp_directory_path().string());
        path = templ;
    }
    ~WorkDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

struct Row {
    std::vector<std::string> combo;  // PATH=VALUE per parameter
    std::size_t group = 0;
    double time_median = 0.0, time_min = 0.0, time_max = 0.0;
    ImageMetrics metrics;
};

}  // namespace

namespace {

// The scene loads with every combination (errors name the --param).
void check_combinations(const SweepArgs& args, const std::vector<std::vector<std::string>>& combos) {
    for (const auto& combo : combos) {
        std::vector<std::string> sets = args.overrides;
        sets.insert(sets.end(), combo.begin(), combo.end());
        try {
            load_scene(args.scene, sets);
        } catch (const Error& e) {
            throw Error("--param " + join(combo, " ") + ": " + e.what());
        }
    }
}

// The reference: adaptive when this volref has the adaptive integrator (and it was not refused), else
// the fixed-step render at the smallest swept step / kFineReferenceDivisor. Also the index of the
// swept render.step (-1: not swept).
struct SweepReference {
    std::string setting, text;
    std::ptrdiff_t step_param = -1;
};
SweepReference choose_reference(const SweepArgs& args, const Scene& base, const std::vector<SweepParam>& params) {
    std::string adaptive_refusal;
    {
        std::vector<std::string> sets = args.overrides;
        sets.push_back("render.integrator=adaptive");
        try {
            load_scene(args.scene, sets);
        } catch (const Error& e) {
            adaptive_refusal = e.what();
        }
    }
    const bool adaptive = args.reference == "adaptive" || (args.reference.empty() && adaptive_refusal.empty());
    if (adaptive && !adaptive_refusal.empty())
        throw Error("--reference adaptive: this volref cannot render the scene adaptively (" + adaptive_refusal +
                    "); use --reference fine");
    std::ptrdiff_t step_param = -1;
    for (std::size_t i = 0; i < params.size(); ++i)
        if (params[i].path == kStepPath) step_param = std::ptrdiff_t(i);
    double min_step = base.render.step;
    if (step_param >= 0) {
        min_step = INFINITY;
        for (const std::string& v : params[std::size_t(step_param)].values) min_step = std::min(min_step, parse_step(v));
    }
    const std::string reference_setting =
        adaptive ? std::string("render.integrator=adaptive")
                 : std::string(kStepPath) + "=" + fmt("%.17g", min_step / kFineReferenceDivisor);
    const std::string reference_text =
        adaptive ? "adaptive (render.integrator=adaptive, render.tolerance = " + fmt("%g", base.render.tolerance) + ")"
                 : "fine (" + std::string(kStepPath) + " = " + fmt("%g", min_step / kFineReferenceDivisor) +
                       ", the smallest swept step / " + fmt("%g", kFineReferenceDivisor) + ")";

    return SweepReference{reference_setting, reference_text, step_param};
}

// The table of the combinations: each swept value, the median time and the error metrics.
void print_table(const SweepArgs& args, const std::vector<SweepParam>& params, const std::vector<Row>& rows,
                 const std::string& reference_text) {
    std::vector<std::size_t> width;
    for (const SweepParam& p : params) {
        std::size_t w = p.path.size();
        for (const std::string& v : p.values) w = std::max(w, v.size());
        width.push_back(w);
    }
    std::printf("volref sweep: %s, %zu combination%s x %d run%s; reference: %s; tolerance %g\n",
                args.scene.string().c_str(), rows.size(), rows.size() == 1 ? "" : "s", args.repeat,
                args.repeat == 1 ? "" : "s", reference_text.c_str(), args.tolerance);
    for (std::size_t i = 0; i < params.size(); ++i) std::printf("%-*s  ", int(width[i]), params[i].path.c_str());
    std::printf("%10s  %11s  %11s  %9s  %9s\n", "time_s", "max_abs", "rmse", "psnr_db", "over_tol");
    for (const Row& r : rows) {
        for (std::size_t i = 0; i < params.size(); ++i)
            std::printf("%-*s  ", int(width[i]), value_of(r.combo[i]).c_str());
        const ChannelMetrics& m = r.metrics.overall;
        std::printf("%10.4f  %11.4e  %11.4e  %9s  %9.4f\n", r.time_median, m.max_abs, m.rmse,
                    std::isinf(m.psnr) ? "inf" : fmt("%.2f", m.psnr).c_str(), r.metrics.fraction_over());
    }

}

// The fits, per group: max abs error = C h^p over render.step (and the RMSE's), and the step for the tolerance.
void print_fits(const SweepArgs& args, const std::vector<std::vector<std::string>>& groups, const std::vector<Row>& rows,
                std::ptrdiff_t step_param) {
    for (std::size_t g = 0; g < groups.size(); ++g) {
        const std::string where = groups[g].empty() ? std::string() : " for " + join(groups[g], " ");
        if (step_param < 0) {
            std::printf("order p: not fitted (%s is not swept)\n", kStepPath);
            break;
        }
        std::vector<double> h, e, rmse;
        for (const Row& r : rows)
            if (r.group == g) {
                h.push_back(parse_step(value_of(r.combo[std::size_t(step_param)])));
                e.push_back(r.metrics.overall.max_abs);
                rmse.push_back(r.metrics.overall.rmse);
            }
        const PowerLawFit fit = fit_power_law(h, e);
        if (!fit.ok) {
            std::printf("order p: not fitted%s (fewer than 2 steps with a non-zero error)\n", where.c_str());
            continue;
        }
        std::printf("order p = %.4f%s (max abs error = %.4g h^p over %s, %d points, Cauchy loss scale %g)\n", fit.p,
                    where.c_str(), fit.c, kStepPath, fit.points, kPowerLawLossScale);
        // The RMSE's order too: the worst pixel (max abs) often converges later than the image as a whole.
        const PowerLawFit fit_rmse = fit_power_law(h, rmse);
        if (fit_rmse.ok)
            std::printf("order p (rmse) = %.4f%s (RMSE = %.4g h^p)\n", fit_rmse.p, where.c_str(), fit_rmse.c);
        const double h_tol = step_for_error(fit, args.tolerance);
        const double h_min = *std::min_element(h.begin(), h.end()), h_max = *std::max_element(h.begin(), h.end());
        std::printf("%s for max abs error <= %g: %.4g (%s)\n", kStepPath, args.tolerance, h_tol,
                    h_tol >= h_min && h_tol <= h_max ? "within the swept range" : "extrapolated");
    }

}

// The files: CSV, then the plots, all under temporary names until complete, then moved into place.
void write_outputs(const SweepArgs& args, const std::vector<SweepParam>& params, const std::vector<Row>& rows,
                   const std::vector<std::vector<std::string>>& groups, std::ptrdiff_t step_param,
                   const std::string& reference_text, const fs::path& work, const fs::path& csv_path,
                   const fs::path& png_path, const fs::path& svg_path) {
    const fs::path csv_tmp = temporary_output_path(csv_path), png_tmp = temporary_output_path(png_path),
                   svg_tmp = temporary_output_path(svg_path);
    struct Cleanup {
        std::vector<fs::path> paths;
        ~Cleanup() {
            std::error_code e;
            for (const auto& p : paths) fs::remove(p, e);
        }
    } cleanup{{csv_tmp, png_tmp, svg_tmp}};
    {
        std::ofstream csv(csv_tmp);
        for (const SweepParam& p : params) csv << csv_field(p.path) << ',';
        csv << "time_median_s,time_min_s,time_max_s,max_abs,mean_abs,rmse,psnr_db,pixels_over,fraction_over\n";
        for (const Row& r : rows) {
            for (const std::string& c : r.combo) csv << csv_field(value_of(c)) << ',';
            const ChannelMetrics& m = r.metrics.overall;
            csv << fmt("%.6g", r.time_median) << ',' << fmt("%.6g", r.time_min) << ',' << fmt("%.6g", r.time_max) << ','
                << fmt("%.9g", m.max_abs) << ',' << fmt("%.9g", m.mean_abs) << ',' << fmt("%.9g", m.rmse) << ','
                << (std::isinf(m.psnr) ? std::string("inf") : fmt("%.6g", m.psnr)) << ',' << m.over << ','
                << fmt("%.6g", r.metrics.fraction_over()) << '\n';
        }
        if (!csv) throw Error(csv_path.string() + ": cannot write");
    }
    PlotSpec plot;
    plot.title = "volref sweep: " + args.scene.filename().string() + "\nreference: " + reference_text;
    plot.tolerance = args.tolerance;
    for (std::size_t g = 0; g < groups.size(); ++g) {
        PlotSeries s;
        s.label = join(groups[g], ", ");
        for (const Row& r : rows)
            if (r.group == g) {
                s.time.push_back(r.time_median);
                s.max_abs.push_back(r.metrics.overall.max_abs);
                s.rmse.push_back(r.metrics.overall.rmse);
                s.point_labels.push_back(step_param >= 0 ? "h=" + value_of(r.combo[std::size_t(step_param)])
                                                         : join(r.combo, ", "));
            }
        plot.series.push_back(std::move(s));
    }
    plot_error_against_time(plot, work, png_tmp, svg_tmp);
    for (const auto& [from, to] : {std::pair{csv_tmp, csv_path}, {png_tmp, png_path}, {svg_tmp, svg_path}})
        commit_output(from, to);
}

}  // namespace

int run_sweep(const SweepArgs& args) {
    if (args.repeat < 1) throw Error("--repeat: expected an integer >= 1");
    if (!(args.tolerance > 0.0) || !std::isfinite(args.tolerance)) throw Error("--tolerance: expected a number > 0");
    if (!args.reference.empty() && args.reference != "adaptive" && args.reference != "fine")
        throw Error("--reference: expected adaptive or fine, got '" + args.reference + "'");
    if (args.params.empty()) throw Error("sweep: give at least one --param PATH=V1,V2,...");
    std::vector<SweepParam> params;
    for (const std::string& p : args.params) params.push_back(parse_sweep_param(p));
    const std::vector<std::vector<std::string>> combos = sweep_combinations(params);

    // Outputs: checked before any render.
    std::error_code ec;
    fs::create_directories(args.output, ec);
    if (ec || !fs::is_directory(args.output)) throw Error("-o " + args.output.string() + ": cannot create the folder");
    const fs::path csv_path = args.output / "sweep.csv", png_path = args.output / "sweep.png",
                   svg_path = args.output / "sweep.svg";
    check_output_folder(csv_path);
    if (!on_path("gnuplot")) throw Error("sweep: gnuplot not found on PATH (Debian: apt-get install gnuplot-nox)");

    const Scene base = load_scene(args.scene, args.overrides);
    check_combinations(args, combos);

    const SweepReference reference = choose_reference(args, base, params);
    const std::ptrdiff_t step_param = reference.step_param;
    const std::string& reference_setting = reference.setting;
    const std::string& reference_text = reference.text;

    // Groups: combinations that differ only in render.step share a reference (and a fit).
    std::vector<std::vector<std::string>> groups;
    std::map<std::vector<std::string>, std::size_t> group_of;
    std::vector<Row> rows;
    for (const auto& combo : combos) {
        std::vector<std::string> key;
        for (std::size_t i = 0; i < combo.size(); ++i)
            if (std::ptrdiff_t(i) != step_param) key.push_back(combo[i]);
        auto [it, inserted] = group_of.emplace(key, groups.size());
        if (inserted) groups.push_back(key);
        Row r;
        r.combo = combo;
        r.group = it->second;
        rows.push_back(std::move(r));
    }

    const WorkDir work;
    const std::string exe = self_executable().string();
    const bool progress = ::isatty(STDERR_FILENO) != 0;
    auto render = [&](const std::vector<std::string>& sets, const fs::path& out, const std::string& what) {
        std::vector<std::string> argv{exe, "render", args.scene.string(), "-o", out.string()};
        if (args.threads > 0) argv.insert(argv.end(), {"--threads", std::to_string(args.threads)});
        for (const std::string& s : sets) argv.insert(argv.end(), {"--set", s});
        throw_if_cancelled();
        const ProcessRun run = run_process(argv, work.path / "render.err");
        throw_if_cancelled();  // Ctrl-C reaches the child too: report the interruption, not its failure
        if (run.status != 0) throw Error("sweep: rendering " + what + " failed: " + run.first_error);
        return run.seconds;
    };

    std::vector<ComparedImage> references;
    for (std::size_t g = 0; g < groups.size(); ++g) {
        std::vector<std::string> sets = args.overrides;
        sets.insert(sets.end(), groups[g].begin(), groups[g].end());
        sets.push_back(reference_setting);
        const fs::path out = work.path / ("reference-" + std::to_string(g) + ".exr");
        if (progress) std::fprintf(stderr, "volref: sweep: reference %s\n", join(sets, " ").c_str());
        render(sets, out, "the reference (" + join(sets, " ") + ")");
        references.push_back(read_compared_image(out));
    }
    for (std::size_t i = 0; i < rows.size(); ++i) {
        Row& r = rows[i];
        std::vector<std::string> sets = args.overrides;
        sets.insert(sets.end(), r.combo.begin(), r.combo.end());
        const fs::path out = work.path / ("render-" + std::to_string(i) + ".exr");
        std::vector<double> times;
        for (int k = 0; k < args.repeat; ++k) {
            if (progress)
                std::fprintf(stderr, "volref: sweep %zu/%zu, run %d/%d: %s\n", i + 1, rows.size(), k + 1, args.repeat,
                             join(r.combo, " ").c_str());
            times.push_back(render(sets, out, join(r.combo, " ")));
        }
        r.time_median = median(times);
        r.time_min = *std::min_element(times.begin(), times.end());
        r.time_max = *std::max_element(times.begin(), times.end());
        const ComparedImage image = read_compared_image(out);
        const ComparedImage& ref = references[r.group];
        if (image.rgba.width != ref.rgba.width || image.rgba.height != ref.rgba.height)
            throw Error("sweep: " + join(r.combo, " ") + " renders a different image size than its reference");
        const std::vector<double> tol(image.rgba.pixels.size(), args.tolerance);
        r.metrics = measure_difference(image.rgba, ref.rgba, tol, false);
    }

    print_table(args, params, rows, reference_text);
    print_fits(args, groups, rows, step_param);
    write_outputs(args, params, rows, groups, step_param, reference_text, work.path, csv_path, png_path, svg_path);
    std::printf("wrote %s, %s, %s\n", csv_path.string().c_str(), png_path.string().c_str(), svg_path.string().c_str());
    return 0;
}

}  // namespace volref::cli
