// bench_render: whole renders through render_scene at 1 and 2 threads (docs/performance.md, "Whole
// renders").
//
// Benchmarks render/<scene>/<path>/threads:<n>, wall-clock time, RenderOptions{threads = n} and
//   full         the defaults: SIMD packets of 16 rays and empty-space skipping (1 and 2 threads)
//   no_skipping  SIMD packets, every segment sampled (empty_space_skipping = false; 1 thread)
//   scalar       one ray at a time, every segment sampled (simd = false, empty_space_skipping = false;
//                1 thread): the reference path as it was before packets and skipping
// The image is the same bits on every path (tested elsewhere), so only the time differs.
// Benchmarks tiles/<scene>/tile:<n>/threads:<t> render the default path with RenderOptions::tile_size
// = n (8 .. 64 pixels square; conventions::kTileSize is the default), for the measured choice of the
// tile size (docs/performance.md, "Tile size"); the image does not depend on it (tested).
//
// Scenes:
//   default      reference_scenes/default.json as the loader reads it: Marschner-Lobb 64^3, trilinear,
//                5-row transfer function, perspective camera, 512 x 512, composite, step 0.5 voxel
//   ml256        the same scene with a 256^3 Marschner-Lobb volume (128 MiB of doubles) and the default
//                camera (bounding sphere in view): the scene bench/scaling.sh renders at 512 x 512
//   ml256_setup  ml256 at 1 x 1 pixel: the fixed cost inside render_scene (generating the procedural
//                volume on one thread, the macrocell grid when skipping, Embree scene, camera, thread
//                arena); ml256 minus this (on the same path) is the ray casting itself
//   default_shaded  the default scene shaded as the VTK comparison's shaded case: Blinn-Phong, ka 0.2,
//                kd 0.7, ks 0.3, n 10, one headlight, central differences on the fly (SIMD path)
//   shaded       reference_scenes/shaded-composite.json: 64^3, tricubic Catmull-Rom with the analytic
//                gradient, gradient opacity, Blinn-Phong under two lights, 512 x 512
// The scene files are read from VOLREF_SOURCE_DIR (a compile definition: the source tree).
//
// render_scene includes building what the scene names (the volume too), so every time here is a whole
// render: what `volref render` reports, minus writing the file.
//
// Samples: the number of ray samples of a render is the sum over pixels of the segment counts of the
// pixel's intervals (march/SamplePlacement.h: max(1, ceil(L / h - slack)) per interval), which is what the composite
// integrator samples when early termination is off (it is, in these scenes) and nothing is skipped. It is
// counted once per scene in a separate pass, outside timing, with the renderer's own pieces: the same
// Camera, the same BoundingGeometry (box = the volume's domain) and the same world step. With empty-space
// skipping ("full") fewer segments are actually sampled; samples/s still counts all of them (the work a
// render without skipping would do per second), so it compares the paths on the same scale. Counters:
//   items_per_second               pixels per second (wall clock)
//   samples_per_second             ray samples per second (wall clock)
//   samples_per_second_per_thread  the same divided by the thread count (per core, on 2 cores)
//   samples, hit_pixels            per render (pixels whose ray has at least one interval)
//
// Suggested run (about 2 min on 2 cores):
//   build/bench/bench_render --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//     --benchmark_enable_random_interleaving=true        (one command line)
#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/common.hpp>

#include "core/camera/Camera.h"
#include "core/film/Image.h"
#include "core/grid/Volume.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/render/Renderer.h"
#include "core/scene/Scene.h"
#include "core/scene/SceneLoader.h"
#include "geometry/BoundingGeometry.h"

#ifndef VOLREF_SOURCE_DIR
#error "VOLREF_SOURCE_DIR must be defined (bench/CMakeLists.txt passes the source tree)"
#endif

