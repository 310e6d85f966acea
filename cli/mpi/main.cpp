// volref-mpi render SCENE -o OUT [--threads T] [--max-memory M] [--set PATH=VALUE ...]
//
// Space split into bricks over the MPI ranks (cli/mpi/Bricks.h: a k-d split of the first volume's
// lattice, extended over every volume); each rank holds its brick of every volume plus a ghost layer
// (read as a sub-box of the file, or generated), integrates the part of every ray inside its brick on
// the single-process render's sample lattice (segment k of an interval, or of a piece of several
// volumes' mix, at the same t on every rank; a segment belongs to the brick holding its midpoint),
// and the parts are combined in ray order (binary swap, or MPI_Gather to rank 0), which writes the
// image. Errors of any rank reach rank 0, which prints the one line `volref render` prints (the lowest
// rank's); every rank exits 1; no file is written. docs/conventions.md §14, docs/architecture.md
// "volref-mpi", docs/performance.md.
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/camera/Camera.h"
#include "core/film/ImageWriter.h"
#include "core/grid/ProceduralField.h"
#include "core/integrate/adaptive/AdaptiveCellWalk.h"
#include "core/integrate/adaptive/AdaptiveIntegrator.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/fixed/FirstHitIntegrator.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/integrate/mix/MultiVolumeIntegrator.h"
#include "core/render/PreparedVolume.h"
#include "core/render/VolumeLoaderHook.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/SceneLoader.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/BoxIntersection.h"
#include "geometry/ClipPlanes.h"
#include "geometry/CropRegions.h"
#include "geometry/VolumeTransform.h"
#include "cli/mpi/BrickReader.h"
#include "cli/mpi/Bricks.h"

