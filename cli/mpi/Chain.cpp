#include "cli/mpi/Chain.h"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <new>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/integrate/adaptive/AdaptiveIntegrator.h"
#include "core/integrate/march/SpanStates.h"

namespace volref::mpi {

namespace {

// Each pixel's ranks in ray order: this rank's place among them (-1: none) and how many there are.
struct RankOrder {
    std::vector<int> position, count;
};
RankOrder rank_order(const Frame& frame, const std::vector<double>& key) {
    const std::size_t P = frame.pixels();
    std::vector<double> keys(P * std::size_t(frame.size));
    MPI_Allgather(key.data(), int(P), MPI_DOUBLE, keys.data(), int(P), MPI_DOUBLE, MPI_COMM_WORLD);
    RankOrder o{std::vector<int>(P, -1), std::vector<int>(P, 0)};
    for (std::size_t px = 0; px < P; ++px) {
        for (int r = 0; r < frame.size; ++r) {
            const double k = keys[std::size_t(r) * P + px];
            if (k == kNone) continue;
            ++o.count[px];
            if (key[px] != kNone && (k < key[px] || (k == key[px] && r < frame.rank))) ++o.position[px];
        }
        if (key[px] != kNone) ++o.position[px];  // from -1: the ranks in front of this one
    }
    return o;
}

// f(px, rays, intervals) for every pixel (round < 0) or this rank's pixels of `round`, in parallel;
// returns the error message of an exception (empty: none).
template <class F>
std::string each_pixel(const Frame& frame, const RankOrder* order, int round, F&& f) {
    try {
        tbb::task_arena arena(frame.threads > 0 ? frame.threads : tbb::task_arena::automatic);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, frame.pixels()), [&](const tbb::blocked_range<std::size_t>& r) {
                std::vector<std::vector<Interval>> intervals(frame.volumes());
                std::vector<Ray> rays(frame.volumes());
                const std::size_t W = std::size_t(frame.width());
                for (std::size_t px = r.begin(); px != r.end(); ++px) {
                    if (round >= 0 && order->position[px] != round) continue;
                    frame.pixel_intervals(int(px % W), int(px / W), rays.data(), intervals.data());
                    f(px, rays, intervals);
                }
            });
        });
    } catch (const std::bad_alloc&) {
        return "out of memory";
    } catch (const std::exception& e) {
        return e.what();
    }
    return {};
}

