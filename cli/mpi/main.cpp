// volref-mpi render SCENE -o OUT [--threads T] [--max-memory M] [--set PATH=VALUE ...] [--balance auto|cells|work]
//
// Space split into bricks over the MPI ranks (cli/mpi/Bricks.h: a k-d split of the first volume's
// lattice, extended over every volume); each rank holds its brick of every volume plus a ghost layer
// (read as a sub-box of the file, or generated) and builds `volref render`'s PreparedScene (pipelines,
// integrators, camera, mix) on them. A rank owns the span of every ray inside its brick (Bricks.h
// owned_span: the samples whose position lies in the brick) and integrates it through the integrator's
// resumable march (Integrator::integrate_span, core/integrate/march/RaySpan.h: the single-process
// sample lattice, SIMD packets, empty-space skipping); the parts are merged in ray order
// (Compositing.h: binary swap or direct send), or, where a span depends on what lies in front (early
// termination, the adaptive composite), the states are handed from rank to rank (Chain.h). Errors of
// any rank reach rank 0, which prints the one line `volref render` prints (the lowest rank's); every
// rank exits 1; no file is written. docs/conventions.md §14, docs/architecture.md "volref-mpi",
// docs/performance.md.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <tbb/task_arena.h>

#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/grid/ProceduralField.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "cli/mpi/Balance.h"
#include "cli/mpi/Chain.h"
#include "cli/mpi/Compositing.h"
#include "cli/mpi/Frame.h"
#include "cli/mpi/ImageOutput.h"

