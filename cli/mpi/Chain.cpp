#include "cli/mpi/Chain.h"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <new>
#include <optional>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/integrate/adaptive/AdaptiveIntegrator.h"
#include "core/integrate/march/SpanStates.h"
#include "core/render/PixelBlocks.h"

namespace volref::mpi {

namespace {

// The adaptive chain's error sums handed back to front per pixel: behind R G B, colour_err, tau_err.
constexpr std::size_t kErrorSums = 5;

// Each pixel's ranks in ray order (by their spans' keys, then rank): this rank's place among them
// (-1: none), how many there are, and the ranks just in front of and behind this one (-1: none).
struct RankOrder {
    std::vector<int> position, count, front, behind;
};
RankOrder rank_order(const Frame& frame, const std::vector<double>& key) {
    const std::size_t P = frame.pixels();
    std::vector<double> keys(P * std::size_t(frame.size));
    MPI_Allgather(key.data(), int(P), MPI_DOUBLE, keys.data(), int(P), MPI_DOUBLE, MPI_COMM_WORLD);
    RankOrder o{std::vector<int>(P, -1), std::vector<int>(P, 0), std::vector<int>(P, -1), std::vector<int>(P, -1)};
    for (std::size_t px = 0; px < P; ++px) {
        const double mine = key[px];
        double front_key = -kNone, behind_key = kNone;
        for (int r = 0; r < frame.size; ++r) {
            const double k = keys[std::size_t(r) * P + px];
            if (k == kNone) continue;
            ++o.count[px];
            if (mine == kNone || r == frame.rank) continue;
            const bool in_front = k < mine || (k == mine && r < frame.rank);
            if (in_front) {
                ++o.position[px];
                if (k > front_key || (k == front_key && r > o.front[px])) front_key = k, o.front[px] = r;
            } else if (k < behind_key || (k == behind_key && r < o.behind[px])) {
                behind_key = k, o.behind[px] = r;
            }
        }
        if (mine != kNone) ++o.position[px];  // from -1: the ranks in front of this one
    }
    return o;
}

// Pixel px's rays and intervals in every volume, for the steps that sample (scratch of one thread).
struct PixelRays {
    std::vector<Ray> rays;
    std::vector<std::vector<Interval>> intervals;
    explicit PixelRays(std::size_t volumes) : rays(volumes), intervals(volumes) {}
    void of(const Frame& frame, std::size_t px) {
        const std::size_t W = std::size_t(frame.width());
        frame.pixel_intervals(int(px % W), int(px / W), rays.data(), intervals.data());
    }
};

// f(px, scratch) for the pixels `list` (all of them when null), on the frame's threads; run() returns the
// error message of an exception (empty: none). The arena is made once (per loop, not per call), and
// with one thread the loop runs inline: an arena made per chunk of the chain below cost a rank 0.2 s
// of its 0.8 s (2 ranks, one thread each, the adaptive scene of docs/performance.md).
class PixelLoop {
public:
    explicit PixelLoop(const Frame& frame) : frame_(frame) {
        // (The count as a value first: emplace's forwarding reference would odr-use TBB's constant.)
        const int threads = frame.threads > 0 ? frame.threads : int(tbb::task_arena::automatic);
        if (threads != 1) arena_.emplace(threads);
    }
    template <class F>
    std::string run(const std::vector<std::size_t>* list, F&& f) {
        const std::size_t n = list ? list->size() : frame_.pixels();
        auto range = [&](std::size_t i0, std::size_t i1) {
            PixelRays scratch(frame_.volumes());
            for (std::size_t i = i0; i != i1; ++i) f(list ? (*list)[i] : i, scratch);
        };
        try {
            if (!arena_) {
                range(0, n);
            } else {
                arena_->execute([&] {
                    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n),
                                      [&](const tbb::blocked_range<std::size_t>& r) { range(r.begin(), r.end()); });
                });
            }
        } catch (const std::bad_alloc&) {
            return "out of memory";
        } catch (const std::exception& e) {
            return e.what();
        }
        return {};
    }
    // f(pixels, n, scratch) on the list cut into fixed batches of `batch` pixels (the last one shorter),
    // the batches spread over the threads: a batch's pixels never depend on the thread count.
    template <class F>
    std::string run_batches(const std::vector<std::size_t>& list, std::size_t batch, F&& f) {
        const std::size_t batches = (list.size() + batch - 1) / batch;
        std::vector<std::size_t> first(batches);
        for (std::size_t b = 0; b < batches; ++b) first[b] = b * batch;
        return run(&first, [&](std::size_t i, PixelRays& scratch) { f(&list[i], std::min(batch, list.size() - i), scratch); });
    }
    // The threads the loop runs on.
    int concurrency() const { return arena_ ? arena_->max_concurrency() : 1; }

private:
    const Frame& frame_;
    std::optional<tbb::task_arena> arena_;
};

