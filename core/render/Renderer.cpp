#include "core/render/Renderer.h"
#include "core/render/PreparedScene.h"

#include <algorithm>
#include <atomic>
#include <optional>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include "core/Cancellation.h"
#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/camera/Camera.h"
#include "core/grid/ProceduralField.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/packet/PacketComposite.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/film/StepDoubling.h"
#include "core/sample/GradientField.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/PreClassifiedVolume.h"
#include "core/io/VolumeReader.h"
#include "core/sample/VolumeSampler.h"
#include "core/sample/ShellSampler.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/ShellCoordinates.h"
#include "geometry/ShellTessellation.h"
#include "geometry/TriangleMesh.h"
#include "transfer/Classifier.h"
#include "transfer/Shader.h"

namespace volref {

static_assert(kPixelBlockPixels <= kMaxPacketRays, "a block is one call to the integrator");

std::shared_ptr<const Volume> share_volume(const VolumeSpec& spec) {
    if (spec.source.memory) return spec.source.memory;  // complete: its own origin and spacing
    return std::make_shared<const Volume>(load_volume(spec));
}

Volume load_volume(const VolumeSpec& spec) {
    if (spec.source.memory) return *spec.source.memory;
    Volume v;
    if (spec.source.field) {
        v = make_procedural_volume(*spec.source.field, spec.origin.value_or(glm::dvec3(0.0)),
                                   spec.spacing.value_or(glm::dvec3(1.0)));
    } else {
        v = read_volume(*spec.source.file, spec.source.format);
        if (spec.origin) v.origin = *spec.origin;
        if (spec.spacing) v.spacing = *spec.spacing;
    }
    return v;
}

int tile_side(int width, int height, int threads) {
    int T = conventions::kTileSize;
    auto tiles = [&](int side) { return std::int64_t((width + side - 1) / side) * std::int64_t((height + side - 1) / side); };
    while (T > conventions::kMinTileSize && tiles(T) < std::int64_t(conventions::kTilesPerThread) * std::max(1, threads)) T /= 2;
    return T;
}

double world_step(const RenderSpec& render, const Volume& volume) {
    if (render.step_units == StepUnits::World) return render.step;
    return render.step * std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
}

GradientSpec resolve_gradient_cache(GradientSpec spec, const Volume& volume, const Classifier& classifier,
                                    const ImageSpec& image, double step) {
    if (!spec.cache_auto) return spec;
    std::size_t visible = 0;
    for (double v : volume.values)
        if (classifier.classify(v, 1.0).opacity > 0.0) ++visible;
    const double voxels = double(volume.values.size());
    const double diagonal = glm::length(volume.domain_max() - volume.domain_min());
    const double per_voxel = double(image.width) * double(image.height) * (diagonal / step) * (double(visible) / voxels) / voxels;
    spec.cache = per_voxel > conventions::kGradientCacheBreakEven;
    spec.cache_auto = false;
    return spec;
}

namespace {

// A tile's pixels (rows of `row` doubles, the image's channels interleaved) into the image, row by row. On
// x86 by streaming stores (SSE2 _mm_stream_pd, then a store fence), which write whole cache lines without
// reading them first: the frame never reads its image, and the 8 MiB of a 512 x 512 RGBA image in double
// are larger than L2, so plain stores read each line back from memory first, and on an Intel Xeon those
// reads held up the voxel fetches (the film variants: docs/performance.md, "What did not help").
// The same values either way; a destination not on 16 bytes (an odd channel count on an odd width) is copied.
void write_tile(Image& image, const double* tile, std::size_t row, const PixelRect& rect) {
    const std::size_t n = std::size_t(rect.x1 - rect.x0) * image.channel_count();
    for (int y = rect.y0; y < rect.y1; ++y) {
        const double* src = tile + std::size_t(y - rect.y0) * row;
        double* dst = &image.at(rect.x0, y, 0);
#if defined(__SSE2__)
        if (reinterpret_cast<std::uintptr_t>(dst) % 16 == 0) {
            std::size_t k = 0;
            for (; k + 2 <= n; k += 2) _mm_stream_pd(dst + k, _mm_loadu_pd(src + k));
            if (k < n) dst[k] = src[k];
            continue;
        }
#endif
        std::copy(src, src + n, dst);
    }
#if defined(__SSE2__)
    _mm_sfence();  // the streaming stores ordered before the task ends (and before the image is read)
#endif
}

// Prints "volref: rendering NN%" on stderr every quarter second once a render has run for a second.
class ProgressReporter {
public:
    ProgressReporter(bool enabled, int total) : total_(total) {
        if (enabled) thread_ = std::thread([this] { run(); });
    }
    ~ProgressReporter() {
        {
            std::lock_guard lock(mutex_);
            done_flag_ = true;
        }
        cv_.notify_all();
        if (thread_.joinable()) thread_.join();
    }
    void tile_done() { done_.fetch_add(1, std::memory_order_relaxed); }

private:
    void run() {
        using namespace std::chrono;
        const auto start = steady_clock::now();
        bool printed = false;
        std::unique_lock lock(mutex_);
        while (!cv_.wait_for(lock, milliseconds(250), [this] { return done_flag_; })) {
            const double elapsed = duration<double>(steady_clock::now() - start).count();
            if (elapsed < 1.0) continue;
            std::fprintf(stderr, "\rvolref: rendering %3d%% (%.1f s)", int(100.0 * done_.load() / total_), elapsed);
            printed = true;
        }
        if (printed) std::fprintf(stderr, "\rvolref: rendering 100%%        \n");
    }
    int total_;
    std::atomic<int> done_{0};
    std::mutex mutex_;
    std::condition_variable cv_;
    bool done_flag_ = false;
    std::thread thread_;
};

// RenderStats::sample_positions: every pixel's ray through every volume's intervals, counted as the
// fixed step places samples (segment_count); 0 for the adaptive integrator.
std::uint64_t count_sample_positions(const PreparedScene& prepared, const Scene& scene, tbb::task_arena& arena) {
    if (scene.render.integrator != IntegrationMethod::Fixed || !prepared.camera) return 0;
    const int W = scene.image.width, H = scene.image.height;
    return arena.execute([&] {
        return tbb::parallel_reduce(
            tbb::blocked_range<int>(0, H), std::uint64_t(0),
            [&](const tbb::blocked_range<int>& rows, std::uint64_t n) {
                Ray rays[kMaxPacketRays], local[kMaxPacketRays];
                std::vector<Interval> intervals[kMaxPacketRays];
                for (int y = rows.begin(); y != rows.end(); ++y)
                    for (int x0 = 0; x0 < W; x0 += kMaxPacketRays) {
                        const int count = std::min(kMaxPacketRays, W - x0);
                        for (int i = 0; i < count; ++i) rays[i] = prepared.camera->pixel_ray(x0 + i, y);
                        for (const auto& v : prepared.volumes) {
                            v->intervals(rays, count, local, intervals);
                            for (int i = 0; i < count; ++i)
                                for (const Interval& iv : intervals[i]) n += std::uint64_t(segment_count(iv, v->step));
                        }
                    }
                return n;
            },
            std::plus<>());
    });
}

}  // namespace

Image render_scene(const Scene& scene, const RenderOptions& options, RenderStats* stats) {
    if (options.error_estimate && scene.render.profile == ProfileId::VolPack)
        throw Error("--error: step doubling halves render.step, and volpack has none (VolPack samples its voxel slices); "
                    "its error channel is already written: where a byte may truncate either way");
    if (options.error_estimate && scene.render.integrator == IntegrationMethod::Fixed) {
        // Step doubling: the image at h, and its error estimate from the image at h / 2.
        RenderOptions single = options;
        single.error_estimate = false;
        // the coarse image is held while the fine one is rendered, and the result is a third:
        // both renders count two more images against the memory limit (PreparedVolume's check).
        const HeldMemory images(2 * std::size_t(scene.image.width) * std::size_t(scene.image.height) * 6 * sizeof(double));
        const Image coarse = render_scene(scene, single, stats);
        Scene half = scene;
        half.render.step *= 0.5;
        return with_step_doubling_error(coarse, render_scene(half, single));
    }
    // One arena for the whole render (--threads): the set-up (procedural volumes are generated in
    // parallel) and the tiles.
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    using Clock = std::chrono::steady_clock;
    const auto setup_start = Clock::now();
    std::optional<PreparedScene> prepared_storage;
    arena.execute([&] { prepared_storage.emplace(scene, options); });
    const PreparedScene& prepared = *prepared_storage;
    if (stats) {
        stats->setup_s = std::chrono::duration<double>(Clock::now() - setup_start).count();
        stats->frames_s.clear();
    }
    if (stats) {
        stats->non_finite_voxels = 0;
        stats->warnings.clear();
        for (const auto& v : prepared.volumes) stats->warnings.insert(stats->warnings.end(), v->warnings.begin(), v->warnings.end());
        for (const auto& v : prepared.volumes)
            for (double x : v->model.volume().values)
                if (!std::isfinite(x)) ++stats->non_finite_voxels;
    }
    const int W = scene.image.width, H = scene.image.height;

    // The channels beyond RGBA this render writes (asked once: each is a virtual call).
    const bool depth = prepared.writes_depth(), error = prepared.writes_error(), fault = prepared.writes_fault();
    std::vector<std::string> channels{"R", "G", "B", "A"};
    if (depth) channels.push_back("Z");
    const std::size_t error_channel = channels.size();
    if (error) channels.push_back("error");
    const std::size_t fault_channel = channels.size();
    if (fault) channels.push_back("fault");  // 1 where the mirrored program does not finish
    Image image(W, H, channels);

    const int T = options.tile_size > 0 ? options.tile_size : tile_side(W, H, arena.max_concurrency());
    const TileGrid tiles(W, H, T);
    for (int frame = 0; frame < std::max(1, options.frames); ++frame) {
    const auto frame_start = Clock::now();
    ProgressReporter progress(options.progress && frame == 0, tiles.count());
    arena.execute([&] {
        parallel_for_tiles(tiles, [&](const PixelRect& tile) {
            if (cancel_requested()) return;  // SIGINT/SIGTERM: stop at the next tile (Cancellation.h)
            PreparedScene::Scratch scratch;
            PixelValue values[kMaxPacketRays];
            // The tile's pixels, written to the image when the tile is done (write_tile).
            const std::size_t C = image.channel_count(), row = std::size_t(T) * C;
            std::vector<double> tile_pixels(std::size_t(T) * row);
            // One call to the integrator a block (PixelBlocks.h).
            for_each_block(tile, [&](const PixelBlock& b) {
                prepared.pixels(b.x, b.y, b.count, values, options.simd, scratch);  // Embree packets per volume
                for (int i = 0; i < b.count; ++i) {
                    double* p = &tile_pixels[std::size_t(b.y[i] - tile.y0) * row + std::size_t(b.x[i] - tile.x0) * C];
                    for (int c = 0; c < 4; ++c) p[c] = values[i].rgba[c];
                    if (depth) p[4] = values[i].depth;
                    if (error) p[error_channel] = values[i].error;
                    if (fault) p[fault_channel] = values[i].fault ? 1.0 : 0.0;
                }
            });
            write_tile(image, tile_pixels.data(), row, tile);
            progress.tile_done();
        });
    });
    throw_if_cancelled();
    if (stats) stats->frames_s.push_back(std::chrono::duration<double>(Clock::now() - frame_start).count());
    }
    if (stats && options.count_samples) stats->sample_positions = count_sample_positions(prepared, scene, arena);
    // A NaN the scene did not ask for never leaves as a result. A scene asks for NaN in two ways:
    // a fault pixel (the mirrored program does not finish: fault channel 1), and the vtk-js profile, which
    // reproduces vtk.js's own (C / A) A, NaN where a ray accumulates A = 0 (its samples below the 0.001 cut-off; conventions
    // section 9). Any other NaN is refused here, before an image is written, with the first pixel named.
    if (scene.render.profile != ProfileId::VtkJs) {
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (fault && image.at(x, y, fault_channel) != 0.0) continue;
                for (std::size_t c = 0; c < 4; ++c)
                    if (std::isnan(image.at(x, y, c)))
                        throw Error("render: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                    ") came out NaN although the scene asks for no NaN (a volref bug: please report it "
                                    "with the scene); no image written");
            }
    }
    return image;
}

}  // namespace volref
