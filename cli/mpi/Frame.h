// What one volref-mpi rank builds for a frame (cli/mpi/main.cpp's set-up) and what its stages share:
// the scene, this rank's brick of every volume, the PreparedScene `volref render` builds (on the
// bricks: every volume's pipeline, integrator and bounds, the camera, the several-volume mix), and the
// per-pixel queries (rays, intervals, the span this rank owns) and per-slot rules (how parts merge,
// what pixel they give). docs/architecture.md, "volref-mpi".
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/camera/Camera.h"
#include "core/integrate/march/RaySpan.h"
#include "core/integrate/mix/MultiVolumeIntegrator.h"
#include "core/render/PreparedScene.h"
#include "core/render/PreparedVolume.h"
#include "core/scene/Scene.h"
#include "geometry/VolumeTransform.h"
#include "cli/mpi/BrickReader.h"
#include "cli/mpi/Bricks.h"
#include "cli/mpi/PartBuffer.h"

namespace volref::mpi {

// One volume of the scene on this rank: its whole grid and the voxels of its brick (read_bricks; then
// handed to the PreparedScene as the volume's data).
struct Member {
    GridBox grid;
    VolumeLayout header;  // file sources
    int ghost = 1;
    std::array<std::int64_t, 3> vlo{0, 0, 0}, vhi{0, 0, 0};
    Volume brick;
    std::optional<VolumeTransform> transform;  // the grid's space to world (`transform`), if any: grid.to_world
};

// One pixel's part in a slot: the ray-order key (the t0 of the span it covers; +inf: this rank owns
// none of the ray) and the RayState (march/RaySpan.h), kPart doubles.
constexpr int kPart = 1 + RayState::kDoubles;
constexpr double kNone = std::numeric_limits<double>::infinity();

// Every rank's error (empty: none) to rank 0; returns true when some rank failed (rank 0 printed the
// lowest failing rank's message as `volref: error: ...`). Every rank calls it at the same points.
bool any_error(const std::string& mine, int rank, int size);

struct Frame {
    Scene scene;
    std::vector<Member> members;
    Lattice lattice;
    std::vector<Brick> bricks;
    int rank = 0, size = 1;
    int threads = 0;
    // `volref render`'s PreparedScene over this rank's bricks, each volume bounded by its whole domain
    // (WholeDomain): the rays, intervals, camera and mix of the single-process render.
    std::unique_ptr<PreparedScene> prepared;
    const PreparedVolume& volume(std::size_t k) const { return *prepared->volumes[k]; }
    const Camera& camera() const { return *prepared->camera; }
    const MultiVolumeIntegrator& multi() const { return *prepared->multi; }  // several volumes

    int width() const { return scene.image.width; }
    int height() const { return scene.image.height; }
    std::size_t pixels() const { return std::size_t(width()) * std::size_t(height()); }
    std::size_t volumes() const { return members.size(); }
    bool adaptive() const { return scene.render.integrator == IntegrationMethod::Adaptive; }
    bool first_hit() const { return is_first_hit(scene.render.projection); }
    // Several volumes composite as one mixed medium (one slot); other projections keep one slot per
    // volume, combined after the ranks' parts (MultiVolumeIntegrator::combine).
    bool mixed() const { return volumes() > 1 && is_composite(scene.render.projection); }
    std::size_t slots() const { return volumes() > 1 && !mixed() ? volumes() : 1; }
    // The image's channels: R G B A, Z (first hit), error (adaptive), as `volref render` writes them.
    int channels() const { return 4 + (first_hit() ? 1 : 0) + (adaptive() ? 1 : 0); }

    // Pixel (x, y)'s ray in every volume's own space (rays[k], the same t) and every volume's intervals
    // (PreparedVolume::intervals: bounds AND domain and crop on the volume's ray, clip planes on the
    // world ray: conventions §4).
    void pixel_intervals(int x, int y, Ray* rays, std::vector<Interval>* intervals) const;
    // The span of the ray this rank owns (`rays[0]`, the first volume's ray: the lattice's space);
    // empty ([+inf, +inf)) when the ray misses the brick's box (padded: every sample a rank owns lies in it).
    RaySpan span(const Ray& lattice_ray) const;
    // The first volume's rays of `count` world rays (PreparedVolume::intervals, Embree packets) that this
    // rank owns a span of and `skip(at[i])` does not refuse, moved to the front in order with their
    // intervals, spans and `at` (the caller's index of each ray, e.g. its pixel); returns how many. The
    // SIMD packets' input (integrate_parts, the fixed-step chain).
    template <class Skip>
    int owned_rays(const Ray* world, int count, Ray* rays, std::vector<Interval>* intervals, RaySpan* spans,
                   std::size_t* at, Skip&& skip) const {
        volume(0).intervals(world, count, rays, intervals);
        int owned = 0;
        for (int i = 0; i < count; ++i) {
            const RaySpan s = span(rays[i]);
            if (intervals[i].empty() || !(s.t0 < s.t1) || skip(at[i])) continue;
            std::swap(intervals[owned], intervals[i]);
            rays[owned] = rays[i];
            spans[owned] = s;
            at[owned++] = at[i];
        }
        return owned;
    }
    // Whether any of `count` world rays meets this rank's brick (span()'s first test, on the first
    // volume's rays): a block of rays that all miss it has no span, and is skipped before its intervals.
    bool meets_brick(const Ray* world, int count) const;
    // Whether the lattice ray meets this rank's padded brick box (span()'s and meets_brick()'s test).
    bool meets_brick_box(const Ray& lattice_ray) const;
    glm::dvec3 brick_lo{0.0}, brick_hi{0.0};  // this rank's brick's box in the first volume's space, padded
    // Slot `slot`'s rule: `back` (a part behind) merged into `front`, and the pixel of a finished state.
    void merge(std::size_t slot, RayState& front, const RayState& back) const;
    PixelValue finish(std::size_t slot, const Ray* rays, const std::vector<Interval>* intervals,
                      const RayState& state) const;
    // Whether finishing a pixel reads its intervals: several volumes' combination (MultiVolumeIntegrator::
    // combine) and the line integrals (an empty ray is (0, 0, 0, 0); average divides by the length).
    bool finish_reads_intervals() const {
        return slots() > 1 || is_line_integral(scene.render.projection);
    }
    // A pixel from its slots' finished values (several volumes: combined), as R G B A [Z] [error].
    void write_pixel(const PixelValue* values, const std::vector<Interval>* intervals, double* out) const;
};

}  // namespace volref::mpi
