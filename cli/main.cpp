// The volref command line. Exit status: 0 success; 1 bad input or failure (one line on stderr,
// "volref: error: ..."); 2 usage errors (CLI11's message); 128 + signal when interrupted by SIGINT
// (130) or SIGTERM (143), with no output written (core/Cancellation.h).
#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/Commands.h"
#include "cli/ExplainCommand.h"
#include "cli/TraceCommand.h"
#include "cli/ConvertCommand.h"
#include "cli/InfoCommand.h"
#include "cli/CompareCommand.h"
#include "cli/SweepCommand.h"
#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"

namespace {
extern "C" void on_signal(int signal) { volref::request_cancel(signal); }

void install_signal_handlers() {
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}
}  // namespace

namespace {

// `volref render`'s options into `args`.
CLI::App* add_render(CLI::App& app, volref::cli::RenderArgs& render) {
    CLI::App* rc = app.add_subcommand("render", "Render a scene file to an image (.exr, .png, .tif)");
    rc->add_option("scene", render.scene, "Scene file (JSON)")->required();
    rc->add_option("-o,--output", render.output, "Output image; the format follows the extension")->required();
    rc->add_option("--threads", render.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 4096));
    rc->add_flag("--no-skipping", render.no_skipping,
                 "Sample every segment (no empty-space skipping); the image is the same, only slower");
    rc->add_flag("--error", render.error,
                 "Fixed-step integrator: also render at step/2 and write the step-doubling error estimate as the "
                 "EXR `error` channel (the adaptive integrator always writes its own)");
    rc->add_flag("--timing", render.timing,
                 "Print one line on stderr: volref: timing {\"setup_s\", \"frames_s\", \"median_s\", \"samples\", "
                 "\"samples_per_s\", \"threads\"} (frame time only: no reading, generation or set-up)");
    rc->add_option("--repeat", render.repeat, "Render the frame N times after one set-up (default 1; the image is written once)")
        ->check(CLI::Range(1, 100000));
    rc->add_option("--set", render.overrides, "Override one scene value: PATH=VALUE (e.g. render.step=0.25)")
        ->take_all();
    return rc;
}

// `volref resample`'s options into `args`.
CLI::App* add_resample(CLI::App& app, volref::cli::ResampleArgs& resample) {
    CLI::App* rs = app.add_subcommand(
        "resample", "Resample a volume between Cartesian and beam-space (cylindrical, spherical) grids; writes NRRD");
    rs->add_option("input", resample.input, "Input volume (.nrrd, .nhdr, .raw)")->required();
    rs->add_option("output", resample.output, "Output volume (.nrrd)")->required();
    rs->add_option("--to", resample.to, "Output grid: cylindrical, spherical or cartesian")->required();
    rs->add_option("--dims", resample.dims, "Output grid size NX,NY,NZ (a shell's in its grid-axis order)")->required();
    rs->add_option("--shell", resample.shell,
                   "The shell as JSON text or a JSON file (scene volume.bounds); --to cartesian: default IN's volref_bounds");
    rs->add_option("--interpolation", resample.interpolation,
                   "nearest, trilinear (default), tricubic-bspline, tricubic-catmull-rom");
    rs->add_option("--origin", resample.origin, "--to cartesian: X,Y,Z of voxel (0,0,0) (with --spacing)");
    rs->add_option("--spacing", resample.spacing, "--to cartesian: SX,SY,SZ (default: the shell's bounding box)");
    rs->add_option("--fill", resample.fill, "Value of samples outside the source (default 0)");
    rs->add_option("--type", resample.type, "Output type: f64 (default) or f32");
    rs->add_option("--encoding", resample.encoding, "Output encoding: raw (default) or gzip");
    rs->add_option("--format", resample.format, "Input format: nrrd or raw (default: from the extension)");
    return rs;
}