// Pixels per block of the pipeline below. A block's states (up to 256 x 15 doubles, 30 KiB) go on as
// one message; a message above OpenMPI's eager limit (4 KiB on shared memory) moves only while both
// its sender and its receiver are inside MPI (a handshake, then the data), so every rank drives MPI's
// progress between chunks of 32 pixels a thread, and posts its receives before it starts (measured at
// 2 ranks on the adaptive scene: the rank behind waited 0.52 s of a 1.5 s chain for states its front
// rank had finished; with the sender's progress 0.11 s, a handshake per block; see performance.md).
// A block is a tile of kChainTile x kChainTile pixels (fewer at the image's edges), its pixels in
// `volref render`'s order (PixelBlocks.h for_each_block: kPixelBlockWidth x kPixelBlockHeight blocks in
// row order, row order inside each), so that a batch of kMaxPacketRays of them (fixed_chain) makes the
// render's packets (4 x 4 on 16 float lanes) and not rows of 16 x 1: with blocks of 256 pixels in rows
// the fast profile's chained frame was 1.15x slower at one rank (docs/performance.md, "volref-mpi on
// the resumable march").
constexpr int kChainTile = 16;
constexpr std::size_t kChainBlock = std::size_t(kChainTile) * kChainTile;
static_assert(kChainTile % kPixelBlockWidth == 0 && kChainTile % kPixelBlockHeight == 0);
// The chain's blocks (its tiles, in row order) in the order every rank takes them, each block's pixels
// in order.
std::vector<std::vector<std::size_t>> chain_blocks(const Frame& frame) {
    const TileGrid tiles(frame.width(), frame.height(), kChainTile);
    std::vector<std::vector<std::size_t>> blocks(std::size_t(tiles.count()));
    for (int t = 0; t < tiles.count(); ++t)
        for_each_block(tiles.tile(t), [&](const PixelBlock& b) {
            for (int i = 0; i < b.count; ++i)
                blocks[std::size_t(t)].push_back(std::size_t(b.y[i]) * std::size_t(frame.width()) + std::size_t(b.x[i]));
        });
    return blocks;
}
// Pixels a thread between two of MPI's progress calls (about 2 ms of the adaptive scene's work).
constexpr std::size_t kChainChunkPerThread = 32;
// The posted receives each progress call tests (the next ones a rank will wait for; any test drives
// every transfer, the window only bounds the call's cost on a frame of many blocks).
constexpr std::size_t kChainReceiveWindow = 8;

// This rank's units (round j, block b) in the order every rank takes them, each with its pixels (in the
// block's order); `reverse`: the rounds counted from each pixel's last rank.
struct ChainUnit {
    int j;
    std::vector<std::size_t> pixels;
};
std::vector<ChainUnit> chain_units(const Frame& frame, const RankOrder& order, bool reverse) {
    auto round_of = [&](std::size_t px) { return reverse ? order.count[px] - 1 - order.position[px] : order.position[px]; };
    std::vector<ChainUnit> units;
    const std::vector<std::vector<std::size_t>> blocks = chain_blocks(frame);
    for (int j = 0; j < frame.size; ++j)
        for (const std::vector<std::size_t>& block : blocks) {
            ChainUnit u{j, {}};
            for (std::size_t px : block)
                if (order.position[px] >= 0 && round_of(px) == j) u.pixels.push_back(px);
            if (!u.pixels.empty()) units.push_back(std::move(u));
        }
    return units;
}

