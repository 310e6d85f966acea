// Rendering a scene: builds what the scene names (volume, sampler, transfer function, bounding
// geometry, camera, integrator) and computes every pixel in parallel over tiles.
//
// Every pixel is computed from its own ray alone (no shared accumulators), so the image is bitwise
// the same for any thread count and any tile order.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/film/Image.h"
#include "core/grid/Volume.h"
#include "core/render/PixelBlocks.h"
#include "core/scene/Scene.h"
#include "transfer/Classifier.h"

namespace volref {

struct RenderOptions {
    int threads = 0;        // 0: all cores
    bool progress = false;  // print progress on stderr after about a second
    // Composite projection: skip the segments in macrocells the classification makes transparent
    // (conventions section 4). The image is bitwise the same either way; false is for checking that.
    bool empty_space_skipping = true;
    bool simd = true;       // use the SIMD packet paths where the scene allows (PacketComposite.h)
    // Fixed-step integrator: also render at step / 2 and write the step-doubling estimate as the
    // "error" channel (StepDoubling.h). The adaptive integrator always writes its own estimate.
    bool error_estimate = false;
    int tile_size = 0;      // pixels per tile side; 0: tile_side() (the image does not depend on it)
    int frames = 1;         // render the frame this many times after one set-up (volref render --repeat)
    bool count_samples = false;  // fill RenderStats::sample_positions (one extra pass, not timed)
};

// The volume a VolumeSpec names: read from its file or made from its procedural field, with the
// spec's origin and spacing overriding the file's; or a copy of the volume it holds in memory
// (VolumeSourceSpec::memory, whose origin and spacing are its own).
Volume load_volume(const VolumeSpec& spec);
// The same, shared: the volume in memory itself (not copied), or a new one.
std::shared_ptr<const Volume> share_volume(const VolumeSpec& spec);

// The tile side render_scene uses for a width x height image on `threads` threads: conventions::kTileSize,
// halved down to kMinTileSize while there are fewer than kTilesPerThread tiles per thread. Inside a
// tile, render_scene (and volref-mpi) hand the integrator blocks of pixels (PixelBlocks.h).
int tile_side(int width, int height, int threads);

// The world-space step: render.step, times the smallest spacing when step_units is voxel.
double world_step(const RenderSpec& render, const Volume& volume);

// What a render noticed about its input.
struct RenderStats {
    std::size_t non_finite_voxels = 0;  // NaN or +-Inf voxels (transparent; docs/accuracy.md)
    // Timing (volref render --timing): the set-up (reading or generating the volumes, building the
    // pipeline, the geometry and the camera) and each frame (every pixel, nothing else), in seconds.
    double setup_s = 0.0;
    std::vector<double> frames_s;
    // RenderOptions::count_samples: the fixed step's sample positions in one frame, summed over every
    // pixel, volume and interval (segment_count, SamplePlacement.h) before skipping and termination:
    // the work of a marcher without empty-space skipping. 0 for the adaptive integrator.
    std::uint64_t sample_positions = 0;
    // Lines the user should read (volref render prints them as "volref: warning: ..."; Python warns).
    std::vector<std::string> warnings;
};

// `stats` (optional) receives what the render noticed (non-finite voxels).
Image render_scene(const Scene& scene, const RenderOptions& options = {}, RenderStats* stats = nullptr);

// Resolves `"cache": "auto"` (core/Conventions.h, kGradientCacheBreakEven): the expected gradient
// evaluations per voxel e = pixels (diagonal / step) (visible voxel fraction) / voxels, with a voxel
// visible when the classifier gives it opacity > 0 at |grad f| = 1; cache iff e > break-even.
GradientSpec resolve_gradient_cache(GradientSpec spec, const Volume& volume, const Classifier& classifier,
                                    const ImageSpec& image, double step);

}  // namespace volref
