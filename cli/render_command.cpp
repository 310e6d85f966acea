// volref render SCENE -o OUT [--threads N] [--no-skipping] [--error] [--set PATH=VALUE ...]
#include <unistd.h>

#include <chrono>
#include <cstdio>

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
    options.progress = ::isatty(STDERR_FILENO) != 0;
    const auto start = std::chrono::steady_clock::now();
    RenderStats stats;
    const Image image = render_scene(scene, options, &stats);
    if (stats.non_finite_voxels > 0)
        std::fprintf(stderr, "volref: warning: %zu non-finite voxels (NaN or Inf), rendered as transparent\n",
                     stats.non_finite_voxels);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_image(image, args.output, scene.image.background);
    std::fprintf(stderr, "volref: rendered %dx%d in %.3f s\n", image.width, image.height, seconds);
    std::printf("%s\n", args.output.string().c_str());
    return 0;
}

}  // namespace volref::cli
