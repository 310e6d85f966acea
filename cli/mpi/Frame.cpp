#include "cli/mpi/Frame.h"

#include <mpi.h>

#include <algorithm>
#include <cstdio>

#include "core/integrate/march/SpanStates.h"
#include "geometry/BoxIntersection.h"

namespace volref::mpi {

bool any_error(const std::string& mine, int rank, int size) {
    int failed = mine.empty() ? 0 : 1, any = 0;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (!any) return false;
    int len = int(mine.size());
    std::vector<int> lens(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size), 0);
    MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<char> all;
    if (rank == 0) {
        int total = 0;
        for (int r = 0; r < size; ++r) offsets[std::size_t(r)] = total, total += lens[std::size_t(r)];
        all.resize(std::size_t(std::max(total, 1)));
    }
    MPI_Gatherv(mine.data(), len, MPI_CHAR, all.data(), lens.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
    if (rank == 0)
        for (int r = 0; r < size; ++r)
            if (lens[std::size_t(r)] > 0) {
                std::fprintf(stderr, "volref: error: %.*s\n", lens[std::size_t(r)], all.data() + offsets[std::size_t(r)]);
                break;
            }
    return true;
}

void Frame::pixel_intervals(int x, int y, Ray* rays, std::vector<Interval>* intervals) const {
    const Ray world = prepared->pixel_ray(x, y);
    for (std::size_t k = 0; k < volumes(); ++k) volume(k).intervals(&world, 1, &rays[k], &intervals[k]);
}

bool Frame::meets_brick_box(const Ray& lattice_ray) const {
    Interval range;
    return intersect_box(lattice_ray, brick_lo, brick_hi, range);
}

RaySpan Frame::span(const Ray& lattice_ray) const {
    if (!meets_brick_box(lattice_ray)) return RaySpan{kNone, kNone};
    return owned_span(bricks[std::size_t(rank)], lattice, members[0].grid, lattice_ray);
}

bool Frame::meets_brick(const Ray* world, int count) const {
    for (int i = 0; i < count; ++i)
        if (meets_brick_box(volume(0).volume_ray(world[i]))) return true;
    return false;
}

// A slot is the volume's own integrator (one volume; several volumes other than composite), or the
// several-volume mix, whose state is composite_state's (march/SpanStates.h).
void Frame::merge(std::size_t slot, RayState& front, const RayState& back) const {
    if (mixed()) composite_state::merge(front, back);
    else volume(slot).integrator->merge_spans(front, back);
}

PixelValue Frame::finish(std::size_t slot, const Ray* rays, const std::vector<Interval>* intervals,
                         const RayState& state) const {
    if (!mixed()) return volume(slot).integrator->finish(rays[slot], intervals[slot], state);
    PixelValue v;
    v.rgba = composite_state::rgba(state);
    return v;
}

void Frame::write_pixel(const PixelValue* values, const std::vector<Interval>* intervals, double* out) const {
    const PixelValue v = slots() > 1 ? multi().combine(values, intervals) : values[0];
    for (int c = 0; c < 4; ++c) out[c] = v.rgba[c];
    if (first_hit()) out[4] = v.depth;
    if (adaptive()) out[channels() - 1] = v.error;
}

}  // namespace volref::mpi
