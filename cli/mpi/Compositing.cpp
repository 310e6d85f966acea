#include "cli/mpi/Compositing.h"

#include <mpi.h>

#include <algorithm>
#include <array>

namespace volref::mpi {

namespace {

RayState state_of(const double* part) { return RayState::read(part + 1); }

// Pixel px from its slots' merged parts (`slot_part(sl)`: kPart doubles each), into out. The pixel's
// rays and intervals are recomputed only where finishing reads them (else they stay empty).
template <class SlotPart>
void finish_pixel(const Frame& frame, std::size_t px, SlotPart&& slot_part, std::vector<Ray>& rays,
                  std::vector<std::vector<Interval>>& intervals, std::vector<PixelValue>& values, double* out) {
    const std::size_t W = std::size_t(frame.width());
    if (frame.finish_reads_intervals()) frame.pixel_intervals(int(px % W), int(px / W), rays.data(), intervals.data());
    for (std::size_t sl = 0; sl < frame.slots(); ++sl)
        values[sl] = frame.finish(sl, rays.data(), intervals.data(), slot_part(sl));
    frame.write_pixel(values.data(), intervals.data(), out);
}

}  // namespace

void direct_send(const Frame& frame, const PartBuffer& part, double* image, Traffic& traffic) {
    const int size = frame.size;
    PartBuffer all;
    if (frame.rank == 0) all.resize(part.size() * std::size_t(size));
    MPI_Gather(part.data(), int(part.size()), MPI_DOUBLE, all.data(), int(part.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (frame.rank != 0) {
        traffic.sent = part.size() * sizeof(double);
        return;
    }
    traffic.received = part.size() * sizeof(double) * std::size_t(size - 1);
    const std::size_t stride = part.size(), slots = frame.slots(), nc = std::size_t(frame.channels());
    std::vector<const double*> order(static_cast<std::size_t>(size));
    std::vector<RayState> merged(slots);
    std::vector<PixelValue> values(slots);
    std::vector<std::vector<Interval>> intervals(frame.volumes());
    std::vector<Ray> rays(frame.volumes());
    for (std::size_t px = 0; px < frame.pixels(); ++px) {
        for (std::size_t sl = 0; sl < slots; ++sl) {
            for (int r = 0; r < size; ++r) order[std::size_t(r)] = &all[std::size_t(r) * stride + (px * slots + sl) * kPart];
            // Ray order: the key, then the rank; parts of no span (key +inf) last.
            std::stable_sort(order.begin(), order.end(), [](const double* a, const double* b) { return a[0] < b[0]; });
            merged[sl] = RayState{};
            for (const double* q : order)
                if (q[0] != kNone) frame.merge(sl, merged[sl], state_of(q));
        }
        finish_pixel(frame, px, [&](std::size_t sl) { return merged[sl]; }, rays, intervals, values, image + px * nc);
    }
}

// In round i rank r and its partner r ^ 2^i halve the pixel range they share, each sends the other half
// to the other and merges the half it keeps. The k-d split of a power-of-two count gives ranks r and
// r ^ 1 sibling bricks, and after round i the 2^(i+1) ranks merged are one subtree's box, convex: the
// ray crosses it in one span, so two merged parts are in ray order by their keys. Then rank 0 gathers
// the finished pixels of every rank's range (MPI_Gatherv).
void binary_swap(const Frame& frame, PartBuffer& part, double* image, Traffic& traffic) {
    const int rank = frame.rank, size = frame.size;
    const std::size_t pixels = frame.pixels(), slots = frame.slots(), nc = std::size_t(frame.channels());
    auto merge = [&](std::size_t sl, double* a, const double* b, bool b_first_on_tie) {
        if (b[0] == kNone) return;
        if (a[0] == kNone) return (void)std::copy(b, b + kPart, a);
        const bool b_front = b[0] < a[0] || (b[0] == a[0] && b_first_on_tie);
        RayState front = state_of(b_front ? b : a);
        frame.merge(sl, front, state_of(b_front ? a : b));
        a[0] = std::min(a[0], b[0]);
        front.write(a + 1);
    };
    auto range_of = [&](int r) {
        std::size_t lo = 0, hi = pixels;
        for (int bit = 1; bit < size; bit <<= 1) {
            const std::size_t mid = lo + (hi - lo) / 2;
            (r & bit ? lo : hi) = mid;
        }
        return std::array<std::size_t, 2>{lo, hi};
    };
    PartBuffer incoming;
    std::size_t lo = 0, hi = pixels;
    const std::size_t stride = slots * kPart;  // one pixel's slots
    for (int bit = 1; bit < size; bit <<= 1) {
        const int partner = rank ^ bit;
        const std::size_t mid = lo + (hi - lo) / 2;
        const bool upper = (rank & bit) != 0;
        const std::size_t keep_lo = upper ? mid : lo, keep_hi = upper ? hi : mid;
        const std::size_t send_lo = upper ? lo : mid, send_hi = upper ? mid : hi;
        incoming.resize((keep_hi - keep_lo) * stride);
        MPI_Sendrecv(&part[send_lo * stride], int((send_hi - send_lo) * stride), MPI_DOUBLE, partner, bit,
                     incoming.data(), int(incoming.size()), MPI_DOUBLE, partner, bit, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        traffic.sent += (send_hi - send_lo) * stride * sizeof(double);
        traffic.received += incoming.size() * sizeof(double);
        for (std::size_t px = keep_lo; px < keep_hi; ++px)
            for (std::size_t sl = 0; sl < slots; ++sl)
                merge(sl, &part[px * stride + sl * kPart], &incoming[(px - keep_lo) * stride + sl * kPart], upper);
        lo = keep_lo;
        hi = keep_hi;
    }
    PartBuffer finished((hi - lo) * nc);
    std::vector<PixelValue> values(slots);
    std::vector<std::vector<Interval>> intervals(frame.volumes());
    std::vector<Ray> rays(frame.volumes());
    for (std::size_t px = lo; px < hi; ++px) {
        auto slot_part = [&](std::size_t sl) {
            const double* q = &part[px * stride + sl * kPart];
            return q[0] == kNone ? RayState{} : state_of(q);
        };
        finish_pixel(frame, px, slot_part, rays, intervals, values, &finished[(px - lo) * nc]);
    }
    std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    for (int r = 0; r < size; ++r) {
        const auto rr = range_of(r);
        counts[std::size_t(r)] = int((rr[1] - rr[0]) * nc);
        displs[std::size_t(r)] = int(rr[0] * nc);
    }
    MPI_Gatherv(finished.data(), int(finished.size()), MPI_DOUBLE, rank == 0 ? image : nullptr, counts.data(),
                displs.data(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (rank != 0) traffic.sent += finished.size() * sizeof(double);
    else traffic.received += (pixels - (hi - lo)) * nc * sizeof(double);
}

}  // namespace volref::mpi