// `volref compare`'s options into `args`.
CLI::App* add_compare(CLI::App& app, volref::cli::CompareArgs& compare) {
    CLI::App* cmp = app.add_subcommand(
        "compare", "Compare two images: max abs, mean abs, RMSE, PSNR, SSIM, pixels over a tolerance; exit 0 within "
                   "tolerance, 1 not, 2 usage or input errors (docs/compare.md)");
    cmp->add_option("a", compare.a, "Image A (any format OpenImageIO reads; e.g. volref's EXR)")->required();
    cmp->add_option("b", compare.b, "Image B, the same size (optional with --scene: B is then the scene rendered)");
    cmp->add_option("--tolerance", compare.tolerance, "Absolute tolerance per channel (default 0)")
        ->check(CLI::NonNegativeNumber);
    cmp->add_flag("--tolerance-from-error", compare.tolerance_from_error,
                  "Add each input's per-pixel `error` channel (volref EXR) to the tolerance");
    cmp->add_option("--background", compare.background,
                    "R,G,B,A: composite premultiplied (EXR) inputs over this background first");
    cmp->add_option("--heatmap", compare.heatmap, "Write a heat map of the per-pixel max abs difference (PNG)");
    cmp->add_option("--heatmap-scale", compare.heatmap_scale,
                    "Difference shown white in the heat map (default: the max abs difference)")
        ->check(CLI::NonNegativeNumber);
    cmp->add_flag("--fit", compare.fit, "Fit a gain, an opacity exponent and a sub-pixel shift; name the likely cause");
    cmp->add_flag("--json", compare.json, "Print the report as JSON");
    cmp->add_option("--scene", compare.scene,
                    "With --fit: the scene A is a render of (B: volref's render of it); the scene is re-rendered with its "
                    "profile's rules changed, one and then two at a time, and under image models (flip, premultiplication, "
                    "BGRA, sRGB), naming the set that explains A (docs/compare.md, \"Convention search\")");
    return cmp;
}

// `volref info`'s options into `args`.
CLI::App* add_info(CLI::App& app, volref::cli::InfoArgs& info) {
    CLI::App* ic = app.add_subcommand("info", "Print a volume file's dims, type, spacing, origin, value range and histogram");
    ic->add_option("file", info.input, "Volume file (.nrrd .nhdr .raw .nii .nii.gz .mhd .mha .vtk .vti .den)")->required();
    ic->add_option("--format", info.format, "nrrd, raw, nifti, metaimage, vtk, vti or den (default: from the extension)");
    ic->add_flag("--json", info.json, "Print JSON instead of text");
    ic->add_option("--bins", info.bins, "Histogram bins (default 16)");
    return ic;
}

// `volref convert`'s options into `args`.
CLI::App* add_convert(CLI::App& app, volref::cli::ConvertArgs& convert) {
    CLI::App* cv = app.add_subcommand("convert", "Convert a volume file to NRRD (.nrrd) or raw + JSON sidecar (.raw)");
    cv->add_option("input", convert.input, "Input volume (any format `volref info` reads)")->required();
    cv->add_option("output", convert.output, "Output volume: .nrrd or .raw (+ .raw.json)")->required();
    cv->add_option("--format", convert.format, "Input format (default: from the extension)");
    cv->add_option("--type", convert.type, "Output type: f64 (NRRD default) or f32; raw: u8..f64 (default: the input's)");
    cv->add_option("--encoding", convert.encoding, "raw (default) or gzip");
    return cv;
}

// `volref trace`'s options into `args`.
CLI::App* add_trace(CLI::App& app, volref::cli::TraceArgs& trace) {
    CLI::App* tc = app.add_subcommand("trace", "Every sample along one pixel's ray, as CSV or JSON (docs/trace.md)");
    tc->add_option("scene", trace.scene, "Scene file (JSON)")->required();
    tc->add_option("--pixel", trace.pixel, "The pixel X,Y (x right, y down from the top-left corner)")->required();
    tc->add_option("--format", trace.format, "csv or json (default: json if -o ends in .json, else csv)");
    tc->add_option("-o,--output", trace.output, "Output file (default: standard output)");
    tc->add_flag("--no-skipping", trace.no_skipping, "List every segment (no empty-space skipping)");
    tc->add_option("--set", trace.overrides, "Override one scene value: PATH=VALUE")->take_all();
    return tc;
}

// `volref explain`'s options into `args`.
CLI::App* add_explain(CLI::App& app, volref::cli::ExplainArgs& explain) {
    CLI::App* ex = app.add_subcommand("explain", "Work one formula step by step with the renderer's own functions "
                                                 "(docs/explain.md); --json for programs");
    ex->add_option("topic", explain.topic, std::string("One of: ") + volref::cli::explain_topics())->required();
    ex->fallthrough(false)->prefix_command()->allow_extras();  // the topic's options are parsed by run_explain (one-line errors naming the option)
    return ex;
}

