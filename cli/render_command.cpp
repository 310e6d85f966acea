// volref render SCENE -o OUT [--threads N] [--no-skipping] [--error] [--timing] [--repeat N] [--set PATH=VALUE ...]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include "cli/Commands.h"
#include "core/film/ImageWriter.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

namespace volref::cli {

int run_render(const RenderArgs& args) {
    check_output_path(args.output);  // fail before any work
    const Scene scene = load_scene(args.scene, args.overrides);
    RenderOptions options;
    options.threads = args.threads;
    options.empty_space_skipping = !args.no_skipping;
    options.error_estimate = args.error;
    options.progress = ::isatty(STDERR_FILENO) != 0 && !args.timing;
    options.frames = args.repeat;
    options.count_samples = args.timing;
    const auto start = std::chrono::steady_clock::now();
    RenderStats stats;
    const Image image = render_scene(scene, options, &stats);
    for (const std::string& w : stats.warnings) std::fprintf(stderr, "volref: warning: %s\n", w.c_str());
    if (stats.non_finite_voxels > 0)
        std::fprintf(stderr, "volref: warning: %zu non-finite voxels (NaN or Inf), rendered as transparent\n",
                     stats.non_finite_voxels);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_image(image, args.output, scene.image.background);
    std::fprintf(stderr, "volref: rendered %dx%d in %.3f s\n", image.width, image.height, seconds);
    // The rays the mirrored program does not finish (NaN pixels, "fault" channel 1)
    for (std::size_t c = 0; c < image.channels.size(); ++c)
        if (image.channels[c] == "fault") {
            std::size_t n = 0;
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x) n += image.at(x, y, c) != 0.0;
            if (n > 0)
                std::fprintf(stderr, "volref: %zu pixels where the mirrored program does not finish (its loop cannot end: NaN, fault channel 1; volref trace says why)\n", n);
        }
    if (args.timing) {
        // The median frame (the mean of the middle two for an even count); samples per second over it.
        std::vector<double> sorted = stats.frames_s;
        std::sort(sorted.begin(), sorted.end());
        const std::size_t n = sorted.size();
        const double median = n == 0 ? 0.0 : (n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]));
        nlohmann::json t;
        t["setup_s"] = stats.setup_s;
        t["frames_s"] = stats.frames_s;
        t["median_s"] = median;
        t["threads"] = args.threads > 0 ? args.threads : tbb::info::default_concurrency();
        if (stats.sample_positions > 0) {
            t["samples"] = stats.sample_positions;
            t["samples_per_s"] = median > 0.0 ? double(stats.sample_positions) / median : 0.0;
        } else {  // the adaptive integrator places no fixed samples
            t["samples"] = nullptr;
            t["samples_per_s"] = nullptr;
        }
        std::fprintf(stderr, "volref: timing %s\n", t.dump().c_str());
    }
    std::printf("%s\n", args.output.string().c_str());
    return 0;
}

}  // namespace volref::cli