namespace {

using namespace volref;

// One pixel's part, 8 doubles: [0] the ray-order key (t of the first owned segment's midpoint, or of
// the extremum; +inf: none), [1..4] colour (composite: R G B and tau; extremum: the pixel R G B A),
// [5] opaque (composite) / the extremum's value, [6] line integral, [7] summed length.
constexpr int kPart = 8;
constexpr double kNone = std::numeric_limits<double>::infinity();

// Every rank's error (empty: none) to rank 0; returns true when some rank failed (rank 0 printed the
// lowest failing rank's message). Every rank calls it at the same points.
bool any_error(const std::string& mine, int rank, int size) {
    int failed = mine.empty() ? 0 : 1, any = 0;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (!any) return false;
    int len = int(mine.size());
    std::vector<int> lens(size), offsets(size, 0);
    MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<char> all;
    if (rank == 0) {
        int total = 0;
        for (int r = 0; r < size; ++r) offsets[r] = total, total += lens[r];
        all.resize(std::size_t(std::max(total, 1)));
    }
    MPI_Gatherv(mine.data(), len, MPI_CHAR, all.data(), lens.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
    if (rank == 0)
        for (int r = 0; r < size; ++r)
            if (lens[r] > 0) {
                std::fprintf(stderr, "volref: error: %.*s\n", lens[r], all.data() + offsets[r]);
                break;
            }
    return true;
}

// What volref-mpi does not render yet (docs/conventions.md §14): one-line errors naming the key.
void check_supported(const Scene& scene) {
    const RenderSpec& r = scene.render;
    if (!r.reference_integrators())
        throw Error("render.profile: volref-mpi supports \"reference\" only (mirror and fast profiles are not supported yet)");
    for (std::size_t k = 0; k < scene.volumes.size(); ++k) {
        const VolumeSpec& vs = scene.volumes[k];
        const std::string key = volume_key(scene, k);
        if (vs.bounds.type != BoundsSpec::Type::Box && vs.bounds.type != BoundsSpec::Type::Mesh)
            throw Error(key + ".bounds: volref-mpi supports box and mesh bounds only (shells are not supported yet)");
        // "auto" decides from the whole volume's voxels (resolve_gradient_cache), which no rank holds.
        if (vs.gradient.cache_auto)
            throw Error(key + ".gradient.cache: \"auto\" is not supported by volref-mpi yet (say true or false)");
    }
}

// The parts each pixel carries: one for a single volume and for the mix of several (composite); one
// per volume for the other projections (each volume's own projection, combined after the ranks').
std::size_t slot_count(const Scene& scene) {
    return scene.volumes.size() > 1 && scene.render.projection != Projection::Composite ? scene.volumes.size() : 1;
}

// OUT ending in ".img": the pixels as doubles in tests/identity/image_dump.cpp's format (a text line
// "W H R G B A", then W H 4 IEEE-754 doubles in the host's byte order), so that tests compare doubles
// (EXR stores floats). Written to a temporary name and renamed into place.
bool dump_output(const std::string& path) { return path.size() > 4 && path.compare(path.size() - 4, 4, ".img") == 0; }

void write_dump(const Image& image, const std::string& path) {
    const std::string temp = path + ".part";
    std::FILE* f = std::fopen(temp.c_str(), "wb");
    if (!f) throw Error(path + ": cannot write");
    std::string header = std::to_string(image.width) + " " + std::to_string(image.height);
    for (const std::string& c : image.channels) header += " " + c;
    header += "\n";
    const bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size() &&
                    std::fwrite(image.pixels.data(), sizeof(double), image.pixels.size(), f) == image.pixels.size();
    if (std::fclose(f) != 0 || !ok || std::rename(temp.c_str(), path.c_str()) != 0) {
        std::remove(temp.c_str());
        throw Error(path + ": cannot write");
    }
}

struct Args {
    std::string scene, output, max_memory;
    int threads = 0;
    std::vector<std::string> overrides;
    bool timing = false;
    std::string compositing = "swap";
    bool compositing_given = false;
};

double now() { return MPI_Wtime(); }

// One volume of the scene on this rank: its whole grid, the voxels of its brick, its pipeline on them.
struct Member {
    mpi::GridBox grid;
    VolumeLayout header;  // file sources
    int ghost = 1;
    std::array<std::int64_t, 3> vlo{0, 0, 0}, vhi{0, 0, 0};
    Volume brick;
    std::unique_ptr<PreparedVolume> prepared;
    int geometry_id = 0;
    std::optional<VolumeTransform> transform;  // its own space to world (`transform`), if any
};

int run(const Args& args, int rank, int size) {
    std::string err;
    // Binary swap needs a power-of-two rank count; others use direct send (said on stderr after a
    // successful render when --compositing swap was asked for).
    const bool power_of_two = (size & (size - 1)) == 0;
    const bool swap = args.compositing == "swap" && power_of_two && size > 1;
    const double t_start = now();
    // ---- set-up: scene, bricks, this rank's bricks of the volumes, their pipelines ----
    Scene scene;
    std::vector<Member> members;
    mpi::Lattice lattice;
    std::vector<mpi::Brick> bricks;
    std::unique_ptr<Camera> camera;
    BoundingGeometry geometry;
    std::unique_ptr<MultiVolumeIntegrator> multi;
    try {
        if (!args.max_memory.empty()) set_memory_limit(parse_memory_size(args.max_memory, "--max-memory"));
        if (rank == 0 && !dump_output(args.output)) check_output_path(args.output);
        scene = load_scene(args.scene, args.overrides);
        check_supported(scene);
        members.resize(scene.volumes.size());
        std::vector<mpi::GridBox> grids;
        for (std::size_t k = 0; k < members.size(); ++k) {
            const VolumeSpec& vs = scene.volumes[k];
            Member& m = members[k];
            if (vs.transform) m.transform.emplace(*vs.transform);
            const VolumeTransform* to_world = m.transform ? &*m.transform : nullptr;  // (members is not resized again)
            if (vs.source.field) {
                m.grid = {vs.source.field->dims, vs.origin.value_or(glm::dvec3(0.0)), vs.spacing.value_or(glm::dvec3(1.0)), to_world};
            } else {
                m.header = mpi::read_volume_header(*vs.source.file, vs.source.format);
                m.header.origin = vs.origin.value_or(m.header.origin);
                m.header.spacing = vs.spacing.value_or(m.header.spacing);
                m.grid = {m.header.dims, m.header.origin, m.header.spacing, to_world};
            }
            m.ghost = mpi::ghost_voxels(vs, scene.render);
            if (scene.render.projection == Projection::FirstHit) {
                // The sign test reads both ends of an owned segment (its midpoint +- h / 2) and the
                // search runs between them: the ghost layer reaches h / 2 further (h in voxels of the
                // finest axis).
                const glm::dvec3& sp = m.grid.spacing;
                const double finest = std::min({sp.x, sp.y, sp.z});
                const double h = scene.render.step_units == StepUnits::World ? scene.render.step / finest : scene.render.step;
                if (!(h > 0.0) || !(h < 1e6)) throw Error("render.step: too large for volref-mpi's ghost layer");
                m.ghost += int(std::ceil(0.5 * h));
            }
            grids.push_back(m.grid);
        }
        lattice = mpi::union_lattice(grids);
        bricks = mpi::split_lattice(lattice, size);
        std::size_t held = 0;  // the bricks read before this one (--max-memory counts them all)
        for (std::size_t k = 0; k < members.size(); ++k) {
            const VolumeSpec& vs = scene.volumes[k];
            Member& m = members[k];
            mpi::voxels_for(bricks[std::size_t(rank)], lattice, grids[0], m.grid, m.ghost, m.vlo, m.vhi);
            const std::array<std::int64_t, 3> n{m.vhi[0] - m.vlo[0] + 1, m.vhi[1] - m.vlo[1] + 1, m.vhi[2] - m.vlo[2] + 1};
            const HeldMemory earlier(held);
            if (vs.source.field) m.brick = make_procedural_brick(*vs.source.field, m.grid.origin, m.grid.spacing, m.vlo, n);
            else m.brick = mpi::read_brick(m.header, m.vlo, n);
            held += m.brick.values.bytes();
        }
    } catch (const std::bad_alloc&) {
        err = "out of memory";
    } catch (const std::exception& e) {
        err = e.what();
    }
    if (any_error(err, rank, size)) return 1;
    try {
        // Whatever reads a volume's data range (the transfer function's default window of a float
        // volume, the shader's zero-gradient tolerance) reads the whole volume's: the ranks agree on it
        // first (Volume::whole_range).
        for (Member& m : members) {
            const auto r = m.brick.value_range();
            double lo = r[0], hi = r[1], glo = 0.0, ghi = 0.0;
            MPI_Allreduce(&lo, &glo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
            MPI_Allreduce(&hi, &ghi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            m.brick.whole_range = std::array<double, 2>{glo, ghi};
        }
        RenderOptions options;
        options.threads = args.threads;
        std::size_t held = 0;
        glm::dvec3 view_lo(std::numeric_limits<double>::infinity()), view_hi(-std::numeric_limits<double>::infinity());
        for (std::size_t k = 0; k < members.size(); ++k) {
            Member& m = members[k];
            set_volume_loader_hook([&](const VolumeSpec&) { return std::move(m.brick); });
            m.prepared = std::make_unique<PreparedVolume>(scene, k, options, held);
            set_volume_loader_hook({});
            held += m.prepared->bytes;
            // The whole volume's box (bounds AND domain): the intervals and the default camera of the
            // single-process render.
            const VolumeSpec& vs = scene.volumes[k];
            const glm::dvec3 domain_lo = m.grid.origin;
            const glm::dvec3 domain_hi =
                m.grid.origin + glm::dvec3(double(m.grid.dims[0] - 1), double(m.grid.dims[1] - 1), double(m.grid.dims[2] - 1)) * m.grid.spacing;
            glm::dvec3 lo, hi, world_lo, world_hi;  // the shape AND domain's box, and its world box
            m.geometry_id = add_cartesian_bounds(geometry, vs, volume_key(scene, k), domain_lo, domain_hi, lo, hi);
            world_box(m.transform ? &*m.transform : nullptr, lo, hi, world_lo, world_hi);
            view_lo = glm::min(view_lo, world_lo);
            view_hi = glm::max(view_hi, world_hi);
        }
        geometry.commit();
        if (members.size() > 1) {  // the single-process render's mix (composite) and combination (others)
            std::vector<MultiVolumeIntegrator::Member> list;
            double step = std::numeric_limits<double>::infinity();
            for (const Member& m : members) {
                list.push_back({m.prepared->pipeline.get(), m.prepared->integrator.get(), m.prepared->context.get()});
                step = std::min(step, m.prepared->step);
            }
            multi = std::make_unique<MultiVolumeIntegrator>(std::move(list), scene.render, step);
        }
        camera = std::make_unique<Camera>(scene.camera, scene.image.width, scene.image.height, view_lo, view_hi);
        const std::size_t slots = slot_count(scene);
        const std::size_t parts =
            std::size_t(scene.image.width) * std::size_t(scene.image.height) * slots * kPart * sizeof(double);
        if (parts / sizeof(double) > std::size_t(std::numeric_limits<int>::max()))
            throw Error("image: " + std::to_string(scene.image.width) + " x " + std::to_string(scene.image.height) +
                        " is too large for volref-mpi (its messages hold at most 2^31 - 1 doubles: " +
                        std::to_string(slots * kPart) + " per pixel)");
        // Direct send: rank 0 holds every rank's parts and its own; binary swap: a rank holds its parts
        // and half of them received; rank 0 also holds the image (up to 5 doubles a pixel).
        const std::size_t image_bytes = parts / (kPart * slots) * 5;
        const std::size_t held_parts = swap ? parts + parts / 2 + (rank == 0 ? image_bytes : 0)
                                            : parts * (rank == 0 ? std::size_t(size) + 1 : 1) + (rank == 0 ? image_bytes : 0);
        check_memory(held + held_parts, "this rank's bricks with the image parts (" + std::to_string(size) + " ranks, " +
                                            (swap ? "binary swap" : "direct send") + ")");
    } catch (const std::bad_alloc&) {
        err = "out of memory";
    } catch (const std::exception& e) {
        err = e.what();
    }
    set_volume_loader_hook({});
    if (any_error(err, rank, size)) return 1;

    const double t_setup = now();
    // ---- this rank's part of every ray ----
    const int W = scene.image.width, H = scene.image.height;
    const RenderSpec& render = scene.render;
    const std::size_t V = members.size(), slots = slot_count(scene);
    const mpi::Brick& brick = bricks[std::size_t(rank)];
    const mpi::GridBox& lattice_grid = members[0].grid;
    const bool first_hit = render.projection == Projection::FirstHit;
    const bool mixed = V > 1 && render.projection == Projection::Composite;
    std::vector<double> part(std::size_t(W) * std::size_t(H) * slots * kPart, 0.0);
    // The brick's box in the first volume's space, padded: the segments worth testing (the test
    // itself is exact).
    glm::dvec3 blo, bhi;
    for (int a = 0; a < 3; ++a) {
        blo[a] = lattice_grid.origin[a] + double(brick.lo[a]) * lattice_grid.spacing[a];
        bhi[a] = lattice_grid.origin[a] + double(brick.hi[a]) * lattice_grid.spacing[a];
        const double pad = 1e-6 * (std::fabs(blo[a]) + std::fabs(bhi[a]) + lattice_grid.spacing[a]);
        blo[a] -= pad;
        bhi[a] += pad;
    }
    // Whether this rank owns the point at t of `lattice_ray` (the first volume's ray, in its own
    // space): the brick holding it in the lattice (conventions §14).
    auto owned_point = [&](const Ray& lattice_ray, double t) {
        return mpi::owns(brick, lattice, (lattice_ray.at(t) - lattice_grid.origin) / lattice_grid.spacing);
    };
    // Pixel (x, y)'s ray in every volume's own space (rays[k], the same t) and every volume's
    // intervals (bounds AND domain and crop on the volume's ray, clip planes on the world ray: §4).
    auto pixel_intervals = [&](int x, int y, Ray* rays, std::vector<Interval>* intervals) {
        const Ray world = camera->pixel_ray(x, y);
        for (std::size_t k = 0; k < V; ++k) {
            const VolumeSpec& vs = scene.volumes[k];
            rays[k] = members[k].transform ? members[k].transform->local_ray(world) : world;
            Ray local = rays[k];
            intervals[k].clear();
            geometry.intervals(&rays[k], 1, members[k].geometry_id, &intervals[k]);
            if (vs.crop) crop_intervals(local, *vs.crop, intervals[k]);
            if (!vs.clip_planes.empty()) clip_intervals(world, vs.clip_planes, intervals[k]);
        }
    };
    // The segments k of an interval (n of them at `step`) whose midpoints this rank owns, front to
    // back (contiguous: the brick is convex), given the ray's range in the padded brick box.
    auto owned_segments = [&](const Ray& lattice_ray, const Interval& iv, double step, const Interval& range, auto&& use) {
        if (iv.t1 < range.t0 || iv.t0 > range.t1) return;
        const std::int64_t n = segment_count(iv, step);
        std::int64_t k0 = std::int64_t(std::floor((range.t0 - iv.t0) / step)) - 1;
        std::int64_t k1 = std::int64_t(std::ceil((range.t1 - iv.t0) / step)) + 1;
        k0 = std::clamp<std::int64_t>(k0, 0, n - 1);
        k1 = std::clamp<std::int64_t>(k1, 0, n - 1);
        for (std::int64_t k = k0; k <= k1; ++k) {
            const Segment s = segment(iv, step, k, n);
            if (owned_point(lattice_ray, s.midpoint())) use(s, k, n);
        }
    };
    // Composite: one part (C, tau, opaque) from owned segments' (opaque, tau, alpha, colour), in ray
    // order, by FrontToBack or BackToFront over this rank's segments.
    struct Composited {
        bool opaque;
        double tau, alpha;
        glm::dvec3 color;
    };
    auto composite_part = [&](const std::vector<Composited>& owned, double* p) {
        CompensatedSum tau;
        bool opaque = false;
        auto add = [&](auto& acc, const Composited& o) {
            const double c[3] = {o.color.r, o.color.g, o.color.b};
            acc.add(true, o.opaque, o.tau, o.alpha, c);
            if (o.opaque) opaque = true;
            else tau.add(o.tau);
        };
        if (render.order == CompositeOrder::FrontToBack) {
            FrontToBack<Scalar> acc;
            for (const Composited& o : owned) {
                add(acc, o);
                if (opaque) break;
            }
            for (int i = 0; i < 3; ++i) p[1 + i] = acc.color(i);
        } else {
            BackToFront<Scalar> acc;
            for (auto it = owned.rbegin(); it != owned.rend(); ++it) add(acc, *it);
            for (int i = 0; i < 3; ++i) p[1 + i] = acc.color(i);
        }
        p[4] = tau.value();
        p[5] = opaque ? 1.0 : 0.0;
    };
    const bool adaptive = render.integrator == IntegrationMethod::Adaptive;
    // First hit: the part of a hit at t found in the piece or segment whose midpoint is `key`.
    auto hit_part = [&](const SamplePipeline& pipeline, const Ray& ray, double t, double key, double* p) {
        p[0] = key;
        const glm::dvec3 c = pipeline.sample(ray, t, SamplePipeline::Use::Surface).color;
        for (int i = 0; i < 3; ++i) p[1 + i] = c[i];
        p[4] = 1.0;
        p[5] = t;
    };
    // mip / minip: the part of this rank's extremum (none: p[0] stays kNone), classified here.
    auto extremum_part = [&](const SamplePipeline& pipeline, const Ray& ray, const Extremum<Scalar>& acc, double* p) {
        if (!acc.any()) return;
        p[0] = acc.where();
        const PipelineSample q = pipeline.sample(ray, acc.where(), SamplePipeline::Use::Unshaded);
        for (int i = 0; i < 3; ++i) p[1 + i] = q.opacity * q.color[i];
        p[4] = q.opacity;
        p[5] = acc.value();
    };
    // render.integrator "adaptive", other than composite: volume k's part from the pieces this rank
    // owns (cut as the single process cuts them; a piece lies in one cell, so in one brick: the one
    // holding its midpoint), by the adaptive integrator's own piece functions. These combine as
    // independent parts: mip / minip the extremum, average / xray the sums (p[5] the error sum),
    // first hit the nearest.
    auto adaptive_part = [&](std::size_t vk, const Ray* rays, const std::vector<Interval>& intervals, double* p) {
        const Ray& ray = rays[vk];
        const PreparedVolume& pv = *members[vk].prepared;
        const SamplePipeline& pipeline = *pv.pipeline;
        const auto* integrator = dynamic_cast<const AdaptiveIntegrator*>(pv.integrator.get());
        std::vector<double> cut;
        switch (render.projection) {
            case Projection::FirstHit: {  // first_crossing_exact, piece by piece
                const VolumeSampler& sampler = *pipeline.cartesian_sampler();  // trilinear (FirstHitIntegrator checks)
                const double iso = *render.isovalue;
                for (const Interval& iv : intervals) {
                    grid_cuts(ray, iv.t0, iv.t1, sampler.volume(), 0.0, cut);
                    for (std::size_t q = 0; q + 1 < cut.size(); ++q) {
                        const double ta = cut[q], tb = cut[q + 1];
                        if (!owned_point(rays[0], 0.5 * (ta + tb))) continue;
                        const std::optional<double> hit = q == 0 && sampler.trilinear(ray.at(iv.t0)) - iso == 0.0
                                                              ? std::optional<double>(iv.t0)
                                                              : first_crossing_in_cell(sampler, ray, ta, tb, iso);
                        if (hit) return hit_part(pipeline, ray, *hit, 0.5 * (ta + tb), p);
                    }
                }
                return;
            }
            case Projection::Mip:
            case Projection::Minip: {
                Extremum<Scalar> acc(render.projection == Projection::Mip);
                for (const Interval& iv : intervals) {
                    integrator->extremum_cuts(ray, iv, cut);
                    for (std::size_t q = 0; q + 1 < cut.size(); ++q)
                        if (owned_point(rays[0], 0.5 * (cut[q] + cut[q + 1])))
                            integrator->extremum_piece(ray, cut[q], cut[q + 1], acc);
                }
                return extremum_part(pipeline, ray, acc, p);
            }
            default: {  // average, xray: AdaptiveIntegrator::line_integral's budget, this rank's pieces
                const double per_length = integrator->line_budget(AdaptiveIntegrator::line_length(intervals));
                AdaptiveIntegrator::LineSums sums;
                CompensatedSum owned_length;
                bool any = false;
                for (const Interval& iv : intervals) {
                    integrator->cuts(ray, iv, cut);
                    for (std::size_t q = 0; q + 1 < cut.size(); ++q) {
                        const double ta = cut[q], tb = cut[q + 1];
                        if (!(tb > ta) || !owned_point(rays[0], 0.5 * (ta + tb))) continue;
                        if (!any) p[0] = 0.5 * (ta + tb);
                        any = true;
                        integrator->line_piece(ray, ta, tb, per_length, sums);
                        owned_length.add(tb - ta);
                    }
                }
                if (!any) return;
                p[5] = sums.error;
                p[6] = sums.integral.value();
                p[7] = owned_length.value();
                return;
            }
        }
    };
    // Volume k's part of the ray (its own step and projection), as a single-volume render's.
    auto volume_part = [&](std::size_t vk, const Ray* rays, const std::vector<Interval>& intervals, const Interval& range,
                           double* p) {
        if (adaptive) return adaptive_part(vk, rays, intervals, p);
        const Ray& ray = rays[vk];
        const PreparedVolume& pv = *members[vk].prepared;
        const SamplePipeline& pipeline = *pv.pipeline;
        const double step = pv.step, unit = pipeline.classifier().unit_distance();
        // FirstHitIntegrator's exact search (Cartesian trilinear grids), on this rank's brick.
        const VolumeSampler* trilinear = pipeline.cartesian_sampler();
        if (trilinear && trilinear->interpolation() != Interpolation::Trilinear) trilinear = nullptr;
        std::vector<Segment> owned;
        std::vector<std::array<std::int64_t, 3>> owned_at;  // first hit: interval, k, n
        for (std::size_t i = 0; i < intervals.size(); ++i)
            owned_segments(rays[0], intervals[i], step, range, [&](const Segment& s, std::int64_t k, std::int64_t n) {
                owned.push_back(s);
                if (first_hit) owned_at.push_back({std::int64_t(i), k, n});
            });
        if (owned.empty()) return;
        p[0] = owned.front().midpoint();
        switch (render.projection) {
            case Projection::Composite: {
                std::vector<Composited> samples;
                for (const Segment& s : owned) {
                    const PipelineSample q = pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
                    if (!(q.opacity > 0.0)) continue;
                    const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, q.opacity, s.length(), unit);
                    samples.push_back({o.solid, o.tau, o.alpha, q.color});
                }
                composite_part(samples, p);
                break;
            }
            case Projection::FirstHit: {
                // FirstHitIntegrator's search over this rank's segments (each one's ends read here: a
                // segment's g(t0) is its predecessor's g(t1), the same t); the key is the hit
                // segment's midpoint (ray order).
                p[0] = kNone;
                const double iso = *render.isovalue;
                auto g = [&](double t) { return pipeline.value(ray, t) - iso; };
                std::optional<double> hit;
                for (std::size_t m = 0; m < owned.size() && !hit; ++m) {
                    const Interval& iv = intervals[std::size_t(owned_at[m][0])];
                    const std::int64_t k = owned_at[m][1];
                    const double ta = owned[m].t0, tb = owned[m].t1, ga = g(ta);
                    if (k == 0 && ga == 0.0) hit = ta;
                    else hit = bracket_crossing(g, trilinear, ray, ta, ga, tb, g(tb), iso, iv.length());
                    if (hit) hit_part(pipeline, ray, *hit, owned[m].midpoint(), p);
                }
                break;
            }
            case Projection::Mip:
            case Projection::Minip: {
                Extremum<Scalar> acc(render.projection == Projection::Mip);
                for (const Segment& s : owned) acc.add(true, pipeline.value(ray, s.midpoint()), s.midpoint());
                p[0] = kNone;
                extremum_part(pipeline, ray, acc, p);
                break;
            }
            default: {  // average, xray
                LineIntegral<CompensatedSum> acc;
                for (const Segment& s : owned) {
                    const double c = pipeline.classifier().coordinate(pipeline.value(ray, s.midpoint()));
                    acc.add(std::isfinite(c) ? c * s.length() : 0.0, s.length());
                }
                p[6] = acc.integral();
                p[7] = acc.length();
                break;
            }
        }
    };
    // Several volumes, composite: the mix of the volumes present (MultiVolumeIntegrator::mix) at each
    // owned segment of the pieces (segments restart at every piece, step = the smallest volume step).
    auto mixed_part = [&](const std::vector<Ray>& rays, const std::vector<Interval>* intervals, const Interval& range,
                          double* p, MultiVolumeIntegrator::MixScratch& scratch) {
        std::vector<Composited> samples;
        bool any = false;
        for (const MultiVolumeIntegrator::Piece& piece : MultiVolumeIntegrator::pieces(intervals, V))
            owned_segments(rays[0], piece.span, multi->step(), range, [&](const Segment& s, std::int64_t, std::int64_t) {
                if (!any) p[0] = s.midpoint();
                any = true;
                const MultiVolumeIntegrator::MixedSegment m = multi->mix(rays.data(), piece.present, s, scratch);
                if (!m.opaque && !(m.tau > 0.0)) return;
                samples.push_back({m.opaque, m.tau, m.opaque ? 1.0 : segment_alpha<Scalar>(m.tau), m.color});
            });
        if (any) composite_part(samples, p);
    };
    // ---- composite with render.integrator "adaptive" or with early termination: the ray's state
    // handed from rank to rank ----
    // The adaptive integrator's refinement of a piece depends on the transmittance in front of it,
    // the largest colour seen and the rules left (AdaptiveComposite.h), and early termination on the
    // opacity in front: a rank's part cannot be integrated before those of the ranks in front. Every
    // rank lists what it owns (adaptive: the pieces cut as the single process cuts them, a piece
    // belonging to the brick holding its midpoint; fixed step: the range of owned segments of each
    // interval or piece) and its key (the first one's midpoint); the keys are all-gathered, giving each
    // pixel's ranks in ray order; in round j the j-th rank of each pixel continues that pixel's state
    // over what it owns, and an MPI_Allreduce hands the states on. The adaptive error's sums run back
    // to front the same way (what is emitted behind each leaf). Pixels' R G B A (error) in `chained`.
    const bool chain = render.projection == Projection::Composite && (adaptive || render.early_termination);
    std::vector<double> chained;
    std::size_t chain_bytes = 0;  // what this rank hands to the collectives (keys, N rounds each way)
    if (chain) {
        using Composite = AdaptiveIntegrator::Composite;
        using MixComposite = AdaptiveComposite<MultiVolumeIntegrator::AdaptiveMix>;
        const auto* one = adaptive && V == 1 ? dynamic_cast<const AdaptiveIntegrator*>(members[0].prepared->integrator.get()) : nullptr;
        const std::size_t P = std::size_t(W) * std::size_t(H);
        // Fixed step: FrontToBack's state, opaque, stopped.
        constexpr std::size_t kFixedState = std::size_t(FrontToBack<Scalar>::kStateValues) + 2;
        const std::size_t S = adaptive ? std::size_t(Composite::kStateSize) : kFixedState;
        // Each pixel's owned parts: adaptive [a, b, union piece]; fixed step [interval or union piece,
        // first segment, last segment].
        std::vector<std::vector<std::array<double, 3>>> pieces(P);
        std::vector<double> key(P, kNone), total(P, 0.0);
        std::vector<int> position(P, -1), count(P, 0);
        tbb::task_arena arena(args.threads > 0 ? args.threads : tbb::task_arena::automatic);
        // f(px, rays, intervals) for the pixels `round` selects (-1: all), in parallel.
        auto each_pixel = [&](int round, auto&& f) {
            arena.execute([&] {
                tbb::parallel_for(tbb::blocked_range<std::size_t>(0, P), [&](const tbb::blocked_range<std::size_t>& r) {
                    std::vector<std::vector<Interval>> intervals(V);
                    std::vector<Ray> rays(V);
                    for (std::size_t px = r.begin(); px != r.end(); ++px) {
                        if (round >= 0 && position[px] != round) continue;
                        pixel_intervals(int(px % std::size_t(W)), int(px / std::size_t(W)), rays.data(), intervals.data());
                        f(px, rays, intervals);
                    }
                });
            });
        };
        // The spans the fixed step's segments are placed on: one volume's intervals, or the pieces of
        // several volumes' union (MultiVolumeIntegrator::composite).
        auto fixed_spans = [&](const std::vector<std::vector<Interval>>& intervals) {
            std::vector<MultiVolumeIntegrator::Piece> spans;
            if (V == 1)
                for (const Interval& iv : intervals[0]) spans.push_back({iv, {0}});
            else
                spans = MultiVolumeIntegrator::pieces(intervals.data(), V);
            return spans;
        };
        const double fixed_step = V == 1 ? members[0].prepared->step : (multi ? multi->step() : 0.0);
        try {
            if (adaptive && V == 1 && !one) throw Error("render.integrator: internal: volref-mpi found no adaptive integrator");
            each_pixel(-1, [&](std::size_t px, const std::vector<Ray>& rays, const std::vector<std::vector<Interval>>& intervals) {
                std::vector<double> cut, all;
                const Ray& ray = rays[0];
                auto keep = [&](double a, double b, std::size_t piece) {
                    if (owned_point(ray, 0.5 * (a + b))) pieces[px].push_back({a, b, double(piece)});
                };
                if (!adaptive) {  // the owned segments of each span: one run (the brick is convex)
                    Interval range;
                    if (!intersect_box(ray, blo, bhi, range)) return;
                    const auto spans = fixed_spans(intervals);
                    for (std::size_t i = 0; i < spans.size(); ++i) {
                        std::int64_t first = -1, last = -1;
                        owned_segments(ray, spans[i].span, fixed_step, range, [&](const Segment& sg, std::int64_t k, std::int64_t) {
                            if (first < 0) {
                                first = k;
                                if (key[px] == kNone) key[px] = sg.midpoint();
                            }
                            last = k;
                        });
                        if (first >= 0) pieces[px].push_back({double(i), double(first), double(last)});
                    }
                    return;
                }
                if (V == 1) {  // AdaptiveIntegrator::composite's pieces
                    for (const Interval& iv : intervals[0]) total[px] += iv.length();
                    for (const Interval& iv : intervals[0]) {
                        one->cuts(ray, iv, cut);
                        for (std::size_t q = 0; q + 1 < cut.size(); ++q) keep(cut[q], cut[q + 1], 0);
                    }
                } else {  // MultiVolumeIntegrator::adaptive_composite's
                    const auto ps = MultiVolumeIntegrator::pieces(intervals.data(), V);
                    for (const auto& piece : ps) total[px] += piece.span.length();
                    for (std::size_t i = 0; i < ps.size(); ++i) {
                        multi->adaptive_cuts(rays.data(), ps[i], all, cut);
                        for (std::size_t q = 0; q + 1 < all.size(); ++q) keep(all[q], all[q + 1], i);
                    }
                }
                if (!pieces[px].empty()) key[px] = 0.5 * (pieces[px][0][0] + pieces[px][0][1]);
            });
        } catch (const std::bad_alloc&) {
            err = "out of memory";
        } catch (const std::exception& e) {
            err = e.what();
        }
        if (any_error(err, rank, size)) return 1;
        std::vector<double> keys(P * std::size_t(size));
        MPI_Allgather(key.data(), int(P), MPI_DOUBLE, keys.data(), int(P), MPI_DOUBLE, MPI_COMM_WORLD);
        chain_bytes = P * sizeof(double) * (1 + std::size_t(size) * (S + (adaptive ? 5 : 0)));
        for (std::size_t px = 0; px < P; ++px)
            for (int r = 0; r < size; ++r) {
                const double k = keys[std::size_t(r) * P + px];
                if (k == kNone) continue;
                ++count[px];
                if (key[px] != kNone && (k < key[px] || (k == key[px] && r < rank))) ++position[px];
            }
        for (std::size_t px = 0; px < P; ++px)
            if (key[px] != kNone) ++position[px];  // from -1: the ranks in front of this one
        const double tolerance = render.tolerance;
        const double safety = !adaptive ? 1.0 : V == 1 ? one->safety() : multi->adaptive_safety();
        const Termination stop = early_termination(render);
        std::vector<double> state(P * S, 0.0), delta(P * S), next(P * S);
        const AdaptiveIntegrator::OneVolume none{one, nullptr};  // (a medium never sampled)
        if (adaptive) {
            const Composite fresh(none, tolerance, safety, 1.0);
            for (std::size_t px = 0; px < P; ++px) fresh.save(&state[px * S]);
        } else {
            const FrontToBack<Scalar> fresh;
            bool opaque = false;
            for (std::size_t px = 0; px < P; ++px) fresh.save(&state[px * S], opaque);
        }
        // The fixed step over one rank's segments, continuing `acc` (CompositeIntegrator::front_to_back,
        // MultiVolumeIntegrator::composite); true once the ray stops (opaque or terminated).
        auto fixed_step_part = [&](std::size_t px, const std::vector<Ray>& rays, const std::vector<std::vector<Interval>>& intervals,
                                   FrontToBack<Scalar>& acc) {
            const auto spans = fixed_spans(intervals);
            MultiVolumeIntegrator::MixScratch scratch;
            const SamplePipeline& pipeline = *members[0].prepared->pipeline;
            const double unit = pipeline.classifier().unit_distance();
            for (const auto& owned : pieces[px]) {
                const MultiVolumeIntegrator::Piece& span = spans[std::size_t(owned[0])];
                const std::int64_t n = segment_count(span.span, fixed_step);
                for (std::int64_t k = std::int64_t(owned[1]); k <= std::int64_t(owned[2]); ++k) {
                    const Segment sg = segment(span.span, fixed_step, k, n);
                    if (V == 1) {
                        const PipelineSample q = pipeline.sample(rays[0], sg.midpoint(), SamplePipeline::Use::Composite);
                        if (!(q.opacity > 0.0)) continue;
                        const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, q.opacity, sg.length(), unit);
                        const double c[3] = {q.color.r, q.color.g, q.color.b};
                        acc.add(true, o.solid, o.tau, o.alpha, c);
                        if (o.solid || acc.stops(o.partial, stop)) return true;
                    } else {
                        const MultiVolumeIntegrator::MixedSegment m = multi->mix(rays.data(), span.present, sg, scratch);
                        if (!m.opaque && !(m.tau > 0.0)) continue;
                        const double c[3] = {m.color.r, m.color.g, m.color.b};
                        acc.add(true, m.opaque, m.tau, m.opaque ? 1.0 : segment_alpha<Scalar>(m.tau), c);
                        if (m.opaque || acc.stops(true, stop)) return true;
                    }
                }
            }
            return false;
        };
        std::vector<std::vector<adaptive_detail::Leaf>> leaves(P);
        for (int j = 0; j < size; ++j) {
            std::fill(delta.begin(), delta.end(), 0.0);
            try {
                each_pixel(j, [&](std::size_t px, const std::vector<Ray>& rays, const std::vector<std::vector<Interval>>& intervals) {
                    const Ray& ray = rays[0];
                    if (!adaptive) {
                        FrontToBack<Scalar> acc;
                        double* in = &state[px * S];
                        bool opaque = in[kFixedState - 2] != 0.0, stopped = in[kFixedState - 1] != 0.0;
                        acc.load(in, opaque);
                        if (!stopped) stopped = fixed_step_part(px, rays, intervals, acc);
                        acc.save(&delta[px * S], opaque);
                        delta[px * S + kFixedState - 2] = opaque ? 1.0 : 0.0;
                        delta[px * S + kFixedState - 1] = stopped ? 1.0 : 0.0;
                    } else if (V == 1) {
                        const AdaptiveIntegrator::OneVolume medium{one, &ray};
                        Composite st(medium, tolerance, safety, total[px]);
                        st.load(&state[px * S]);
                        for (const auto& piece : pieces[px]) {
                            if (st.is_opaque()) break;
                            one->composite_piece(ray, piece[0], piece[1], st);
                        }
                        st.save(&delta[px * S]);
                        leaves[px] = st.leaves();
                    } else {
                        const auto ps = MultiVolumeIntegrator::pieces(intervals.data(), V);
                        MultiVolumeIntegrator::AdaptiveMix medium = multi->adaptive_mix(rays.data());
                        MixComposite st(medium, tolerance, safety, total[px]);
                        st.load(&state[px * S]);
                        std::vector<MultiVolumeIntegrator::MixTerm> opaque;
                        for (const auto& piece : pieces[px]) {
                            if (st.is_opaque()) break;
                            const std::vector<int>& present = ps[std::size_t(piece[2])].present;
                            medium.present = &present;
                            multi->adaptive_piece(rays.data(), present, piece[0], piece[1], st, opaque);
                        }
                        st.save(&delta[px * S]);
                        leaves[px] = st.leaves();
                    }
                });
            } catch (const std::bad_alloc&) {
                err = "out of memory";
            } catch (const std::exception& e) {
                err = e.what();
            }
            if (any_error(err, rank, size)) return 1;
            // One rank wrote each pixel of this round, the others 0: the sum is its state.
            MPI_Allreduce(delta.data(), next.data(), int(P * S), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
            for (std::size_t px = 0; px < P; ++px)
                if (count[px] > j) std::copy(&next[px * S], &next[px * S] + S, &state[px * S]);
        }
        if (!adaptive) {  // the fixed step's pixels: FrontToBack's colour and alpha
            chained.assign(P * 4, 0.0);
            for (std::size_t px = 0; px < P; ++px) {
                FrontToBack<Scalar> acc;
                acc.load(&state[px * S], state[px * S + kFixedState - 2] != 0.0);
                for (int c = 0; c < 3; ++c) chained[px * 4 + std::size_t(c)] = acc.color(c);
                chained[px * 4 + 3] = acc.alpha();
            }
        } else {
            // The error's sums, back to front: (behind R G B, colour_err, tau_err), from the opaque piece's T c.
            constexpr std::size_t E = 5;
            std::vector<double> sums(P * E, 0.0), dsums(P * E), nsums(P * E);
            for (std::size_t px = 0; px < P; ++px)
                for (int i = 0; i < 3; ++i) sums[px * E + std::size_t(i)] = state[px * S + Composite::kStateOpaqueColour + std::size_t(i)];
            for (int j = size - 1; j >= 0; --j) {
                std::fill(dsums.begin(), dsums.end(), 0.0);
                for (std::size_t px = 0; px < P; ++px) {
                    if (position[px] != j) continue;
                    double* q = &sums[px * E];
                    glm::dvec3 behind(q[0], q[1], q[2]);
                    double colour_err = q[3], tau_err = q[4];
                    Composite::error_sums(leaves[px], behind, colour_err, tau_err);
                    double* d = &dsums[px * E];
                    d[0] = behind.r, d[1] = behind.g, d[2] = behind.b, d[3] = colour_err, d[4] = tau_err;
                }
                MPI_Allreduce(dsums.data(), nsums.data(), int(P * E), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
                for (std::size_t px = 0; px < P; ++px)
                    if (count[px] > j) std::copy(&nsums[px * E], &nsums[px * E] + E, &sums[px * E]);
            }
            chained.assign(P * 5, 0.0);
            for (std::size_t px = 0; px < P; ++px) {
                if (!(total[px] > 0.0)) continue;  // no interval: (0, 0, 0, 0), error 0 (as the single process)
                Composite st(none, tolerance, safety, total[px]);
                st.load(&state[px * S]);
                const PixelValue v = st.result_from(sums[px * E + 3], sums[px * E + 4]);
                for (int c = 0; c < 4; ++c) chained[px * 5 + std::size_t(c)] = v.rgba[c];
                chained[px * 5 + 4] = v.error;
            }
        }
    }
    if (!chain) try {
        tbb::task_arena arena(args.threads > 0 ? args.threads : tbb::task_arena::automatic);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int>& rows) {
                std::vector<std::vector<Interval>> intervals(V);
                std::vector<Ray> rays(V);
                MultiVolumeIntegrator::MixScratch scratch;
                for (int y = rows.begin(); y != rows.end(); ++y)
                    for (int x = 0; x < W; ++x) {
                        pixel_intervals(x, y, rays.data(), intervals.data());
                        double* p = &part[(std::size_t(y) * std::size_t(W) + std::size_t(x)) * slots * kPart];
                        for (std::size_t s = 0; s < slots; ++s) p[s * kPart] = kNone;
                        Interval range;  // the ray in the brick's box (in the first volume's space)
                        bool none = true;
                        for (const auto& iv : intervals) none = none && iv.empty();
                        if (none || !intersect_box(rays[0], blo, bhi, range)) continue;
                        if (mixed) {
                            mixed_part(rays, intervals.data(), range, p, scratch);
                        } else {
                            for (std::size_t k = 0; k < V; ++k)
                                if (!intervals[k].empty()) volume_part(k, rays.data(), intervals[k], range, p + k * kPart);
                        }
                    }
            });
        });
    } catch (const std::bad_alloc&) {
        err = "out of memory";
    } catch (const std::exception& e) {
        err = e.what();
    }
    if (any_error(err, rank, size)) return 1;