namespace {

using volref::Scene;

Scene reference_scene(const std::string& name) {
    return volref::load_scene(std::string(VOLREF_SOURCE_DIR) + "/reference_scenes/" + name + ".json");
}

Scene ml256(int size) {
    Scene s = reference_scene("default");
    s.volume().source.field->dims = {256, 256, 256};
    s.camera = volref::CameraSpec{};  // the default camera: looking along -z, bounding sphere in view
    s.image.width = s.image.height = size;
    return s;
}

Scene default_shaded() {
    Scene s = reference_scene("default");
    volref::ShadingSpec shading;
    shading.ka = 0.2;
    shading.kd = 0.7;
    shading.ks = 0.3;
    shading.n = 10.0;
    s.volume().shading = shading;
    return s;
}

const Scene& scene(const std::string& name) {
    static const std::map<std::string, Scene> scenes{
        {"default", reference_scene("default")},
        {"ml256", ml256(512)},
        {"ml256_setup", ml256(1)},
        {"default_shaded", default_shaded()},
        {"shaded", reference_scene("shaded-composite")},
    };
    return scenes.at(name);
}

struct SampleCount {
    std::int64_t samples = 0, hit_pixels = 0;
};

// The segments every pixel's ray is cut into, as render_scene places them (see the header comment).
SampleCount count_samples(const Scene& scene) {
    const volref::Volume volume = volref::load_volume(scene.volume());
    const double step = volref::world_step(scene.render, volume);
    const glm::dvec3 domain_lo = volume.domain_min(), domain_hi = volume.domain_max();
    const glm::dvec3 box_lo = scene.volume().bounds.min.value_or(domain_lo);
    const glm::dvec3 box_hi = scene.volume().bounds.max.value_or(domain_hi);
    volref::BoundingGeometry geometry;
    const int id = geometry.add_box(box_lo, box_hi, domain_lo, domain_hi);
    geometry.commit();
    const int W = scene.image.width, H = scene.image.height;
    const volref::Camera camera(scene.camera, W, H, glm::max(box_lo, domain_lo), glm::min(box_hi, domain_hi));
    SampleCount count;
    std::vector<volref::Interval> intervals;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            geometry.intervals(camera.pixel_ray(x, y), id, intervals);
            if (!intervals.empty()) ++count.hit_pixels;
            for (const volref::Interval& iv : intervals) count.samples += volref::segment_count(iv, step);
        }
    return count;
}

const SampleCount& samples(const std::string& name) {
    static std::map<std::string, SampleCount> counts;
    auto it = counts.find(name);
    if (it == counts.end()) it = counts.emplace(name, count_samples(scene(name))).first;
    return it->second;
}

enum class Path { Full, NoSkipping, Scalar };

void register_tiles(const std::string& name, int tile, int threads) {
    const std::string bench = "tiles/" + name + "/tile:" + std::to_string(tile) + "/threads:" + std::to_string(threads);
    benchmark::RegisterBenchmark(bench.c_str(), [name, tile, threads](benchmark::State& state) {
        const Scene& s = scene(name);
        volref::RenderOptions options;
        options.threads = threads;
        options.tile_size = tile;
        for (auto _ : state) {
            const volref::Image image = volref::render_scene(s, options);
            benchmark::DoNotOptimize(image.pixels.data());
            benchmark::ClobberMemory();
        }
    })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

void register_render(const std::string& name, Path path, int threads) {
    const char* path_name = path == Path::Full ? "full" : path == Path::NoSkipping ? "no_skipping" : "scalar";
    const std::string bench = "render/" + name + "/" + path_name + "/threads:" + std::to_string(threads);
    benchmark::RegisterBenchmark(bench.c_str(), [name, path, threads](benchmark::State& state) {
        const Scene& s = scene(name);
        const SampleCount& count = samples(name);  // counted before timing
        volref::RenderOptions options;
        options.threads = threads;
        options.simd = path != Path::Scalar;
        options.empty_space_skipping = path == Path::Full;
        for (auto _ : state) {
            const volref::Image image = volref::render_scene(s, options);
            benchmark::DoNotOptimize(image.pixels.data());
            benchmark::ClobberMemory();
        }
        const double iterations = double(state.iterations());
        const auto pixels = std::int64_t(s.image.width) * std::int64_t(s.image.height);
        state.SetItemsProcessed(std::int64_t(state.iterations()) * pixels);
        state.counters["samples_per_second"] =
            benchmark::Counter(iterations * double(count.samples), benchmark::Counter::kIsRate);
        state.counters["samples_per_second_per_thread"] =
            benchmark::Counter(iterations * double(count.samples) / threads, benchmark::Counter::kIsRate);
        state.counters["samples"] = double(count.samples);
        state.counters["hit_pixels"] = double(count.hit_pixels);
    })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

}  // namespace

int main(int argc, char** argv) {
    for (const char* name : {"default", "default_shaded", "ml256", "ml256_setup", "shaded"}) {
        register_render(name, Path::Full, 1);
        register_render(name, Path::Full, 2);
        register_render(name, Path::NoSkipping, 1);  // for ml256_setup: without building the macrocell grid
        if (std::string(name) != "ml256_setup") register_render(name, Path::Scalar, 1);
    }
    for (const char* name : {"default", "default_shaded"})
        for (int tile : {8, 16, 32, 64})
            for (int threads : {1, 2}) register_tiles(name, tile, threads);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
