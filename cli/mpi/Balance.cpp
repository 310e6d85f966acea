#include "cli/mpi/Balance.h"

#include <mpi.h>

#include <cstdint>
#include <utility>

#include "core/integrate/march/March.h"

namespace volref::mpi {

WorkBins count_work(const Frame& f) {
    constexpr int kProbe = 4;
    constexpr std::int64_t kWorkBins = 16;
    WorkBins bins(f.lattice, kWorkBins);
    const PreparedVolume& first = *f.members[0].prepared;
    const GridBox& g = f.members[0].grid;
    MarchOptions o;
    o.step = first.step;
    o.skip = is_composite(f.scene.render.projection) ? first.macrocells.get() : nullptr;
    Ray world[kMaxPacketRays], rays[kMaxPacketRays];
    std::vector<Interval> intervals[kMaxPacketRays];
    for (int y = kProbe / 2; y < f.height(); y += kProbe)
        for (int x0 = kProbe / 2; x0 < f.width(); x0 += kProbe * kMaxPacketRays) {
            int n = 0;
            for (int x = x0; x < f.width() && n < kMaxPacketRays; x += kProbe) world[n++] = f.camera->pixel_ray(x, y);
            f.volume_intervals(0, world, n, rays, intervals);
            for (int i = 0; i < n; ++i) {
                o.span = f.span(rays[i]);
                if (intervals[i].empty() || !(o.span.t0 < o.span.t1)) continue;
                o.ray = &rays[i];
                march(intervals[i], o, [&](const MarchSample& m) {
                    bins.work[bins.bin_of(f.lattice, (rays[i].at(m.t) - g.origin) / g.spacing)] += 1.0;
                    return true;
                });
            }
        }
    return bins;
}

std::vector<Brick> balanced_bricks(const Frame& f, WorkBins mine) {
    std::vector<double> sum(mine.work.size(), 0.0);
    MPI_Allreduce(mine.work.data(), sum.data(), int(sum.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    mine.work = std::move(sum);
    return split_lattice(f.lattice, f.size, &mine);
}

}  // namespace volref::mpi