    const double t_render = now();
    MPI_Barrier(MPI_COMM_WORLD);  // (timing: the compositing below starts when the slowest rank is done)
    const double t_ready = now();

    // One slot's pixel from its parts in ray order (sorted by key; parts with no segment, key +inf,
    // last): R G B A (and Z for first hit).
    const int nc = 4 + (first_hit ? 1 : 0) + (adaptive ? 1 : 0);
    auto pixel_of = [&](const double* const* order, int count) {
        glm::dvec4 rgba(0.0);
        double line_error = 0.0;
        double depth = kNone;
        if (first_hit) {  // the nearest rank's hit
            if (order[0][0] != kNone) {
                rgba = glm::dvec4(order[0][1], order[0][2], order[0][3], 1.0);
                depth = order[0][5];
            }
        } else if (render.projection == Projection::Composite) {
            CompensatedSum tau;
            bool opaque = false;
            glm::dvec3 c(0.0);
            for (int r = 0; r < count; ++r) {
                const double* q = order[r];
                if (q[0] == kNone) break;
                const double T = std::exp(-tau.value());
                for (int i = 0; i < 3; ++i) c[i] += T * q[1 + i];
                tau.add(q[4]);
                if (q[5] != 0.0) {
                    opaque = true;
                    break;
                }
            }
            rgba = glm::dvec4(c, opaque ? 1.0 : -std::expm1(-tau.value()) + 0.0);
        } else if (render.projection == Projection::Mip || render.projection == Projection::Minip) {
            const bool maximum = render.projection == Projection::Mip;
            const double* best = nullptr;
            for (int r = 0; r < count; ++r) {
                const double* q = order[r];
                if (q[0] == kNone) break;
                if (!best || (maximum ? q[5] > best[5] : q[5] < best[5])) best = q;
            }
            if (best) rgba = glm::dvec4(best[1], best[2], best[3], best[4]);
        } else {  // average, xray
            bool hit = false;
            CompensatedSum integral, length, error;
            for (int r = 0; r < count; ++r) {
                const double* q = order[r];
                if (q[0] == kNone) break;
                hit = true;
                integral.add(q[6]);
                length.add(q[7]);
                error.add(q[5]);
            }
            if (hit) {
                const bool mean = render.projection == Projection::Average;
                const double g = mean ? integral.value() / length.value() : render.gain * integral.value();
                rgba = glm::dvec4(g, g, g, 1.0);
                // The adaptive integrator's estimate (AdaptiveIntegrator::line_integral's form).
                if (adaptive)
                    line_error = (mean ? error.value() / length.value() : render.gain * error.value()) +
                                 adaptive_detail::rounding_bound(rgba);
            }
        }
        PixelValue v;
        v.rgba = rgba;
        v.depth = depth;
        // The adaptive integrator's error channel: the rounding bound of an exact result (mip, minip,
        // first hit: AdaptiveIntegrator::extremum, FirstHitIntegrator), the sums' estimate (average, xray).
        if (adaptive)
            v.error = render.projection == Projection::Average || render.projection == Projection::Xray
                          ? line_error
                          : adaptive_detail::rounding_bound(rgba);
        return v;
    };
    // Pixel px from its slots' values: one slot as it is; several volumes (other than composite)
    // combined by the single-process rule (MultiVolumeIntegrator::combine, which reads the pixel's
    // intervals: recomputed here). out = R G B A (and Z).
    auto finish = [&](std::size_t px, const PixelValue* values, double* out, std::vector<std::vector<Interval>>& intervals,
                      std::vector<Ray>& rays) {
        PixelValue v = values[0];
        if (slots > 1) {
            pixel_intervals(int(px % std::size_t(W)), int(px / std::size_t(W)), rays.data(), intervals.data());
            v = multi->combine(values, intervals.data());
        }
        for (int c = 0; c < 4; ++c) out[c] = v.rgba[c];
        if (first_hit) out[4] = v.depth;
        if (adaptive) out[nc - 1] = v.error;
    };

