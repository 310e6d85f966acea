// Highway's per-target compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/integrate/packet/PacketExtremum.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "core/integrate/packet/PacketExtremum.h"
#include "core/integrate/packet/PacketKernels-inl.h"

#include <limits>

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace {
using namespace packet;

template <typename T>
void extremum_lanes(const VolumeView& view, const PacketRun& run, bool maximum, const Ray* rays, const std::vector<Interval>* intervals,
                    RayExtremum* out, int count, const RaySpan* spans) {
    using D = hn::ScalableTag<T>;
    using V = hn::Vec<D>;
    using M = hn::Mask<D>;
    const D d;
    constexpr std::size_t kLanes = RayPacketT<T>::kLanes;
    // Each lane's extremum so far for the walk's skipping (NaN before its first sample).
    HWY_ALIGN double extremum[kLanes];
    HWY_ALIGN T lane_best[kLanes];
    for (double& e : extremum) e = std::numeric_limits<double>::quiet_NaN();
    // Float lanes work in coordinates local to the volume (RayPacketT): positions relative to its
    // origin, t relative to each lane's first entry (added back to the extremum's t below).
    constexpr bool kFast = std::is_same_v<T, float>;
    const double zero_origin[3] = {0.0, 0.0, 0.0};
    const GridView& grid = view.grid_of<T>();
    const double* origin = kFast ? zero_origin : grid.origin;
    RayPacketT<T> packet(rays, intervals, count, run.step, run.macrocells, run.macrocells ? extremum : nullptr, maximum,
                         kFast ? grid.origin : nullptr, spans);
    const V Ox = hn::Load(d, packet.ox), Oy = hn::Load(d, packet.oy), Oz = hn::Load(d, packet.oz);
    const V Dx = hn::Load(d, packet.dx), Dy = hn::Load(d, packet.dy), Dz = hn::Load(d, packet.dz);
    const PacketTrilinearT<T> trilinear(grid.voxels, grid.voxel_type, grid.dims, origin, grid.inv_spacing);
    const V nan = hn::Set(d, std::numeric_limits<T>::quiet_NaN());
    Extremum<SimdLanes<T>> acc(maximum);
    while (packet.next()) {
        const V t = hn::Load(d, packet.tm);
        const M alive = hn::Gt(hn::Load(d, packet.live), hn::Zero(d));
        const V v = trilinear(hn::Add(Ox, hn::Mul(t, Dx)), hn::Add(Oy, hn::Mul(t, Dy)), hn::Add(Oz, hn::Mul(t, Dz)));
        acc.add(alive, v, t);
        if (run.macrocells) {
            hn::Store(hn::IfThenElse(acc.any(), acc.value(), nan), d, lane_best);
            for (std::size_t l = 0; l < kLanes; ++l) extremum[l] = double(lane_best[l]);
        }
    }
    HWY_ALIGN T b[kLanes], tb[kLanes], s[kLanes];
    hn::Store(acc.value(), d, b);
    hn::Store(acc.where(), d, tb);
    hn::Store(hn::IfThenElseZero(acc.any(), hn::Set(d, T(1))), d, s);
    for (int l = 0; l < count && l < int(packet.lanes); ++l) out[l] = RayExtremum{s[l] != T(0), double(b[l]), double(tb[l]) + packet.t_ref[l]};
}

template <typename T>
void extremum_all(const VolumeView& view, const PacketRun& run, bool maximum, const Ray* rays, const std::vector<Interval>* intervals,
                  RayExtremum* out, int count, const RaySpan* spans) {
    const int L = int(hn::Lanes(hn::ScalableTag<T>()));
    for (int first = 0; first < count; first += L)
        extremum_lanes<T>(view, run, maximum, rays + first, intervals + first, out + first, std::min(L, count - first),
                          spans ? spans + first : nullptr);
}

}  // namespace

void ExtremumPacket(const VolumeView& view, const PacketRun& run, bool maximum, const Ray* rays, const std::vector<Interval>* intervals,
                    RayExtremum* out, int count, const RaySpan* spans) {
    on_lanes(run.fast, [&]<typename T>() HWY_ATTR { extremum_all<T>(view, run, maximum, rays, intervals, out, count, spans); });
}

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace volref {
HWY_EXPORT(ExtremumPacket);

void extremum_packet(const VolumeView& view, const PacketRun& run, bool maximum, const Ray* rays, const std::vector<Interval>* intervals,
                     RayExtremum* out, int count, const RaySpan* spans) {
    HWY_DYNAMIC_DISPATCH(ExtremumPacket)(view, run, maximum, rays, intervals, out, count, spans);
}
}  // namespace volref
#endif