// The state (S doubles a pixel) handed from rank to rank point to point: the image in blocks of
// kChainBlock pixels; in round j (front to back, or from the last rank with `reverse`), block b, a rank
// takes its round-j pixels' states from the ranks in front of it (receives posted at the start, in the
// order they are sent, waited for here), runs step(px, scratch, state) on them (or step(pixels, n,
// scratch) on fixed batches of up to kMaxPacketRays of them, which reads and writes `state` itself), and sends them on to
// the ranks behind (non-blocking). Every rank goes through the units (j, b) in the same order and a unit only waits for
// (j - 1, b), which its sender did earlier in that order: no deadlock, and a rank waits only where it
// overtakes the rank in front of it on the same block (no barrier per round, no image-wide reduction).
// On return each pixel's state is final on its last rank. An error aborts every rank (MPI_Abort: the
// ranks behind would wait for its states).
template <class Step>
void hand_on(const Frame& frame, const RankOrder& order, std::size_t S, PartBuffer& state, bool reverse,
             std::size_t& bytes, Step&& step) {
    const std::vector<int>& from = reverse ? order.behind : order.front;
    const std::vector<int>& to = reverse ? order.front : order.behind;
    const std::vector<ChainUnit> units = chain_units(frame, order, reverse);
    // In: every receive posted at once, unit by unit, from each rank in front (its pixels in pixel
    // order, as it sends them; a sender's messages to one rank match the receives in the order posted),
    // so that a state's handshake goes on while this rank computes and its data is there when needed.
    struct Inbox {
        std::size_t unit;
        int from;
        std::vector<double> states;
    };
    std::vector<Inbox> inbox;
    std::vector<MPI_Request> receives;
    for (std::size_t u = 0; u < units.size(); ++u)
        for (int r = 0; r < frame.size && units[u].j > 0; ++r) {
            std::size_t n = 0;
            for (std::size_t px : units[u].pixels) n += from[px] == r ? 1 : 0;
            if (n > 0) inbox.push_back({u, r, std::vector<double>(n * S)});
        }
    receives.resize(inbox.size());
    for (std::size_t i = 0; i < inbox.size(); ++i)
        MPI_Irecv(inbox[i].states.data(), int(inbox[i].states.size()), MPI_DOUBLE, inbox[i].from, 0, MPI_COMM_WORLD,
                  &receives[i]);
    std::vector<std::vector<double>> outbox;
    std::vector<MPI_Request> sends;
    std::string err;
    std::vector<std::size_t> part;
    PixelLoop loop(frame);
    const std::size_t chunk = kChainChunkPerThread * std::size_t(loop.concurrency());
    std::size_t next_in = 0;     // inbox[next_in...]: the receives of the units not yet taken
    std::size_t first_send = 0;  // sends[.. first_send): completed
    std::vector<int> completed;
    // MPI's progress (any test call drives every pending transfer): the open sends, freed as they
    // complete, and the next few receives; a window, so that a frame of many blocks tests few requests.
    auto progress = [&] {
        while (first_send < sends.size() && sends[first_send] == MPI_REQUEST_NULL) ++first_send;
        if (first_send < sends.size()) {
            completed.resize(sends.size() - first_send);
            int n = 0;
            MPI_Testsome(int(sends.size() - first_send), sends.data() + first_send, &n, completed.data(), MPI_STATUSES_IGNORE);
        }
        const std::size_t window = std::min(receives.size() - next_in, kChainReceiveWindow);
        int done = 0;
        if (window > 0) MPI_Testall(int(window), receives.data() + next_in, &done, MPI_STATUSES_IGNORE);
    };
    for (std::size_t u = 0; u < units.size() && err.empty(); ++u) {
        const std::vector<std::size_t>& mine = units[u].pixels;
        for (; next_in < inbox.size() && inbox[next_in].unit == u; ++next_in) {
            Inbox& in = inbox[next_in];
            MPI_Wait(&receives[next_in], MPI_STATUS_IGNORE);
            std::size_t i = 0;
            for (std::size_t px : mine)
                if (from[px] == in.from) std::copy(&in.states[i * S], &in.states[i * S] + S, &state[px * S]), ++i;
            std::vector<double>().swap(in.states);
        }
        // In chunks of kChainChunkPerThread pixels a thread, progressing the sends and receives between them.
        for (std::size_t c0 = 0; c0 < mine.size() && err.empty(); c0 += chunk) {
            part.assign(mine.begin() + std::ptrdiff_t(c0), mine.begin() + std::ptrdiff_t(std::min(mine.size(), c0 + chunk)));
            if constexpr (std::is_invocable_v<Step, const std::size_t*, std::size_t, PixelRays&>)
                err = loop.run_batches(part, std::size_t(kMaxPacketRays), step);
            else
                err = loop.run(&part, [&](std::size_t px, PixelRays& scratch) { step(px, scratch, &state[px * S]); });
            progress();
        }
        // Out: to each rank behind, in pixel order.
        for (int r = 0; r < frame.size && err.empty(); ++r) {
            std::vector<double> out;
            for (std::size_t px : mine)
                if (to[px] == r) out.insert(out.end(), &state[px * S], &state[px * S] + S);
            if (out.empty()) continue;
            bytes += out.size() * sizeof(double);
            outbox.push_back(std::move(out));
            sends.emplace_back();
            MPI_Isend(outbox.back().data(), int(outbox.back().size()), MPI_DOUBLE, r, 0, MPI_COMM_WORLD, &sends.back());
        }
        progress();
    }
    // (An error stops this rank's pipeline; the ranks behind it may then wait for its states: abort.)
    if (!err.empty()) {
        std::fprintf(stderr, "volref: error: %s\n", err.c_str());
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Waitall(int(sends.size()), sends.data(), MPI_STATUSES_IGNORE);
}

// The final states (on each pixel's last rank, or first with `first`) summed onto rank 0 (`all`; `mine`
// holds this rank's, zero elsewhere: both fresh from fresh_chain).
const PartBuffer& collect(const Frame& frame, const RankOrder& order, std::size_t S, const PartBuffer& state,
                          bool first, std::size_t& bytes, PartBuffer& mine, PartBuffer& all) {
    const std::size_t P = frame.pixels();
    for (std::size_t px = 0; px < P; ++px) {
        const bool holds = order.position[px] >= 0 && order.position[px] == (first ? 0 : order.count[px] - 1);
        if (holds) std::copy(&state[px * S], &state[px * S] + S, &mine[px * S]);
    }
    MPI_Reduce(mine.data(), all.data(), int(P * S), MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    bytes += mine.size() * sizeof(double);
    return all;
}

// The keys of the pixels whose ray this rank owns a span of (kNone elsewhere): its span's t0, where
// has(px, span, scratch) says the span holds something to integrate.
template <class Has>
bool span_keys(const Frame& frame, std::vector<double>& key, Has&& has) {
    key.assign(frame.pixels(), kNone);
    const std::string err = PixelLoop(frame).run(nullptr, [&](std::size_t px, PixelRays& scratch) {
        scratch.of(frame, px);
        const RaySpan span = frame.span(scratch.rays[0]);
        if (span.t0 < span.t1 && has(px, span, scratch)) key[px] = span.t0;
    });
    return !any_error(err, frame.rank, frame.size);
}

// The fixed step with early termination: RayState resumed span after span (the volume's integrator,
// or the several-volume mix); pixels R G B A on rank 0.
bool fixed_chain(const Frame& frame, ChainBuffers& buf, std::size_t& bytes) {
    const std::size_t P = frame.pixels(), S = RayState::kDoubles;
    std::vector<double> key;
    const bool ok = span_keys(frame, key, [&](std::size_t, const RaySpan&, const PixelRays& scratch) {
        for (const auto& iv : scratch.intervals)
            if (!iv.empty()) return true;
        return false;
    });
    if (!ok) return false;
    const RankOrder order = rank_order(frame, key);
    bytes = P * sizeof(double) * std::size_t(frame.size);
    PartBuffer& state = buf.state;  // fresh states (all zero)
    const PreparedVolume& first = frame.volume(0);
    auto one = [&](std::size_t px, PixelRays& scratch) {
        double* s = &state[px * S];
        scratch.of(frame, px);
        RayState st = RayState::read(s);
        const RaySpan span = frame.span(scratch.rays[0]);
        if (frame.mixed()) frame.multi().composite_span(scratch.rays.data(), scratch.intervals.data(), span, st);
        else first.integrator->integrate_span(scratch.rays[0], scratch.intervals[0], span, st);
        st.write(s);
    };
    // A batch of the block's pixels as one call of SIMD packets (integrate_parts' way, main.cpp): the
    // rays with a span and a state not yet stopped; each lane takes the samples its scalar call would.
    hand_on(frame, order, S, state, false, bytes, [&](const std::size_t* px, std::size_t n, PixelRays& scratch) {
        if (frame.mixed() || !first.packets) {
            for (std::size_t i = 0; i < n; ++i) one(px[i], scratch);
            return;
        }
        const std::size_t W = std::size_t(frame.width());
        Ray world[kMaxPacketRays], rays[kMaxPacketRays];
        std::vector<Interval> intervals[kMaxPacketRays];
        RaySpan spans[kMaxPacketRays];
        RayState states[kMaxPacketRays];
        std::size_t at[kMaxPacketRays];
        for (std::size_t i = 0; i < n; ++i) world[i] = frame.camera().pixel_ray(int(px[i] % W), int(px[i] / W)), at[i] = px[i];
        const int count = frame.owned_rays(world, int(n), rays, intervals, spans, at, [&](std::size_t p) {
            return RayState::read(&state[p * S]).stopped != 0.0;
        });
        for (int i = 0; i < count; ++i) states[i] = RayState::read(&state[at[i] * S]);
        if (count > 0) first.integrator->integrate_span_packet(rays, intervals, spans, states, count);
        for (int i = 0; i < count; ++i) states[i].write(&state[at[i] * S]);
    });
    const PartBuffer& final_state = collect(frame, order, S, state, false, bytes, buf.held, buf.summed);
    if (frame.rank != 0) return true;
    PartBuffer& pixels = buf.pixels;
    // The slot's own finish (the reference's composite_state, the fast profile's product_state); a
    // composite's does not read the ray or its intervals (Frame::finish_reads_intervals).
    const Ray no_ray{};
    const std::vector<Interval> no_intervals;
    for (std::size_t px = 0; px < P; ++px) {
        const glm::dvec4 rgba = frame.finish(0, &no_ray, &no_intervals, RayState::read(&final_state[px * S])).rgba;
        for (int c = 0; c < 4; ++c) pixels[px * 4 + std::size_t(c)] = rgba[c];
    }
    return true;
}

// The adaptive composite's pieces this rank owns in every pixel ([a, b, union piece]: cut as the single
// process cuts them, AdaptiveIntegrator::composite and MultiVolumeIntegrator::adaptive_composite; a
// piece belongs to the rank whose span holds its midpoint), the keys, and each ray's total length
// (rank 0: every pixel's). False after an error (reported).
bool adaptive_pieces(const Frame& frame, const AdaptiveIntegrator* one, std::vector<std::vector<std::array<double, 3>>>& pieces,
                     std::vector<double>& key, std::vector<double>& total) {
    const std::size_t V = frame.volumes();
    auto length = [&](const PixelRays& scratch) {
        double L = 0.0;
        if (V == 1)
            for (const Interval& iv : scratch.intervals[0]) L += iv.length();
        else
            for (const auto& piece : MultiVolumeIntegrator::pieces(scratch.intervals.data(), V)) L += piece.span.length();
        return L;
    };
    const bool ok = span_keys(frame, key, [&](std::size_t px, const RaySpan& span, const PixelRays& scratch) {
        std::vector<double> cut, all;
        auto keep = [&](double a, double b, std::size_t piece) {
            if (span.owns(0.5 * (a + b))) pieces[px].push_back({a, b, double(piece)});
        };
        total[px] = length(scratch);
        if (V == 1) {
            for (const Interval& iv : scratch.intervals[0]) {
                one->cuts(scratch.rays[0], iv, cut, span);
                for (std::size_t q = 0; q + 1 < cut.size(); ++q) keep(cut[q], cut[q + 1], 0);
            }
        } else {
            const auto ps = MultiVolumeIntegrator::pieces(scratch.intervals.data(), V);
            for (std::size_t i = 0; i < ps.size(); ++i) {
                frame.multi().adaptive_cuts(scratch.rays.data(), ps[i], all, cut);
                for (std::size_t q = 0; q + 1 < all.size(); ++q) keep(all[q], all[q + 1], i);
            }
        }
        return !pieces[px].empty();
    });
    if (!ok) return false;
    const std::string err = PixelLoop(frame).run(nullptr, [&](std::size_t px, PixelRays& scratch) {
        if (frame.rank != 0 || total[px] > 0.0) return;
        scratch.of(frame, px);
        total[px] = length(scratch);
    });
    return !any_error(err, frame.rank, frame.size);
}

// render.integrator "adaptive": the pieces cut as the single process cuts them (AdaptiveIntegrator::
// composite, MultiVolumeIntegrator::adaptive_composite), a piece belonging to the rank whose span
// holds its midpoint; AdaptiveComposite's state front to back, then the error's sums back to front;
// pixels R G B A error on rank 0.
bool adaptive_chain(const Frame& frame, ChainBuffers& buf, std::size_t& bytes) {
    using Composite = AdaptiveIntegrator::Composite;
    using MixComposite = AdaptiveComposite<MultiVolumeIntegrator::AdaptiveMix>;
    const std::size_t P = frame.pixels(), V = frame.volumes(), S = std::size_t(Composite::kStateSize);
    // The volume's adaptive integrator (one volume): made from its context, as the mix makes its own.
    std::unique_ptr<AdaptiveIntegrator> made;
    if (V == 1) made = std::make_unique<AdaptiveIntegrator>(*frame.volume(0).context);
    const AdaptiveIntegrator* one = made.get();
    std::vector<std::vector<std::array<double, 3>>> pieces(P);  // [a, b, union piece]
    std::vector<double> key, total(P, 0.0);
    if (!adaptive_pieces(frame, one, pieces, key, total)) return false;
    const RankOrder order = rank_order(frame, key);
    bytes = P * sizeof(double) * std::size_t(frame.size);
    const double tolerance = frame.scene.render.tolerance;
    const double safety = V == 1 ? one->safety() : frame.multi().adaptive_safety();
    const AdaptiveIntegrator::OneVolume none{one, nullptr};  // (a medium never sampled)
    PartBuffer& state = buf.state;
    const Composite fresh(none, tolerance, safety, 1.0);
    for (std::size_t px = 0; px < P; ++px) fresh.save(&state[px * S]);
    std::vector<std::vector<adaptive_detail::Leaf>> leaves(P);
    hand_on(frame, order, S, state, false, bytes, [&](std::size_t px, PixelRays& scratch, double* s) {
        scratch.of(frame, px);
        const std::vector<Ray>& rays = scratch.rays;
        if (V == 1) {
            const AdaptiveIntegrator::OneVolume medium{one, &rays[0]};  // (AdaptiveComposite keeps a reference)
            Composite st(medium, tolerance, safety, total[px]);
            st.load(s);
            for (const auto& piece : pieces[px]) {
                if (st.is_opaque()) break;
                one->composite_piece(rays[0], piece[0], piece[1], st);
            }
            st.save(s);
            leaves[px] = st.leaves();
            return;
        }
        const auto ps = MultiVolumeIntegrator::pieces(scratch.intervals.data(), V);
        MultiVolumeIntegrator::AdaptiveMix medium = frame.multi().adaptive_mix(rays.data());
        MixComposite st(medium, tolerance, safety, total[px]);
        st.load(s);
        std::vector<MultiVolumeIntegrator::MixTerm> opaque;
        for (const auto& piece : pieces[px]) {
            if (st.is_opaque()) break;
            const std::vector<int>& present = ps[std::size_t(piece[2])].present;
            medium.present = &present;
            frame.multi().adaptive_piece(rays.data(), present, piece[0], piece[1], st, opaque);
        }
        st.save(s);
        leaves[px] = st.leaves();
    });
    // The error's sums, back to front: (behind R G B, colour_err, tau_err), from the opaque piece's T c
    // (the last rank's final state).
    constexpr std::size_t E = kErrorSums;
    PartBuffer& sums = buf.sums;  // (all zero)
    for (std::size_t px = 0; px < P; ++px)
        if (order.position[px] >= 0 && order.position[px] == order.count[px] - 1)
            for (std::size_t i = 0; i < 3; ++i) sums[px * E + i] = state[px * S + Composite::kStateOpaqueColour + i];
    hand_on(frame, order, E, sums, true, bytes, [&](std::size_t px, PixelRays&, double* q) {
        glm::dvec3 behind(q[0], q[1], q[2]);
        double colour_err = q[3], tau_err = q[4];
        Composite::error_sums(leaves[px], behind, colour_err, tau_err);
        q[0] = behind.r, q[1] = behind.g, q[2] = behind.b, q[3] = colour_err, q[4] = tau_err;
    });
    const PartBuffer& final_state = collect(frame, order, S, state, false, bytes, buf.held, buf.summed);
    const PartBuffer& final_sums = collect(frame, order, E, sums, true, bytes, buf.sums_held, buf.sums_summed);
    if (frame.rank != 0) return true;
    PartBuffer& pixels = buf.pixels;
    for (std::size_t px = 0; px < P; ++px) {
        if (!(total[px] > 0.0)) continue;  // no interval: (0, 0, 0, 0), error 0 (as the single process)
        Composite st(none, tolerance, safety, total[px]);
        st.load(&final_state[px * S]);
        const PixelValue v = st.result_from(final_sums[px * E + 3], final_sums[px * E + 4]);
        for (int c = 0; c < 4; ++c) pixels[px * 5 + std::size_t(c)] = v.rgba[c];
        pixels[px * 5 + 4] = v.error;
    }
    return true;
}

}  // namespace

namespace {

// The doubles a pixel's state and (the adaptive chain) its error sums take: what fresh_chain allocates
// and chain_bytes counts.
struct ChainValues {
    std::size_t state, sums;
};
ChainValues chain_values(const Frame& frame) {
    if (frame.adaptive()) return {std::size_t(AdaptiveIntegrator::Composite::kStateSize), kErrorSums};
    return {std::size_t(RayState::kDoubles), 0};
}

}  // namespace

std::size_t chain_bytes(const Frame& frame) {
    const std::size_t P = frame.pixels(), ranks = std::size_t(frame.size), root = frame.rank == 0 ? 1 : 0;
    const ChainValues v = chain_values(frame);
    const std::size_t handed = v.state + v.sums;
    const std::size_t per_pixel = (1 + ranks) * sizeof(double) + 4 * sizeof(int) + handed * sizeof(double) * (4 + root) +
                                  root * std::size_t(frame.channels()) * sizeof(double);
    return P * per_pixel;
}

bool chained(const Frame& frame) {
    if (!is_composite(frame.scene.render.projection)) return false;
    if (frame.adaptive()) return true;
    if (frame.size == 1) return false;  // one span a pixel: nothing to hand on, the parts' path (as volref render)
    return frame.mixed() ? frame.multi().composite_spans_in_order() : frame.volume(0).integrator->spans_in_order();
}

ChainBuffers fresh_chain(const Frame& frame) {
    const std::size_t P = frame.pixels(), root = frame.rank == 0 ? 1 : 0;
    const auto [S, E] = chain_values(frame);
    ChainBuffers b;
    b.state.assign(P * S, 0.0), b.held.assign(P * S, 0.0), b.summed.assign(root * P * S, 0.0);
    b.sums.assign(P * E, 0.0), b.sums_held.assign(P * E, 0.0), b.sums_summed.assign(root * P * E, 0.0);
    b.pixels.assign(root * P * std::size_t(frame.channels()), 0.0);
    return b;
}

bool chained_pixels(const Frame& frame, ChainBuffers& buffers, std::size_t& bytes) {
    return frame.adaptive() ? adaptive_chain(frame, buffers, bytes) : fixed_chain(frame, buffers, bytes);
}

}  // namespace volref::mpi