namespace {

using namespace volref;
using namespace volref::mpi;

// What volref-mpi does not render yet (docs/conventions.md §14): one-line errors naming the key.
void check_supported(const Scene& scene) {
    const RenderSpec& r = scene.render;
    if (!r.reference_integrators() && !(r.profile == ProfileId::Fast && r.profile_rules.empty()))
        throw Error("render.profile: volref-mpi supports \"reference\" and \"fast\" only (mirror profiles are not supported yet)");
    // Each rank would build its table over its own brick's values, so ranks would read different tables.
    if (r.profile_options.preintegration > 0)
        throw Error("render.profile_options.preintegration: volref-mpi does not render pre-integrated segments yet");
    for (std::size_t k = 0; k < scene.volumes.size(); ++k) {
        const VolumeSpec& vs = scene.volumes[k];
        const std::string key = volume_key(scene, k);
        if (vs.bounds.type != BoundsSpec::Type::Box && vs.bounds.type != BoundsSpec::Type::Mesh &&
            vs.bounds.type != BoundsSpec::Type::Tetrahedra)
            throw Error(key + ".bounds: volref-mpi supports box, mesh and tetrahedra bounds only (shells are not supported yet)");
        // "auto" decides from the whole volume's voxels (resolve_gradient_cache), which no rank holds.
        if (vs.gradient.cache_auto)
            throw Error(key + ".gradient.cache: \"auto\" is not supported by volref-mpi yet (say true or false)");
    }
}

struct Args {
    std::string scene, output, max_memory, compositing = "swap";
    std::string balance = "auto";  // auto: work for the chain, cells otherwise (conventions §14)
    int threads = 0;
    std::vector<std::string> overrides;
    bool timing = false, compositing_given = false;
};

double now() { return MPI_Wtime(); }

// Runs f, turning an exception into its message (reported on every rank by any_error).
template <class F>
std::string guarded(F&& f) {
    try {
        f();
    } catch (const std::bad_alloc&) {
        return "out of memory";
    } catch (const std::exception& e) {
        return e.what();
    }
    return {};
}

// Set-up, first half: the scene, every volume's grid, the lattice and its bricks, and this rank's
// brick of every volume (read as a sub-box of its file, or generated).
void read_bricks(const Args& args, Frame& f, const std::vector<Brick>* bricks) {
    if (!args.max_memory.empty()) set_memory_limit(parse_memory_size(args.max_memory, "--max-memory"));
    if (f.rank == 0) check_output(args.output);
    f.scene = load_scene(args.scene, args.overrides);
    check_supported(f.scene);
    f.members.resize(f.scene.volumes.size());
    std::vector<GridBox> grids;
    for (std::size_t k = 0; k < f.members.size(); ++k) {
        const VolumeSpec& vs = f.scene.volumes[k];
        Member& m = f.members[k];
        if (vs.transform) m.transform.emplace(*vs.transform);
        const VolumeTransform* to_world = m.transform ? &*m.transform : nullptr;  // (members is not resized again)
        if (vs.source.field) {
            m.grid = {vs.source.field->dims, vs.origin.value_or(glm::dvec3(0.0)), vs.spacing.value_or(glm::dvec3(1.0)), to_world};
        } else {
            m.header = read_volume_header(*vs.source.file, vs.source.format);
            m.header.origin = vs.origin.value_or(m.header.origin);
            m.header.spacing = vs.spacing.value_or(m.header.spacing);
            m.grid = {m.header.dims, m.header.origin, m.header.spacing, to_world};
        }
        m.ghost = ghost_voxels(vs, f.scene.render);
        if (f.first_hit()) {
            // The sign test reads both ends of an owned segment (its midpoint +- h / 2) and the search
            // runs between them: the ghost layer reaches h / 2 further (h in voxels of the finest axis).
            const glm::dvec3& sp = m.grid.spacing;
            const double finest = std::min({sp.x, sp.y, sp.z});
            const double h = f.scene.render.step_units == StepUnits::World ? f.scene.render.step / finest : f.scene.render.step;
            if (!(h > 0.0) || !(h < 1e6)) throw Error("render.step: too large for volref-mpi's ghost layer");
            m.ghost += int(std::ceil(0.5 * h));
        }
        grids.push_back(m.grid);
    }
    f.lattice = union_lattice(grids);
    f.bricks = bricks ? *bricks : split_lattice(f.lattice, f.size);
    std::size_t held = 0;  // the bricks read before this one (--max-memory counts them all)
    for (std::size_t k = 0; k < f.members.size(); ++k) {
        const VolumeSpec& vs = f.scene.volumes[k];
        Member& m = f.members[k];
        voxels_for(f.bricks[std::size_t(f.rank)], f.lattice, grids[0], m.grid, m.ghost, m.vlo, m.vhi);
        const std::array<std::int64_t, 3> n{m.vhi[0] - m.vlo[0] + 1, m.vhi[1] - m.vlo[1] + 1, m.vhi[2] - m.vlo[2] + 1};
        const HeldMemory earlier(held);
        if (vs.source.field) m.brick = make_procedural_brick(*vs.source.field, m.grid.origin, m.grid.spacing, m.vlo, n);
        else m.brick = read_brick(m.header, m.vlo, n);
        held += m.brick.values.bytes();
    }
}

// Set-up, second half: `volref render`'s PreparedScene on this rank's bricks (the whole volume's data
// range agreed first: Volume::whole_range; each volume bounded by its whole domain: WholeDomain), and
// the memory the image's parts will take.
void prepare(const Args& args, Frame& f, bool swap) {
    for (Member& m : f.members) {
        const auto r = m.brick.value_range();
        double lo = r[0], hi = r[1], glo = 0.0, ghi = 0.0;
        MPI_Allreduce(&lo, &glo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
        MPI_Allreduce(&hi, &ghi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        m.brick.whole_range = std::array<double, 2>{glo, ghi};
    }
    // The bricks in memory (VolumeSourceSpec::memory): complete, with their own origin (the lower
    // corner, ghosts included) and the volume's spacing; the scene's file then only names them. The
    // rays are bounded, and the default camera frames, by the whole volumes' domains.
    std::vector<WholeDomain> whole;
    for (std::size_t k = 0; k < f.members.size(); ++k) {
        Member& m = f.members[k];
        f.scene.volumes[k].source.memory = std::make_shared<const Volume>(std::move(m.brick));
        const glm::dvec3 last(double(m.grid.dims[0] - 1), double(m.grid.dims[1] - 1), double(m.grid.dims[2] - 1));
        whole.push_back({m.grid.origin, m.grid.origin + last * m.grid.spacing});
    }
    RenderOptions options;
    options.threads = args.threads;
    f.prepared = std::make_unique<PreparedScene>(f.scene, options, whole);
    std::size_t held = 0;
    for (const auto& v : f.prepared->volumes) {
        held += v->bytes;
        if (!v->integrator->resumable() && !(f.adaptive() && is_composite(f.scene.render.projection)))
            throw Error("render: volref-mpi cannot integrate this projection or integrator in parts yet");
    }
    // The brick's box in the first volume's space, padded: the rays worth a span (the span is exact).
    const Brick& brick = f.bricks[std::size_t(f.rank)];
    const GridBox& g = f.members[0].grid;
    for (int a = 0; a < 3; ++a) {
        f.brick_lo[a] = g.origin[a] + double(brick.lo[a]) * g.spacing[a];
        f.brick_hi[a] = g.origin[a] + double(brick.hi[a]) * g.spacing[a];
        const double pad = 1e-6 * (std::fabs(f.brick_lo[a]) + std::fabs(f.brick_hi[a]) + g.spacing[a]);
        f.brick_lo[a] -= pad;
        f.brick_hi[a] += pad;
    }
    const std::size_t parts = f.pixels() * f.slots() * kPart * sizeof(double);
    if (parts / sizeof(double) > std::size_t(std::numeric_limits<int>::max()))
        throw Error("image: " + std::to_string(f.width()) + " x " + std::to_string(f.height()) +
                    " is too large for volref-mpi (its messages hold at most 2^31 - 1 doubles: " +
                    std::to_string(f.slots() * kPart) + " per pixel)");
    // Chained: the chain's arrays (Chain.h chain_bytes). Direct send: rank 0 holds every rank's parts
    // and its own; binary swap: a rank holds its parts and half of them received; rank 0 also holds the image.
    const std::size_t image_bytes = f.pixels() * std::size_t(f.channels()) * sizeof(double);
    const std::size_t mine = f.rank == 0 ? image_bytes : 0;
    const std::string ranks = std::to_string(f.size) + " ranks";
    if (chained(f))
        check_memory(held + chain_bytes(f), "this rank's bricks with the chain's states (" + ranks + ")");
    else if (swap)
        check_memory(held + parts + parts / 2 + mine, "this rank's bricks with the image parts (" + ranks + ", binary swap)");
    else
        check_memory(held + parts * (f.rank == 0 ? std::size_t(f.size) + 1 : 1) + mine,
                     "this rank's bricks with the image parts (" + ranks + ", direct send)");
}

// This rank's parts before it integrates: every key kNone (no span), every state zero. Made at set-up,
// as `volref render` makes its image before it times a frame (Renderer.cpp), so that render_s is the
// integration and not the buffer's first touch (PartBuffer.h: 1.5 to 17 ms on huge pages).
PartBuffer fresh_parts(const Frame& f) {
    PartBuffer part(f.pixels() * f.slots() * kPart, 0.0);
    for (std::size_t i = 0; i < f.pixels() * f.slots(); ++i) part[i * kPart] = kNone;
    return part;
}

// This rank's part of every pixel (Frame::slots() parts of kPart doubles, `part` from fresh_parts): the key
// of its span and the state its span gives from a fresh one (the slot's integrator, in SIMD packets where
// the volume allows; several volumes: the mix, or each volume's own integrator).
void integrate_parts(const Frame& f, PartBuffer& part) {
    const std::size_t V = f.volumes(), slots = f.slots(), W = std::size_t(f.width());
    const PreparedVolume& first = f.volume(0);
    auto store = [&](std::size_t px, std::size_t slot, double key, const RayState& st) {
        double* p = &part[(px * slots + slot) * kPart];
        p[0] = key;
        st.write(p + 1);
    };
    // Several volumes: one pixel at a time (the mix, or each volume's own integrator).
    auto one_pixel = [&](int x, int y, std::vector<Ray>& rays, std::vector<std::vector<Interval>>& intervals) {
        const std::size_t px = std::size_t(y) * W + std::size_t(x);
        f.pixel_intervals(x, y, rays.data(), intervals.data());
        const RaySpan span = f.span(rays[0]);
        if (!(span.t0 < span.t1)) return;
        RayState st;
        if (f.mixed()) {
            f.multi().composite_span(rays.data(), intervals.data(), span, st);
            return store(px, 0, span.t0, st);
        }
        for (std::size_t k = 0; k < V; ++k) {
            if (intervals[k].empty()) continue;
            st = RayState{};
            f.volume(k).integrator->integrate_span(rays[k], intervals[k], span, st);
            store(px, k, span.t0, st);
        }
    };
    static_assert(kPixelBlockPixels <= kMaxPacketRays);
    // `volref render`'s order (PixelBlocks.h): tiles of tile_side() pixels, one task each, of blocks of
    // pixels (the packets of one call to the integrator). The tiles keep neighbouring rays' voxels in
    // cache: rows of blocks across the image made one rank's frame 1.37x `volref render`'s on a 256^3
    // volume (64 MiB).
    tbb::task_arena arena(f.threads > 0 ? f.threads : tbb::task_arena::automatic);
    const TileGrid tiles(f.width(), f.height(), tile_side(f.width(), f.height(), arena.max_concurrency()));
    arena.execute([&] {
        parallel_for_tiles(tiles, [&](const PixelRect& tile) {
            Ray world[kMaxPacketRays], rays[kMaxPacketRays];
            std::vector<Interval> intervals[kMaxPacketRays];
            RaySpan spans[kMaxPacketRays];
            RayState states[kMaxPacketRays];
            std::size_t at[kMaxPacketRays];
            std::vector<Ray> vrays(V);
            std::vector<std::vector<Interval>> vintervals(V);
            for_each_block(tile, [&](const PixelBlock& b) {
                if (V > 1) {
                    for (int i = 0; i < b.count; ++i) one_pixel(b.x[i], b.y[i], vrays, vintervals);
                    return;
                }
                const int n = b.count;
                for (int i = 0; i < n; ++i) {
                    world[i] = f.camera().pixel_ray(b.x[i], b.y[i]);
                    at[i] = std::size_t(b.y[i]) * W + std::size_t(b.x[i]);
                }
                if (!f.meets_brick(world, n)) return;
                const int count = f.owned_rays(world, n, rays, intervals, spans, at, [](std::size_t) { return false; });
                if (count == 0) return;
                std::fill(states, states + count, RayState{});
                if (first.packets) first.integrator->integrate_span_packet(rays, intervals, spans, states, count);
                else
                    for (int i = 0; i < count; ++i) first.integrator->integrate_span(rays[i], intervals[i], spans[i], states[i]);
                for (int i = 0; i < count; ++i) store(at[i], 0, spans[i].t0, states[i]);
            });
        });
    });
}

void print_timing(const Frame& f, bool chain, bool swap, const char* bricks, const double (&mine)[2], double gather_s,
                  double write_s, const Traffic& traffic) {
    double slowest[2] = {0.0, 0.0};
    MPI_Reduce(mine, slowest, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    unsigned long long sent = traffic.sent, most = 0;
    MPI_Reduce(&sent, &most, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, 0, MPI_COMM_WORLD);
    // Each rank's own integration time (rank order): how even the bricks' cut was.
    std::vector<double> each(f.rank == 0 ? std::size_t(f.size) : 1);
    MPI_Gather(&mine[1], 1, MPI_DOUBLE, each.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (f.rank != 0) return;
    std::string ranks_s;
    for (double t : each) {
        char one[32];
        std::snprintf(one, sizeof one, "%s%.4f", ranks_s.empty() ? "" : ", ", t);
        ranks_s += one;
    }
    std::fprintf(stderr,
                 "volref: timing {\"ranks\": %d, \"compositing\": \"%s\", \"bricks\": \"%s\", \"setup_s\": %.4f, \"render_s\": %.4f, "
                 "\"render_s_ranks\": [%s], \"gather_s\": %.4f, \"combine_write_s\": %.4f, \"bytes_sent_per_rank\": %llu, "
                 "\"bytes_received_rank0\": %llu, \"image_bytes\": %zu}\n",
                 f.size, chain ? "chain" : swap ? "swap" : "direct", bricks, slowest[0], slowest[1], ranks_s.c_str(), gather_s, write_s,
                 most, (unsigned long long)traffic.received, f.pixels() * std::size_t(f.channels()) * sizeof(double));
}

int run(const Args& args, int rank, int size) {
    // Binary swap needs a power-of-two rank count; others use direct send (said on stderr after a
    // successful render when --compositing swap was asked for).
    const bool power_of_two = (size & (size - 1)) == 0;
    const bool swap = args.compositing == "swap" && power_of_two && size > 1;
    const double t_start = now();
    auto fresh = [&] {
        auto f = std::make_unique<Frame>();
        f->rank = rank;
        f->size = size;
        f->threads = args.threads;
        return f;
    };
    std::unique_ptr<Frame> frame = fresh();
    if (any_error(guarded([&] { read_bricks(args, *frame, nullptr); }), rank, size)) return 1;
    if (any_error(guarded([&] { prepare(args, *frame, swap); }), rank, size)) return 1;
    const char* bricks = "cells";  // how the bricks were cut (--timing): cells, work (cut again), work-same-cut
    const bool by_work = args.balance == "work" || (args.balance == "auto" && chained(*frame));
    if (by_work && size > 1) {  // the bricks again, cut where the work balances
        WorkBins work;
        if (any_error(guarded([&] { work = count_work(*frame); }), rank, size)) return 1;
        const std::vector<Brick> balanced = balanced_bricks(*frame, std::move(work));
        bricks = "work-same-cut";
        if (balanced != frame->bricks) {
            bricks = "work";
            frame.reset();  // (its bricks' memory first)
            frame = fresh();
            if (any_error(guarded([&] { read_bricks(args, *frame, &balanced); }), rank, size)) return 1;
            if (any_error(guarded([&] { prepare(args, *frame, swap); }), rank, size)) return 1;
        }
    }
    Frame& f = *frame;
    const bool chain = chained(f);
    PartBuffer part;
    ChainBuffers chained_buffers;  // (its pixels: the image on rank 0)
    if (any_error(guarded([&] { chain ? void(chained_buffers = fresh_chain(f)) : void(part = fresh_parts(f)); }), rank, size)) return 1;

    const double t_setup = now();
    Traffic traffic;
    double t_own = 0.0;  // when this rank's own integration ended (before any_error's all-reduce)
    if (chain) {
        if (!chained_pixels(f, chained_buffers, traffic.sent)) return 1;
        t_own = now();
    } else if (any_error(guarded([&] { integrate_parts(f, part), t_own = now(); }), rank, size)) {
        return 1;
    }
    MPI_Barrier(MPI_COMM_WORLD);  // (timing: the compositing below starts when the slowest rank is done)
    const double t_ready = now();

    std::vector<std::string> channels{"R", "G", "B", "A"};
    if (f.first_hit()) channels.push_back("Z");  // as volref render writes it
    if (f.adaptive()) channels.push_back("error");  // the adaptive integrator's estimate, as volref render writes it
    std::unique_ptr<Image> image;
    if (rank == 0) image = std::make_unique<Image>(f.width(), f.height(), channels);
    double* pixels = rank == 0 ? image->pixels.data() : nullptr;
    if (chain) {
        if (rank == 0) std::copy(chained_buffers.pixels.begin(), chained_buffers.pixels.end(), pixels);
    } else if (swap) {
        binary_swap(f, part, pixels, traffic);
    } else {
        direct_send(f, part, pixels, traffic);
    }
    const double t_gather = now();
    std::string err;
    if (rank == 0)
        err = guarded([&] { write_output(*image, args.output, f.scene.image.background); });
    const double t_write = now();
    if (any_error(err, rank, size)) return 1;
    if (args.timing)
        print_timing(f, chain, swap, bricks, {t_setup - t_start, t_own - t_setup}, t_gather - t_ready, t_write - t_gather, traffic);
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
    rc->add_option("--balance", args.balance,
                   "Where the bricks are cut: cells (equal cell counts), work (the samples counted on every 4th "
                   "pixel's rays balance; the bricks are read twice) or auto (work where the ranks chain "
                   "each pixel's state, cells otherwise)")
        ->check(CLI::IsMember({"auto", "work", "cells"}))
        ->capture_default_str();
    rc->add_flag("--timing", args.timing,
                 "Print one line on stderr (rank 0): volref: timing {ranks, compositing, bricks (cells, work, work-same-cut), setup_s, render_s (the slowest "
                 "rank's), render_s_ranks (each rank's), gather_s, combine_write_s, bytes_sent_per_rank (the most any rank sent), bytes_received_rank0, "
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
