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
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/camera/Camera.h"
#include "core/film/ImageWriter.h"
#include "core/grid/ProceduralField.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/render/PreparedVolume.h"
#include "core/render/VolumeLoaderHook.h"
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
    if (r.projection == Projection::FirstHit) throw Error("render.projection: \"first-hit\" is not supported by volref-mpi yet");
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
};

double now() { return MPI_Wtime(); }

int run(const Args& args, int rank, int size) {
    std::string err;
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
        mpi::VolumeHeader header;
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
        bricks = mpi::split_bricks(dims, size, mpi::ghost_voxels(vs, scene.render));
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
        // The default window of a float volume is the whole volume's data range (TransferFunction.cpp):
        // the ranks agree on it first.
        if (!vs.classification && !vs.transfer.window && !scalar_type_is_integer(brick_volume.type)) {
            const auto r = brick_volume.value_range();
            double lo = r[0], hi = r[1], glo = 0.0, ghi = 0.0;
            MPI_Allreduce(&lo, &glo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
            MPI_Allreduce(&hi, &ghi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            vs.transfer.window = std::array<double, 2>{glo, ghi};
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
        check_memory(prepared->bytes + parts * (rank == 0 ? std::size_t(size) + 1 : 1),
                     "this rank's brick with the image parts (" + std::to_string(size) + " ranks)");
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
                        for (const Interval& iv : intervals) {
                            if (iv.t1 < range.t0 || iv.t0 > range.t1) continue;
                            const std::int64_t n = segment_count(iv, step);
                            std::int64_t k0 = std::int64_t(std::floor((range.t0 - iv.t0) / step)) - 1;
                            std::int64_t k1 = std::int64_t(std::ceil((range.t1 - iv.t0) / step)) + 1;
                            k0 = std::clamp<std::int64_t>(k0, 0, n - 1);
                            k1 = std::clamp<std::int64_t>(k1, 0, n - 1);
                            for (std::int64_t k = k0; k <= k1; ++k) {
                                const Segment s = segment(iv, step, k, n);
                                const glm::dvec3 u = (ray.at(s.midpoint()) - origin) / spacing;
                                if (mpi::owns(brick, dims, u)) owned.push_back(s);
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
    MPI_Barrier(MPI_COMM_WORLD);  // (timing: the gather below starts when the slowest rank is done)
    const double t_ready = now();
    // ---- rank 0: the parts in ray order ----
    std::vector<double> all;
    if (rank == 0) all.resize(part.size() * std::size_t(size));
    MPI_Gather(part.data(), int(part.size()), MPI_DOUBLE, all.data(), int(part.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    const double t_gather = now();
    if (rank == 0) {
        try {
            Image image(W, H, {"R", "G", "B", "A"});
            const std::size_t stride = part.size();
            std::vector<const double*> order(static_cast<std::size_t>(size));
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    const std::size_t at = (std::size_t(y) * std::size_t(W) + std::size_t(x)) * kPart;
                    for (int r = 0; r < size; ++r) order[std::size_t(r)] = &all[std::size_t(r) * stride + at];
                    // Ray order: the key, then the rank (ties of the extremum: the first sample wins).
                    std::stable_sort(order.begin(), order.end(), [](const double* a, const double* b) { return a[0] < b[0]; });
                    glm::dvec4 rgba(0.0);
                    if (render.projection == Projection::Composite) {
                        CompensatedSum tau;
                        bool opaque = false;
                        glm::dvec3 c(0.0);
                        for (const double* q : order) {
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
                        for (const double* q : order) {
                            if (q[0] == kNone) break;
                            if (!best || (maximum ? q[5] > best[5] : q[5] < best[5])) best = q;
                        }
                        if (best) rgba = glm::dvec4(best[1], best[2], best[3], best[4]);
                    } else {
                        bool hit = false;
                        CompensatedSum integral, length;
                        for (int r = 0; r < size; ++r) {  // rank order: any fixed order
                            const double* q = &all[std::size_t(r) * stride + at];
                            if (q[0] == kNone) continue;
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
                    for (int c = 0; c < 4; ++c) image.at(x, y, std::size_t(c)) = rgba[c];
                }
            if (dump_output(args.output)) write_dump(image, args.output);
            else write_image(image, args.output, scene.image.background);
        } catch (const std::exception& e) {
            err = e.what();
        }
    }
    const double t_write = now();
    if (any_error(err, rank, size)) return 1;
    if (args.timing) {  // the slowest rank's set-up and render; rank 0's gather and combine + write
        double mine[2] = {t_setup - t_start, t_render - t_setup}, slowest[2] = {0.0, 0.0};
        MPI_Reduce(mine, slowest, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        if (rank == 0)
            std::fprintf(stderr,
                         "volref: timing {\"ranks\": %d, \"setup_s\": %.4f, \"render_s\": %.4f, \"gather_s\": %.4f, "
                         "\"combine_write_s\": %.4f, \"bytes_sent_per_rank\": %zu, \"bytes_received_rank0\": %zu}\n",
                         size, slowest[0], slowest[1], t_gather - t_ready, t_write - t_gather, part.size() * sizeof(double),
                         part.size() * sizeof(double) * std::size_t(size - 1));
    }
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
    rc->add_flag("--timing", args.timing,
                 "Print one line on stderr (rank 0): volref: timing {ranks, setup_s, render_s (the slowest rank's), "
                 "gather_s, combine_write_s, bytes_sent_per_rank, bytes_received_rank0}");
    int status = 0;
    try {
        app.parse(argc, argv);
        status = run(args, rank, size);
    } catch (const CLI::ParseError& e) {
        status = rank == 0 ? (app.exit(e) == 0 ? 0 : 2) : (e.get_exit_code() == 0 ? 0 : 2);
    }
    MPI_Finalize();
    return status;
}
