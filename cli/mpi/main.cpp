// volref-mpi render SCENE -o OUT [--threads T] [--max-memory M] [--set PATH=VALUE ...]
//
// One volume split into bricks over the MPI ranks (cli/mpi/Bricks.h); each rank holds its brick plus a
// ghost layer (read as a sub-box of the file, or generated), integrates the part of every ray inside
// its brick on the single-process render's sample lattice (segment k of an interval at the same t on
// every rank; a segment belongs to the brick holding its midpoint), and rank 0 combines the parts in
// ray order (MPI_Gather, direct send) and writes the image. Errors of any rank reach rank 0, which
// prints the one line `volref render` prints (the lowest rank's); every rank exits 1; no file is
// written. docs/conventions.md §14, docs/architecture.md "volref-mpi", docs/performance.md.
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
#include "core/integrate/fixed/FirstHitIntegrator.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/render/PreparedVolume.h"
#include "core/render/VolumeLoaderHook.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/SceneLoader.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/BoxIntersection.h"
#include "geometry/ClipPlanes.h"
#include "geometry/CropRegions.h"
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

// The first version's scope (docs/conventions.md §14): one-line errors naming the key.
void check_supported(const Scene& scene) {
    if (scene.volumes.size() != 1) throw Error("volumes: volref-mpi renders one volume (several volumes are not supported yet)");
    const VolumeSpec& vs = scene.volume();
    const RenderSpec& r = scene.render;
    if (r.integrator != IntegrationMethod::Fixed)
        throw Error("render.integrator: volref-mpi supports \"fixed\" only (the adaptive integrator is not supported yet)");
    if (r.profile != ProfileId::Reference)
        throw Error("render.profile: volref-mpi supports \"reference\" only (mirror and fast profiles are not supported yet)");
    if (r.early_termination) throw Error("render.early_termination: not supported by volref-mpi yet");
    if (vs.bounds.type != BoundsSpec::Type::Box)
        throw Error("volume.bounds: volref-mpi supports box bounds only (meshes and shells are not supported yet)");
    if (vs.transform) throw Error("volume.transform: not supported by volref-mpi yet");
    if (vs.gradient.cache || vs.gradient.cache_auto) throw Error("volume.gradient.cache: not supported by volref-mpi yet");
    if (vs.classify == VolumeSpec::Classify::Pre) throw Error("volume.classify: \"pre\" is not supported by volref-mpi yet");
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

int run(const Args& args, int rank, int size) {
    std::string err;
    // Binary swap needs a power-of-two rank count; others use direct send (said on stderr after a
    // successful render when --compositing swap was asked for).
    const bool power_of_two = (size & (size - 1)) == 0;
    const bool swap = args.compositing == "swap" && power_of_two && size > 1;
    const double t_start = now();
    // ---- set-up: scene, bricks, this rank's brick, its pipeline ----
    Scene scene;
    std::array<std::int64_t, 3> dims{1, 1, 1};
    glm::dvec3 origin(0.0), spacing(1.0);
    std::vector<mpi::Brick> bricks;
    std::unique_ptr<PreparedVolume> prepared;
    std::unique_ptr<Camera> camera;
    BoundingGeometry geometry;
    int geometry_id = 0;
    Volume brick_volume;
    try {
        if (!args.max_memory.empty()) set_memory_limit(parse_memory_size(args.max_memory, "--max-memory"));
        if (rank == 0 && !dump_output(args.output)) check_output_path(args.output);
        scene = load_scene(args.scene, args.overrides);
        check_supported(scene);
        VolumeSpec& vs = scene.volume();
        VolumeLayout header;
        if (vs.source.field) {
            dims = vs.source.field->dims;
            origin = vs.origin.value_or(glm::dvec3(0.0));
            spacing = vs.spacing.value_or(glm::dvec3(1.0));
        } else {
            header = mpi::read_volume_header(*vs.source.file, vs.source.format);
            dims = header.dims;
            origin = vs.origin.value_or(header.origin);
            spacing = vs.spacing.value_or(header.spacing);
            header.origin = origin;
            header.spacing = spacing;
        }
        int ghost = mpi::ghost_voxels(vs, scene.render);
        if (scene.render.projection == Projection::FirstHit) {
            // The sign test reads both ends of an owned segment (its midpoint +- h / 2) and the search
            // runs between them: the ghost layer reaches h / 2 further (h in voxels of the finest axis).
            const double finest = std::min({spacing.x, spacing.y, spacing.z});
            const double h = scene.render.step_units == StepUnits::World ? scene.render.step / finest : scene.render.step;
            if (!(h > 0.0) || !(h < 1e6)) throw Error("render.step: too large for volref-mpi's ghost layer");
            ghost += int(std::ceil(0.5 * h));
        }
        bricks = mpi::split_bricks(dims, size, ghost);
        const mpi::Brick& b = bricks[std::size_t(rank)];
        if (vs.source.field) brick_volume = make_procedural_brick(*vs.source.field, origin, spacing, b.vlo, b.voxel_dims());
        else brick_volume = mpi::read_brick(header, b.vlo, b.voxel_dims());
    } catch (const std::bad_alloc&) {
        err = "out of memory";
    } catch (const std::exception& e) {
        err = e.what();
    }
    if (any_error(err, rank, size)) return 1;
    try {
        VolumeSpec& vs = scene.volume();
        // Whatever reads the volume's data range (the transfer function's default window of a float
        // volume, the shader's zero-gradient tolerance) reads the whole volume's: the ranks agree on it
        // first (Volume::whole_range).
        {
            const auto r = brick_volume.value_range();
            double lo = r[0], hi = r[1], glo = 0.0, ghi = 0.0;
            MPI_Allreduce(&lo, &glo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
            MPI_Allreduce(&hi, &ghi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            brick_volume.whole_range = std::array<double, 2>{glo, ghi};
        }
        set_volume_loader_hook([&](const VolumeSpec&) { return std::move(brick_volume); });
        RenderOptions options;
        options.threads = args.threads;
        prepared = std::make_unique<PreparedVolume>(scene, 0, options, 0);
        set_volume_loader_hook({});
        // The whole volume's box (bounds AND domain): the intervals and the default camera of the
        // single-process render.
        const glm::dvec3 domain_lo = origin;
        const glm::dvec3 domain_hi = origin + glm::dvec3(double(dims[0] - 1), double(dims[1] - 1), double(dims[2] - 1)) * spacing;
        const glm::dvec3 box_lo = vs.bounds.min.value_or(domain_lo), box_hi = vs.bounds.max.value_or(domain_hi);
        if (!(box_lo.x <= box_hi.x && box_lo.y <= box_hi.y && box_lo.z <= box_hi.z))
            throw Error("volume.bounds: min must not exceed max");
        geometry_id = geometry.add_box(box_lo, box_hi, domain_lo, domain_hi);
        geometry.commit();
        camera = std::make_unique<Camera>(scene.camera, scene.image.width, scene.image.height, glm::max(box_lo, domain_lo),
                                          glm::min(box_hi, domain_hi));
        const std::size_t parts = std::size_t(scene.image.width) * std::size_t(scene.image.height) * kPart * sizeof(double);
        if (parts / sizeof(double) > std::size_t(std::numeric_limits<int>::max()))
            throw Error("image: " + std::to_string(scene.image.width) + " x " + std::to_string(scene.image.height) +
                        " is too large for volref-mpi (its messages hold at most 2^31 - 1 doubles: 8 per pixel)");
        // Direct send: rank 0 holds every rank's parts and its own; binary swap: a rank holds its parts
        // and half of them received; rank 0 also holds the image (up to 5 doubles a pixel).
        const std::size_t image_bytes = parts / kPart * 5;
        const std::size_t held = swap ? parts + parts / 2 + (rank == 0 ? image_bytes : 0)
                                      : parts * (rank == 0 ? std::size_t(size) + 1 : 1) + (rank == 0 ? image_bytes : 0);
        check_memory(prepared->bytes + held, "this rank's brick with the image parts (" + std::to_string(size) + " ranks, " +
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
    const VolumeSpec& vs = scene.volume();
    const mpi::Brick& brick = bricks[std::size_t(rank)];
    const SamplePipeline& pipeline = *prepared->pipeline;
    const double step = prepared->step, unit = pipeline.classifier().unit_distance();
    const bool first_hit = render.projection == Projection::FirstHit;
    // FirstHitIntegrator's exact search (Cartesian trilinear grids), on this rank's brick.
    const VolumeSampler* trilinear = pipeline.cartesian_sampler();
    if (trilinear && trilinear->interpolation() != Interpolation::Trilinear) trilinear = nullptr;
    std::vector<double> part(std::size_t(W) * std::size_t(H) * kPart, 0.0);
    // The brick's world box, padded: the segments worth testing (the test itself is exact).
    glm::dvec3 blo, bhi;
    for (int a = 0; a < 3; ++a) {
        blo[a] = origin[a] + double(brick.lo[a] > 0 ? brick.lo[a] : 0) * spacing[a];
        bhi[a] = origin[a] + double(brick.hi[a] < dims[a] - 1 ? brick.hi[a] : dims[a] - 1) * spacing[a];
        const double pad = 1e-6 * (std::fabs(blo[a]) + std::fabs(bhi[a]) + spacing[a]);
        blo[a] -= pad;
        bhi[a] += pad;
    }
    try {
        tbb::task_arena arena(args.threads > 0 ? args.threads : tbb::task_arena::automatic);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int>& rows) {
                std::vector<Interval> intervals;
                for (int y = rows.begin(); y != rows.end(); ++y)
                    for (int x = 0; x < W; ++x) {
                        const Ray ray = camera->pixel_ray(x, y);
                        Ray local = ray;
                        intervals.clear();
                        geometry.intervals(&ray, 1, geometry_id, &intervals);
                        if (vs.crop) crop_intervals(local, *vs.crop, intervals);
                        if (!vs.clip_planes.empty()) clip_intervals(ray, vs.clip_planes, intervals);
                        double* p = &part[(std::size_t(y) * std::size_t(W) + std::size_t(x)) * kPart];
                        p[0] = kNone;
                        Interval range;
                        if (intervals.empty() || !intersect_box(ray, blo, bhi, range)) continue;
                        // The owned segments, front to back (contiguous: the brick is convex).
                        std::vector<Segment> owned;
                        std::vector<std::array<std::int64_t, 3>> owned_at;  // first hit: interval, k, n
                        for (std::size_t i = 0; i < intervals.size(); ++i) {
                            const Interval& iv = intervals[i];
                            if (iv.t1 < range.t0 || iv.t0 > range.t1) continue;
                            const std::int64_t n = segment_count(iv, step);
                            std::int64_t k0 = std::int64_t(std::floor((range.t0 - iv.t0) / step)) - 1;
                            std::int64_t k1 = std::int64_t(std::ceil((range.t1 - iv.t0) / step)) + 1;
                            k0 = std::clamp<std::int64_t>(k0, 0, n - 1);
                            k1 = std::clamp<std::int64_t>(k1, 0, n - 1);
                            for (std::int64_t k = k0; k <= k1; ++k) {
                                const Segment s = segment(iv, step, k, n);
                                const glm::dvec3 u = (ray.at(s.midpoint()) - origin) / spacing;
                                if (!mpi::owns(brick, dims, u)) continue;
                                owned.push_back(s);
                                if (first_hit) owned_at.push_back({std::int64_t(i), k, n});
                            }
                        }
                        if (owned.empty()) continue;
                        p[0] = owned.front().midpoint();
                        switch (render.projection) {
                            case Projection::Composite: {
                                CompensatedSum tau;
                                bool opaque = false;
                                auto add = [&](auto& acc, const Segment& s) {
                                    const PipelineSample q = pipeline.sample(ray, s.midpoint(), SamplePipeline::Use::Composite);
                                    if (!(q.opacity > 0.0)) return;
                                    const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, q.opacity, s.length(), unit);
                                    const double c[3] = {q.color.r, q.color.g, q.color.b};
                                    acc.add(true, o.solid, o.tau, o.alpha, c);
                                    if (o.solid) opaque = true;
                                    else tau.add(o.tau);
                                };
                                if (render.order == CompositeOrder::FrontToBack) {
                                    FrontToBack<Scalar> acc;
                                    for (const Segment& s : owned) {
                                        add(acc, s);
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
                                break;
                            }
                            case Projection::FirstHit: {
                                // FirstHitIntegrator's search over this rank's segments (each one's
                                // ends read here: a segment's g(t0) is its predecessor's g(t1), the
                                // same t); the key is the hit segment's midpoint (ray order).
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
                                    if (hit) {
                                        p[0] = owned[m].midpoint();
                                        const glm::dvec3 c =
                                            pipeline.sample(ray, *hit, SamplePipeline::Use::Surface).color;
                                        for (int i = 0; i < 3; ++i) p[1 + i] = c[i];
                                        p[4] = 1.0;
                                        p[5] = *hit;
                                    }
                                }
                                break;
                            }
                            case Projection::Mip:
                            case Projection::Minip: {
                                Extremum<Scalar> acc(render.projection == Projection::Mip);
                                for (const Segment& s : owned) acc.add(true, pipeline.value(ray, s.midpoint()), s.midpoint());
                                if (!acc.any()) {
                                    p[0] = kNone;
                                    break;
                                }
                                p[0] = acc.where();
                                const PipelineSample q = pipeline.sample(ray, acc.where(), SamplePipeline::Use::Unshaded);
                                for (int i = 0; i < 3; ++i) p[1 + i] = q.opacity * q.color[i];
                                p[4] = q.opacity;
                                p[5] = acc.value();
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

    // One pixel from its parts in ray order (sorted by key; parts with no segment, key +inf, last):
    // out = R G B A (and Z for first hit).
    const int nc = first_hit ? 5 : 4;
    auto pixel_of = [&](const double* const* order, int count, double* out) {
        glm::dvec4 rgba(0.0);
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
            CompensatedSum integral, length;
            for (int r = 0; r < count; ++r) {
                const double* q = order[r];
                if (q[0] == kNone) break;
                hit = true;
                integral.add(q[6]);
                length.add(q[7]);
            }
            if (hit) {
                const double g = render.projection == Projection::Average ? integral.value() / length.value()
                                                                          : render.gain * integral.value();
                rgba = glm::dvec4(g, g, g, 1.0);
            }
        }
        for (int c = 0; c < 4; ++c) out[c] = rgba[c];
        if (first_hit) out[4] = depth;
    };

    std::vector<std::string> channels{"R", "G", "B", "A"};
    if (first_hit) channels.push_back("Z");  // as volref render writes it
    std::unique_ptr<Image> image;
    if (rank == 0) image = std::make_unique<Image>(W, H, channels);
    const std::size_t pixels = std::size_t(W) * std::size_t(H);
    std::size_t bytes_sent = 0, bytes_received = 0;  // by this rank, this frame
    double t_gather = 0.0;  // rank 0: the parts (direct) or the finished pixels (swap) are in
    if (!swap) {
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
            for (std::size_t px = 0; px < pixels; ++px) {
                for (int r = 0; r < size; ++r) order[std::size_t(r)] = &all[std::size_t(r) * stride + px * kPart];
                // Ray order: the key, then the rank (ties of the extremum: the first sample wins).
                std::stable_sort(order.begin(), order.end(), [](const double* a, const double* b) { return a[0] < b[0]; });
                pixel_of(order.data(), size, &image->pixels[px * std::size_t(nc)]);
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
            } else if (!first_hit) {  // average, xray: the sums add
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
            incoming.resize((keep_hi - keep_lo) * kPart);
            MPI_Sendrecv(&part[send_lo * kPart], int((send_hi - send_lo) * kPart), MPI_DOUBLE, partner, bit,
                         incoming.data(), int(incoming.size()), MPI_DOUBLE, partner, bit, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            bytes_sent += (send_hi - send_lo) * kPart * sizeof(double);
            bytes_received += incoming.size() * sizeof(double);
            for (std::size_t px = keep_lo; px < keep_hi; ++px)
                merge(&part[px * kPart], &incoming[(px - keep_lo) * kPart], upper);
            lo = keep_lo;
            hi = keep_hi;
        }
        std::vector<double> finished((hi - lo) * std::size_t(nc));
        for (std::size_t px = lo; px < hi; ++px) {
            const double* q = &part[px * kPart];
            pixel_of(&q, 1, &finished[(px - lo) * std::size_t(nc)]);
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
                         size, swap ? "swap" : "direct", slowest[0], slowest[1], t_gather - t_ready, t_write - t_gather,
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