// `volref sweep`'s options into `args`.
CLI::App* add_sweep(CLI::App& app, volref::cli::SweepArgs& sweep) {
    CLI::App* sw = app.add_subcommand(
        "sweep", "Render every combination of scene parameters, time each (median of N whole-process runs), measure "
                 "the error against a reference; table, sweep.csv, sweep.png/.svg (gnuplot), order of accuracy");
    sw->add_option("scene", sweep.scene, "Scene file (JSON)")->required();
    sw->add_option("--param", sweep.params, "PATH=V1,V2,...: a scene key and its values (as --set); repeatable")
        ->required()
        ->take_all();
    sw->add_option("--reference", sweep.reference,
                   "adaptive (render.integrator=adaptive) or fine (fixed step = smallest swept step / 16); default: "
                   "adaptive when available");
    sw->add_option("--repeat", sweep.repeat, "Runs per combination; the median wall time is reported (default 3)")
        ->check(CLI::Range(1, 1000));
    sw->add_option("--tolerance", sweep.tolerance, "Max abs error per channel to count pixels over and predict a step for "
                                                   "(default 1e-3)")
        ->check(CLI::PositiveNumber);
    sw->add_option("-o,--output", sweep.output, "Folder for sweep.csv, sweep.png, sweep.svg (default: .)");
    sw->add_option("--threads", sweep.threads, "Worker threads of each render (default: all cores)")
        ->check(CLI::Range(1, 4096));
    sw->add_option("--set", sweep.overrides, "Override one scene value for every render: PATH=VALUE")->take_all();
    return sw;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"volref: a CPU reference volume ray caster, the numerical oracle for GPU volume renderers"};
    app.require_subcommand(1);
    // Options of every command; they may also follow the command's name (fallthrough).
    app.fallthrough();
    std::string max_memory;
    app.add_option("--max-memory", max_memory,
                   "Refuse a volume, image or cache needing more than SIZE (e.g. 512M, 4G); default: physical memory")
        ->envname("VOLREF_MAX_MEMORY");

    volref::cli::RenderArgs render;
    CLI::App* rc = add_render(app, render);
    volref::cli::ResampleArgs resample;
    CLI::App* rs = add_resample(app, resample);
    volref::cli::CompareArgs compare;
    CLI::App* cmp = add_compare(app, compare);
    volref::cli::InfoArgs info;
    CLI::App* ic = add_info(app, info);
    volref::cli::ConvertArgs convert;
    CLI::App* cv = add_convert(app, convert);
    volref::cli::TraceArgs trace;
    CLI::App* tc = add_trace(app, trace);
    volref::cli::ExplainArgs explain;
    CLI::App* ex = add_explain(app, explain);
    volref::cli::SweepArgs sweep;
    CLI::App* sw = add_sweep(app, sweep);

    // ---- more subcommands: add each one's block above this line ----

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // CLI11 prints the message (and --help's text); usage errors exit 2, --help exits 0.
        return app.exit(e) == 0 ? 0 : 2;
    }
    install_signal_handlers();
    try {
        if (!max_memory.empty()) volref::set_memory_limit(volref::parse_memory_size(max_memory, "--max-memory"));
        if (rc->parsed()) return volref::cli::run_render(render);
        if (rs->parsed()) return volref::cli::run_resample(resample);
        if (cmp->parsed()) {
            // compare's exit status 1 means "differs": bad input exits 2 (docs/compare.md).
            try {
                return volref::cli::run_compare(compare);
            } catch (const volref::Cancelled&) {
                throw;
            } catch (const std::exception& e) {
                std::fprintf(stderr, "volref: error: %s\n", e.what());
                return 2;
            }
        }
        if (ic->parsed()) return volref::cli::run_info(info);
        if (cv->parsed()) return volref::cli::run_convert(convert);
        if (tc->parsed()) return volref::cli::run_trace(trace);
        if (ex->parsed()) {
            explain.args = ex->remaining();
            return volref::cli::run_explain(explain);
        }
        if (sw->parsed()) return volref::cli::run_sweep(sweep);
        // ---- more subcommands: dispatch above this line ----
    } catch (const volref::Cancelled& e) {
        std::fprintf(stderr, "\nvolref: %s\n", e.what());
        return 128 + e.signal();
    } catch (const volref::Error& e) {
        std::fprintf(stderr, "volref: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "volref: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "volref: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