    std::vector<std::string> channels{"R", "G", "B", "A"};
    if (first_hit) channels.push_back("Z");  // as volref render writes it
    if (adaptive) channels.push_back("error");  // the adaptive integrator's estimate, as volref render writes it
    std::unique_ptr<Image> image;
    if (rank == 0) image = std::make_unique<Image>(W, H, channels);
    const std::size_t pixels = std::size_t(W) * std::size_t(H);
    std::size_t bytes_sent = 0, bytes_received = 0;  // by this rank, this frame
    double t_gather = 0.0;  // rank 0: the parts (direct) or the finished pixels (swap) are in
    if (chain) {  // every rank holds the pixels
        t_gather = now();
        bytes_sent = chain_bytes;
        if (rank == 0) std::copy(chained.begin(), chained.end(), image->pixels.begin());
    } else if (!swap) {
        // ---- direct send: every rank's parts to rank 0, combined there in ray order ----
        std::vector<double> all;
        if (rank == 0) all.resize(part.size() * std::size_t(size));
        MPI_Gather(part.data(), int(part.size()), MPI_DOUBLE, all.data(), int(part.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
        t_gather = now();
        if (rank != 0) bytes_sent = part.size() * sizeof(double);
        else bytes_received = part.size() * sizeof(double) * std::size_t(size - 1);
        if (rank == 0) {
            const std::size_t stride = part.size();
            std::vector<const double*> order(static_cast<std::size_t>(size));
            std::vector<PixelValue> values(slots);
            std::vector<std::vector<Interval>> intervals(V);
            std::vector<Ray> rays(V);
            for (std::size_t px = 0; px < pixels; ++px) {
                for (std::size_t sl = 0; sl < slots; ++sl) {
                    for (int r = 0; r < size; ++r)
                        order[std::size_t(r)] = &all[std::size_t(r) * stride + (px * slots + sl) * kPart];
                    // Ray order: the key, then the rank (ties of the extremum: the first sample wins).
                    std::stable_sort(order.begin(), order.end(), [](const double* a, const double* b) { return a[0] < b[0]; });
                    values[sl] = pixel_of(order.data(), size);
                }
                finish(px, values.data(), &image->pixels[px * std::size_t(nc)], intervals, rays);
            }
        }
    } else {
        // ---- binary swap: log2(N) rounds; in round i rank r and its partner r ^ 2^i halve the pixel
        // range they share, each sends the other half to the other and merges the half it keeps. The
        // k-d split of a power-of-two count gives ranks r and r ^ 1 sibling bricks, and after round i
        // the 2^(i+1) ranks merged are one subtree's box, convex: the ray crosses it in one run of
        // segments, so two merged parts are in ray order by their keys. Then rank 0 gathers the
        // finished pixels of every rank's range (MPI_Gatherv). ----
        auto merge = [&](double* a, const double* b, bool b_first_on_tie) {
            if (b[0] == kNone) return;
            if (a[0] == kNone) {
                std::copy(b, b + kPart, a);
                return;
            }
            const bool b_front = b[0] < a[0] || (b[0] == a[0] && b_first_on_tie);
            const double* f = b_front ? b : a;  // front
            const double* k = b_front ? a : b;  // back
            double out[kPart];
            std::copy(f, f + kPart, out);
            if (render.projection == Projection::Composite) {
                if (f[5] == 0.0) {  // front over back; tau adds; opaque when the back is
                    const double T = std::exp(-f[4]);
                    for (int i = 1; i <= 3; ++i) out[i] = f[i] + T * k[i];
                    out[4] = f[4] + k[4];
                    out[5] = k[5];
                }
            } else if (render.projection == Projection::Mip || render.projection == Projection::Minip) {
                const bool maximum = render.projection == Projection::Mip;
                if (maximum ? k[5] > f[5] : k[5] < f[5]) std::copy(k, k + kPart, out);  // ties: the front's
            } else if (!first_hit) {  // average, xray: the sums add (adaptive: and the error estimates)
                out[5] = f[5] + k[5];
                out[6] = f[6] + k[6];
                out[7] = f[7] + k[7];
            }
            std::copy(out, out + kPart, a);
        };
        auto range_of = [&](int r) {
            std::size_t lo = 0, hi = pixels;
            for (int bit = 1; bit < size; bit <<= 1) {
                const std::size_t mid = lo + (hi - lo) / 2;
                if (r & bit) lo = mid;
                else hi = mid;
            }
            return std::array<std::size_t, 2>{lo, hi};
        };
        std::vector<double> incoming;
        std::size_t lo = 0, hi = pixels;
        for (int bit = 1; bit < size; bit <<= 1) {
            const int partner = rank ^ bit;
            const std::size_t mid = lo + (hi - lo) / 2;
            const bool upper = (rank & bit) != 0;
            const std::size_t keep_lo = upper ? mid : lo, keep_hi = upper ? hi : mid;
            const std::size_t send_lo = upper ? lo : mid, send_hi = upper ? mid : hi;
            const std::size_t stride = slots * kPart;  // one pixel's slots
            incoming.resize((keep_hi - keep_lo) * stride);
            MPI_Sendrecv(&part[send_lo * stride], int((send_hi - send_lo) * stride), MPI_DOUBLE, partner, bit,
                         incoming.data(), int(incoming.size()), MPI_DOUBLE, partner, bit, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            bytes_sent += (send_hi - send_lo) * stride * sizeof(double);
            bytes_received += incoming.size() * sizeof(double);
            for (std::size_t px = keep_lo; px < keep_hi; ++px)
                for (std::size_t sl = 0; sl < slots; ++sl)
                    merge(&part[px * stride + sl * kPart], &incoming[(px - keep_lo) * stride + sl * kPart], upper);
            lo = keep_lo;
            hi = keep_hi;
        }
        std::vector<double> finished((hi - lo) * std::size_t(nc));
        std::vector<PixelValue> values(slots);
        std::vector<std::vector<Interval>> intervals(V);
        std::vector<Ray> rays(V);
        for (std::size_t px = lo; px < hi; ++px) {
            for (std::size_t sl = 0; sl < slots; ++sl) {
                const double* q = &part[(px * slots + sl) * kPart];
                values[sl] = pixel_of(&q, 1);
            }
            finish(px, values.data(), &finished[(px - lo) * std::size_t(nc)], intervals, rays);
        }
        std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
        for (int r = 0; r < size; ++r) {
            const auto rr = range_of(r);
            counts[std::size_t(r)] = int((rr[1] - rr[0]) * std::size_t(nc));
            displs[std::size_t(r)] = int(rr[0] * std::size_t(nc));
        }
        MPI_Gatherv(finished.data(), int(finished.size()), MPI_DOUBLE, rank == 0 ? image->pixels.data() : nullptr,
                    counts.data(), displs.data(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
        t_gather = now();
        if (rank != 0) bytes_sent += finished.size() * sizeof(double);
        else bytes_received += (pixels - (hi - lo)) * std::size_t(nc) * sizeof(double);
    }
    if (rank == 0) {
        try {
            if (dump_output(args.output)) write_dump(*image, args.output);
            else write_image(*image, args.output, scene.image.background);
        } catch (const std::exception& e) {
            err = e.what();
        }
    }
    const double t_write = now();
    if (any_error(err, rank, size)) return 1;
    if (args.timing) {  // the slowest rank's set-up and render; rank 0's compositing and write
        double mine[2] = {t_setup - t_start, t_render - t_setup}, slowest[2] = {0.0, 0.0};
        MPI_Reduce(mine, slowest, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        unsigned long long sent = bytes_sent, most = 0;
        MPI_Reduce(&sent, &most, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, 0, MPI_COMM_WORLD);
        if (rank == 0)
            std::fprintf(stderr,
                         "volref: timing {\"ranks\": %d, \"compositing\": \"%s\", \"setup_s\": %.4f, \"render_s\": %.4f, "
                         "\"gather_s\": %.4f, \"combine_write_s\": %.4f, \"bytes_sent_per_rank\": %llu, "
                         "\"bytes_received_rank0\": %llu, \"image_bytes\": %zu}\n",
                         size, chain ? "chain" : swap ? "swap" : "direct", slowest[0], slowest[1], t_gather - t_ready, t_write - t_gather,
                         most, (unsigned long long)bytes_received,
                         pixels * std::size_t(nc) * sizeof(double));
    }
    if (args.compositing == "swap" && !power_of_two && args.compositing_given && rank == 0)
        std::fprintf(stderr, "volref-mpi: note: binary swap needs a power-of-two rank count; %d ranks used direct send\n",
                     size);
    if (rank == 0) std::printf("%s\n", args.output.c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    CLI::App app{"volref-mpi: volref render over MPI ranks, one brick of the volume per rank"};
    app.require_subcommand(1);
    app.fallthrough();
    Args args;
    app.add_option("--max-memory", args.max_memory, "Refuse a brick, image or cache needing more than SIZE per rank (e.g. 512M)")
        ->envname("VOLREF_MAX_MEMORY");
    CLI::App* rc = app.add_subcommand("render", "Render a scene file to an image (.exr, .png, .tif)");
    rc->add_option("scene", args.scene, "Scene file (JSON)")->required();
    rc->add_option("-o,--output", args.output, "Output image (written by rank 0)")->required();
    rc->add_option("--threads", args.threads, "Worker threads per rank (default: all cores)")->check(CLI::Range(1, 4096));
    rc->add_option("--set", args.overrides, "Override one scene value: PATH=VALUE")->take_all();
    rc->add_option("--compositing", args.compositing,
                   "How the ranks' parts are combined: swap (binary swap, power-of-two rank counts; others fall back "
                   "to direct) or direct (MPI_Gather to rank 0)")
        ->check(CLI::IsMember({"direct", "swap"}))
        ->capture_default_str();
    rc->add_flag("--timing", args.timing,
                 "Print one line on stderr (rank 0): volref: timing {ranks, compositing, setup_s, render_s (the slowest "
                 "rank's), gather_s, combine_write_s, bytes_sent_per_rank (the most any rank sent), bytes_received_rank0, "
                 "image_bytes}");
    int status = 0;
    try {
        app.parse(argc, argv);
        args.compositing_given = rc->count("--compositing") > 0;
        status = run(args, rank, size);
    } catch (const CLI::ParseError& e) {
        status = rank == 0 ? (app.exit(e) == 0 ? 0 : 2) : (e.get_exit_code() == 0 ? 0 : 2);
    }
    MPI_Finalize();
    return status;
}