// The state (S doubles a pixel) handed on: in round j (front to back, or from the last rank with
// `reverse`) each pixel's j-th rank runs step(px, rays, intervals, in_out); one rank wrote each pixel,
// so the MPI_Allreduce sum of the rounds' writes is the next state. False after an error (reported).
template <class Step>
bool hand_on(const Frame& frame, const RankOrder& order, std::size_t S, std::vector<double>& state, bool reverse, Step&& step) {
    const std::size_t P = frame.pixels();
    std::vector<double> delta(P * S), next(P * S);
    for (int i = 0; i < frame.size; ++i) {
        const int j = reverse ? frame.size - 1 - i : i;
        std::fill(delta.begin(), delta.end(), 0.0);
        const std::string err = each_pixel(frame, &order, j, [&](std::size_t px, const std::vector<Ray>& rays,
                                                                  const std::vector<std::vector<Interval>>& intervals) {
            std::copy(&state[px * S], &state[px * S] + S, &delta[px * S]);
            step(px, rays, intervals, &delta[px * S]);
        });
        if (any_error(err, frame.rank, frame.size)) return false;
        MPI_Allreduce(delta.data(), next.data(), int(P * S), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
        for (std::size_t px = 0; px < P; ++px)
            if (order.count[px] > j) std::copy(&next[px * S], &next[px * S] + S, &state[px * S]);
    }
    return true;
}

// The fixed step with early termination: RayState resumed span after span (the volume's integrator,
// or the several-volume mix); pixels R G B A.
bool fixed_chain(const Frame& frame, std::vector<double>& pixels, std::size_t& bytes) {
    const std::size_t P = frame.pixels(), S = RayState::kDoubles;
    std::vector<double> key(P, kNone);
    std::string err = each_pixel(frame, nullptr, -1, [&](std::size_t px, const std::vector<Ray>& rays,
                                                         const std::vector<std::vector<Interval>>& intervals) {
        const RaySpan span = frame.span(rays[0]);
        bool any = false;
        for (const auto& iv : intervals) any = any || !iv.empty();
        if (any && span.t0 < span.t1) key[px] = span.t0;
    });
    if (any_error(err, frame.rank, frame.size)) return false;
    const RankOrder order = rank_order(frame, key);
    std::vector<double> state(P * S, 0.0);  // fresh states (all zero)
    const bool ok = hand_on(frame, order, S, state, false, [&](std::size_t, const std::vector<Ray>& rays,
                                                                const std::vector<std::vector<Interval>>& intervals, double* s) {
        RayState st;
        std::memcpy(&st, s, sizeof st);
        if (frame.mixed()) frame.multi->composite_span(rays.data(), intervals.data(), frame.span(rays[0]), st);
        else frame.members[0].prepared->integrator->integrate_span(rays[0], intervals[0], frame.span(rays[0]), st);
        std::memcpy(s, &st, sizeof st);
    });
    if (!ok) return false;
    bytes = P * sizeof(double) * (1 + std::size_t(frame.size) * S);
    pixels.assign(P * 4, 0.0);
    for (std::size_t px = 0; px < P; ++px) {
        RayState st;
        std::memcpy(&st, &state[px * S], sizeof st);
        const glm::dvec4 rgba = composite_state::rgba(st);
        for (int c = 0; c < 4; ++c) pixels[px * 4 + std::size_t(c)] = rgba[c];
    }
    return true;
}

// render.integrator "adaptive": the pieces cut as the single process cuts them (AdaptiveIntegrator::
// composite, MultiVolumeIntegrator::adaptive_composite), a piece belonging to the rank whose span
// holds its midpoint; AdaptiveComposite's state front to back, then the error's sums back to front;
// pixels R G B A error.
bool adaptive_chain(const Frame& frame, std::vector<double>& pixels, std::size_t& bytes) {
    using Composite = AdaptiveIntegrator::Composite;
    using MixComposite = AdaptiveComposite<MultiVolumeIntegrator::AdaptiveMix>;
    const std::size_t P = frame.pixels(), V = frame.volumes(), S = std::size_t(Composite::kStateSize);
    // The volume's adaptive integrator (one volume): made from its context, as the mix makes its own.
    std::unique_ptr<AdaptiveIntegrator> made;
    if (V == 1) made = std::make_unique<AdaptiveIntegrator>(*frame.members[0].prepared->context);
    const AdaptiveIntegrator* one = made.get();
    std::vector<std::vector<std::array<double, 3>>> pieces(P);  // [a, b, union piece]
    std::vector<double> key(P, kNone), total(P, 0.0);
    std::string err = each_pixel(frame, nullptr, -1, [&](std::size_t px, const std::vector<Ray>& rays,
                                                         const std::vector<std::vector<Interval>>& intervals) {
        std::vector<double> cut, all;
        const RaySpan span = frame.span(rays[0]);
        auto keep = [&](double a, double b, std::size_t piece) {
            if (span.owns(0.5 * (a + b))) pieces[px].push_back({a, b, double(piece)});
        };
        if (V == 1) {
            for (const Interval& iv : intervals[0]) total[px] += iv.length();
            for (const Interval& iv : intervals[0]) {
                one->cuts(rays[0], iv, cut);
                for (std::size_t q = 0; q + 1 < cut.size(); ++q) keep(cut[q], cut[q + 1], 0);
            }
        } else {
            const auto ps = MultiVolumeIntegrator::pieces(intervals.data(), V);
            for (const auto& piece : ps) total[px] += piece.span.length();
            for (std::size_t i = 0; i < ps.size(); ++i) {
                frame.multi->adaptive_cuts(rays.data(), ps[i], all, cut);
                for (std::size_t q = 0; q + 1 < all.size(); ++q) keep(all[q], all[q + 1], i);
            }
        }
        if (!pieces[px].empty()) key[px] = span.t0;
    });
    if (any_error(err, frame.rank, frame.size)) return false;
    const RankOrder order = rank_order(frame, key);
    const double tolerance = frame.scene.render.tolerance;
    const double safety = V == 1 ? one->safety() : frame.multi->adaptive_safety();
    const AdaptiveIntegrator::OneVolume none{one, nullptr};  // (a medium never sampled)
    std::vector<double> state(P * S, 0.0);
    const Composite fresh(none, tolerance, safety, 1.0);
    for (std::size_t px = 0; px < P; ++px) fresh.save(&state[px * S]);
    std::vector<std::vector<adaptive_detail::Leaf>> leaves(P);
    bool ok = hand_on(frame, order, S, state, false, [&](std::size_t px, const std::vector<Ray>& rays,
                                                          const std::vector<std::vector<Interval>>& intervals, double* s) {
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
        const auto ps = MultiVolumeIntegrator::pieces(intervals.data(), V);
        MultiVolumeIntegrator::AdaptiveMix medium = frame.multi->adaptive_mix(rays.data());
        MixComposite st(medium, tolerance, safety, total[px]);
        st.load(s);
        std::vector<MultiVolumeIntegrator::MixTerm> opaque;
        for (const auto& piece : pieces[px]) {
            if (st.is_opaque()) break;
            const std::vector<int>& present = ps[std::size_t(piece[2])].present;
            medium.present = &present;
            frame.multi->adaptive_piece(rays.data(), present, piece[0], piece[1], st, opaque);
        }
        st.save(s);
        leaves[px] = st.leaves();
    });
    if (!ok) return false;
    // The error's sums, back to front: (behind R G B, colour_err, tau_err), from the opaque piece's T c.
    constexpr std::size_t E = 5;
    std::vector<double> sums(P * E, 0.0);
    for (std::size_t px = 0; px < P; ++px)
        for (std::size_t i = 0; i < 3; ++i) sums[px * E + i] = state[px * S + Composite::kStateOpaqueColour + i];
    ok = hand_on(frame, order, E, sums, true, [&](std::size_t px, const std::vector<Ray>&, const std::vector<std::vector<Interval>>&,
                                                  double* q) {
        glm::dvec3 behind(q[0], q[1], q[2]);
        double colour_err = q[3], tau_err = q[4];
        Composite::error_sums(leaves[px], behind, colour_err, tau_err);
        q[0] = behind.r, q[1] = behind.g, q[2] = behind.b, q[3] = colour_err, q[4] = tau_err;
    });
    if (!ok) return false;
    bytes = P * sizeof(double) * (1 + std::size_t(frame.size) * (S + E));
    pixels.assign(P * 5, 0.0);
    for (std::size_t px = 0; px < P; ++px) {
        if (!(total[px] > 0.0)) continue;  // no interval: (0, 0, 0, 0), error 0 (as the single process)
        Composite st(none, tolerance, safety, total[px]);
        st.load(&state[px * S]);
        const PixelValue v = st.result_from(sums[px * E + 3], sums[px * E + 4]);
        for (int c = 0; c < 4; ++c) pixels[px * 5 + std::size_t(c)] = v.rgba[c];
        pixels[px * 5 + 4] = v.error;
    }
    return true;
}

}  // namespace

bool chained(const Frame& frame) {
    if (frame.scene.render.projection != Projection::Composite) return false;
    if (frame.adaptive()) return true;
    return frame.mixed() ? frame.multi->composite_spans_in_order() : frame.members[0].prepared->integrator->spans_in_order();
}

bool chained_pixels(const Frame& frame, std::vector<double>& pixels, std::size_t& bytes) {
    return frame.adaptive() ? adaptive_chain(frame, pixels, bytes) : fixed_chain(frame, pixels, bytes);
}

}  // namespace volref::mpi
