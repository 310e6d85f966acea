#include "cli/mpi/Balance.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "core/grid/VoxelArray.h"
#include "core/integrate/march/March.h"
#include "core/render/PixelBlocks.h"

namespace volref::mpi {

WorkBins count_work(const Frame& f) {
    constexpr int kProbe = 4;          // rays: every 4th pixel on both axes
    constexpr int kProbeBlocks = 2;    // packets: every 2nd block of pixels on both axes
    constexpr std::int64_t kWorkBins = 16;
    WorkBins bins(f.lattice, kWorkBins);
    const PreparedVolume& first = f.volume(0);
    const GridBox& g = f.members[0].grid;
    MarchOptions o;
    o.step = first.step;
    o.skip = is_composite(f.scene.render.projection) ? first.macrocells.get() : nullptr;
    Ray world[kMaxPacketRays], rays[kMaxPacketRays];
    std::vector<Interval> intervals[kMaxPacketRays];
    // The span this rank owns of ray i, marched as the render places its samples; on_sample(u) with each
    // sample's continuous lattice index.
    auto walk = [&](int i, auto&& on_sample) {
        o.span = f.span(rays[i]);
        if (intervals[i].empty() || !(o.span.t0 < o.span.t1)) return false;
        o.ray = &rays[i];
        march(intervals[i], o, [&](const MarchSample& m) {
            on_sample((rays[i].at(m.t) - g.origin) / g.spacing);
            return true;
        });
        return true;
    };
    if (f.adaptive()) {  // one ray at a time: its samples
        for (int y = kProbe / 2; y < f.height(); y += kProbe)
            for (int x0 = kProbe / 2; x0 < f.width(); x0 += kProbe * kMaxPacketRays) {
                int n = 0;
                for (int x = x0; x < f.width() && n < kMaxPacketRays; x += kProbe) world[n++] = f.camera().pixel_ray(x, y);
                first.intervals(world, n, rays, intervals);
                for (int i = 0; i < n; ++i) walk(i, [&](const glm::dvec3& u) { bins.work[bins.bin_of(f.lattice, u)] += 1.0; });
            }
        return bins;
    }
    // The fixed step: packets of kWorkPacketLanes rays with a span, from every kProbeBlocks-th block of the
    // render's (PixelBlocks.h; main.cpp integrate_parts), costed by add_packet_work (Bricks.h).
    const std::int64_t voxel_bytes = f.scene.render.profile == ProfileId::Fast
                                         ? std::int64_t(sizeof(float))
                                         : std::int64_t(scalar_type_size(first.model.volume().values.type()));
    std::vector<LaneSample> lanes[kWorkPacketLanes];
    for_each_block(PixelRect{0, 0, f.width(), f.height()}, [&](const PixelBlock& b) {
        const int n = b.count;
        for (int i = 0; i < n; ++i) world[i] = f.camera().pixel_ray(b.x[i], b.y[i]);
        first.intervals(world, n, rays, intervals);
        int count = 0;
        for (int i = 0; i < n; ++i) {
            const bool owned = walk(i, [&](const glm::dvec3& u) {
                const std::int64_t c[3] = {std::int64_t(std::floor(u.x)), std::int64_t(std::floor(u.y)), std::int64_t(std::floor(u.z))};
                const std::int64_t voxel = c[0] + g.dims[0] * (c[1] + g.dims[1] * c[2]);
                lanes[count].push_back({bins.bin_of(f.lattice, u), voxel * voxel_bytes / kWorkLineBytes});
            });
            if (owned && ++count == kWorkPacketLanes) {
                add_packet_work(lanes, count, bins.work);
                for (auto& l : lanes) l.clear();
                count = 0;
            }
        }
        if (count > 0) add_packet_work(lanes, count, bins.work);
        for (auto& l : lanes) l.clear();
    }, kProbeBlocks);
    return bins;
}

std::vector<Brick> balanced_bricks(const Frame& f, WorkBins mine) {
    std::vector<double> sum(mine.work.size(), 0.0);
    MPI_Allreduce(mine.work.data(), sum.data(), int(sum.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    mine.work = std::move(sum);
    return split_lattice(f.lattice, f.size, &mine);
}

}  // namespace volref::mpi
