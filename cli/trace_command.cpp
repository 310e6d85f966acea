// volref trace SCENE --pixel X,Y [--format csv|json] [-o FILE] [--no-skipping] [--set PATH=VALUE ...]
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli/TraceCommand.h"
#include "core/Error.h"
#include "core/explain/PixelTrace.h"
#include "core/io/OutputFile.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneLoader.h"

namespace volref::cli {

int run_trace(const TraceArgs& args) {
    std::string format = args.format;
    if (format.empty()) format = args.output.extension() == ".json" ? "json" : "csv";
    if (format != "csv" && format != "json") throw Error("--format: expected csv or json, got \"" + format + "\"");
    if (!args.output.empty()) check_output_folder(args.output);  // fail before any work
    const Scene scene = load_scene(args.scene, args.overrides);
    const auto pixel = explain::parse_pixel(args.pixel, scene.image.width, scene.image.height);
    if (is_first_hit(scene.render.projection)) throw Error("trace: first-hit is not supported yet");
    RenderOptions options;
    options.empty_space_skipping = !args.no_skipping;
    const PreparedScene prepared(scene, options);
    const explain::PixelTrace trace = explain::trace_pixel(prepared, pixel[0], pixel[1]);
    if (trace.pixel.fault)  // the CSV has no place for it; JSON carries it as "fault" too
        std::fprintf(stderr, "volref: pixel (%d, %d): the mirrored program does not finish this ray: %s\n", pixel[0],
                     pixel[1], trace.fault.c_str());
    std::ostringstream text;
    if (format == "json")
        text << explain::trace_json(trace) << '\n';
    else
        explain::write_trace_csv(trace, text);
    if (args.output.empty()) {
        std::cout << text.str();
        return 0;
    }
    const std::filesystem::path tmp = temporary_output_path(args.output);
    {
        std::ofstream out(tmp);
        out << text.str();
        if (!out.good()) {
            std::error_code ec;
            std::filesystem::remove(tmp, ec);
            throw Error(args.output.string() + ": cannot write");
        }
    }
    commit_output(tmp, args.output);
    std::fprintf(stderr, "volref: traced pixel (%d, %d): %zu samples\n", pixel[0], pixel[1], trace.samples.size());
    return 0;
}

}  // namespace volref::cli
