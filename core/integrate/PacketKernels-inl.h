// Pieces shared by the SIMD packet kernels (PacketComposite.cpp, PacketExtremum.cpp), compiled once
// per Highway target: the lane walk over intervals and segments (Segments.h placement) and the
// trilinear reconstruction of a packet of points, term by term as VolumeSampler::trilinear.
// Per-target include guard (Highway's pattern for -inl headers).
#if defined(VOLREF_PACKET_KERNELS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef VOLREF_PACKET_KERNELS_INL_H_
#undef VOLREF_PACKET_KERNELS_INL_H_
#else
#define VOLREF_PACKET_KERNELS_INL_H_
#endif

#include <hwy/highway.h>

#include <vector>

#include "core/camera/Ray.h"
#include "core/integrate/SegmentWalk.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace packet {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::ScalableTag<double>;
using DI = hn::RebindToSigned<D>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// The rays of a packet (SoA) and each lane's walk over its segments (ForwardSegmentWalk: the same
// segments as the scalar path, with empty-space skipping when `grid` is set); lanes beyond `count`
// never become active.
struct RayPacket {
    static constexpr std::size_t kLanes = HWY_LANES(double);
    HWY_ALIGN double ox[kLanes], oy[kLanes], oz[kLanes], dx[kLanes], dy[kLanes], dz[kLanes];
    HWY_ALIGN double tm[kLanes], len[kLanes], live[kLanes];
    ForwardSegmentWalk walk[kLanes];
    bool active[kLanes];
    std::size_t lanes = 0;

    RayPacket(const Ray* rays, const std::vector<Interval>* intervals, int count, double step,
              const MacrocellGrid* grid = nullptr) {
        lanes = hn::Lanes(D());
        for (std::size_t l = 0; l < lanes; ++l) {
            const bool real = int(l) < count;
            const Ray& r = rays[real ? l : 0];
            ox[l] = r.origin.x;
            oy[l] = r.origin.y;
            oz[l] = r.origin.z;
            dx[l] = r.direction.x;
            dy[l] = r.direction.y;
            dz[l] = r.direction.z;
            active[l] = real;
            if (real) walk[l] = ForwardSegmentWalk(grid, rays[l], intervals[l], step);
        }
    }
    // Moves every active lane to its next segment and fills tm (midpoints), len (lengths) and live
    // (1/0); false when no lane is active any more.
    bool next() {
        bool any = false;
        for (std::size_t l = 0; l < lanes; ++l) {
            Segment s;
            if (active[l] && !walk[l].next(s)) active[l] = false;
            if (active[l]) {
                tm[l] = s.midpoint();
                len[l] = s.length();
                live[l] = 1.0;
                any = true;
            } else {
                tm[l] = 0.0;
                len[l] = 0.0;
                live[l] = 0.0;
            }
        }
        return any;
    }
};

// Trilinear reconstruction of a regular grid for packets of world points (VolumeSampler::trilinear:
// u = clamp((x - origin) inv_spacing, 0, n - 1), cell min(floor(u), n - 2), Levoy's sum in order).
struct PacketTrilinear {
    const double* voxels;
    V org[3], inv[3], maxi[3], top[3];
    bool flat[3];
    V nx, nxy;
    hn::Vec<DI> offx, offy, offz;

    PacketTrilinear(const double* data, const std::int64_t dims[3], const double origin[3], const double inv_spacing[3]) {
        const D d;
        const DI di;
        voxels = data;
        for (int a = 0; a < 3; ++a) {
            org[a] = hn::Set(d, origin[a]);
            inv[a] = hn::Set(d, inv_spacing[a]);
            maxi[a] = hn::Set(d, double(dims[a] - 1));
            top[a] = hn::Set(d, double(dims[a] - 2));
            flat[a] = dims[a] == 1;
        }
        nx = hn::Set(d, double(dims[0]));
        nxy = hn::Set(d, double(dims[0] * dims[1]));
        offx = hn::Set(di, flat[0] ? 0 : 1);
        offy = hn::Set(di, flat[1] ? 0 : dims[0]);
        offz = hn::Set(di, flat[2] ? 0 : dims[0] * dims[1]);
    }

    HWY_INLINE V operator()(V x, V y, V z) const {
        const D d;
        const DI di;
        const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
        const V X[3] = {x, y, z};
        V cell[3], frac[3];
        for (int a = 0; a < 3; ++a) {
            const V u = hn::Min(hn::Max(hn::Mul(hn::Sub(X[a], org[a]), inv[a]), zero), maxi[a]);
            if (flat[a]) {
                cell[a] = zero;
                frac[a] = zero;
            } else {
                cell[a] = hn::Min(hn::Floor(u), top[a]);
                frac[a] = hn::Sub(u, cell[a]);
            }
        }
        // i + nx j + nx ny k, exact in double.
        const auto idx = hn::Add(hn::ConvertTo(di, hn::Add(cell[0], hn::Mul(nx, cell[1]))),
                                 hn::ConvertTo(di, hn::Mul(nxy, cell[2])));
        const V f1 = hn::GatherIndex(d, voxels, idx);
        const V f2 = hn::GatherIndex(d, voxels, hn::Add(idx, offx));
        const V f3 = hn::GatherIndex(d, voxels, hn::Add(hn::Add(idx, offx), offy));
        const V f4 = hn::GatherIndex(d, voxels, hn::Add(idx, offy));
        const auto idz = hn::Add(idx, offz);
        const V f5 = hn::GatherIndex(d, voxels, idz);
        const V f6 = hn::GatherIndex(d, voxels, hn::Add(idz, offx));
        const V f7 = hn::GatherIndex(d, voxels, hn::Add(hn::Add(idz, offx), offy));
        const V f8 = hn::GatherIndex(d, voxels, hn::Add(idz, offy));
        const V p = frac[0], q = frac[1], r = frac[2];
        const V P = hn::Sub(one, p), Q = hn::Sub(one, q), R = hn::Sub(one, r);
        V v = zero;
        v = hn::Add(v, hn::Mul(f1, hn::Mul(hn::Mul(P, Q), R)));
        v = hn::Add(v, hn::Mul(f2, hn::Mul(hn::Mul(p, Q), R)));
        v = hn::Add(v, hn::Mul(f3, hn::Mul(hn::Mul(p, q), R)));
        v = hn::Add(v, hn::Mul(f4, hn::Mul(hn::Mul(P, q), R)));
        v = hn::Add(v, hn::Mul(f5, hn::Mul(hn::Mul(P, Q), r)));
        v = hn::Add(v, hn::Mul(f6, hn::Mul(hn::Mul(p, Q), r)));
        v = hn::Add(v, hn::Mul(f7, hn::Mul(hn::Mul(p, q), r)));
        v = hn::Add(v, hn::Mul(f8, hn::Mul(hn::Mul(P, q), r)));
        return v;
    }
};

}  // namespace packet
}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
