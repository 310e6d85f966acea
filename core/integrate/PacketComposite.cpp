// Highway's per-target compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/integrate/PacketComposite.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include "core/integrate/PacketComposite.h"
#include "core/integrate/Segments.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using D = hn::ScalableTag<double>;
using DI = hn::RebindToSigned<D>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// A piecewise-linear function of one channel of `ys` (rows of `stride` values) at v, as
// PiecewiseLinear::operator(): k = the number of rows with x <= v; k = 0 -> y_0, k = R -> y_{R-1},
// else y_{k-1} + (v - x_{k-1}) / (x_k - x_{k-1}) (y_k - y_{k-1}).
struct TableLookup {
    V lo_row, hi_row, lo_x, hi_x;  // row indices as doubles (exact)
    M below, above;
};

HWY_INLINE TableLookup locate_rows(D d, const double* xs, int rows, V v) {
    const DI di;
    V k = hn::Zero(d);
    const V one = hn::Set(d, 1.0);
    for (int r = 0; r < rows; ++r) k = hn::Add(k, hn::IfThenElseZero(hn::Le(hn::Set(d, xs[r]), v), one));
    TableLookup t;
    t.below = hn::Eq(k, hn::Zero(d));
    t.above = hn::Eq(k, hn::Set(d, double(rows)));
    t.lo_row = hn::Max(hn::Sub(k, one), hn::Zero(d));
    t.hi_row = hn::Min(k, hn::Set(d, double(rows - 1)));
    t.lo_x = hn::GatherIndex(d, xs, hn::ConvertTo(di, t.lo_row));
    t.hi_x = hn::GatherIndex(d, xs, hn::ConvertTo(di, t.hi_row));
    return t;
}

HWY_INLINE V table_channel(D d, const TableLookup& t, const double* ys, int rows, int stride, int channel, V v) {
    const DI di;
    const V s = hn::Set(d, double(stride)), c = hn::Set(d, double(channel));
    const V y0 = hn::GatherIndex(d, ys, hn::ConvertTo(di, hn::Add(hn::Mul(t.lo_row, s), c)));
    const V y1 = hn::GatherIndex(d, ys, hn::ConvertTo(di, hn::Add(hn::Mul(t.hi_row, s), c)));
    const V w = hn::Div(hn::Sub(v, t.lo_x), hn::Sub(t.hi_x, t.lo_x));
    const V inner = hn::Add(y0, hn::Mul(w, hn::Sub(y1, y0)));
    const V first = hn::Set(d, ys[channel]), last = hn::Set(d, ys[(rows - 1) * stride + channel]);
    return hn::IfThenElse(t.below, first, hn::IfThenElse(t.above, last, inner));
}

// One lane's walk over its intervals and segments.
struct LaneWalk {
    const std::vector<Interval>* intervals = nullptr;
    std::size_t interval = 0;
    std::int64_t k = 0, n = 0;
    bool active = false;

    void start(const std::vector<Interval>* ivs, double step) {
        intervals = ivs;
        interval = 0;
        active = !ivs->empty();
        if (active) {
            k = 0;
            n = segment_count((*ivs)[0], step);
        }
    }
    Segment current(double step) const { return segment((*intervals)[interval], step, k, n); }
    void advance(double step) {
        if (++k < n) return;
        if (++interval < intervals->size()) {
            k = 0;
            n = segment_count((*intervals)[interval], step);
        } else {
            active = false;
        }
    }
};

void composite_lanes(const PacketCompositeInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                     PixelValue* out, int count) {
    const D d;
    const DI di;
    constexpr std::size_t kLanes = HWY_LANES(double);
    const std::size_t L = hn::Lanes(d);
    HWY_ALIGN double ox[kLanes], oy[kLanes], oz[kLanes], dx[kLanes], dy[kLanes], dz[kLanes];
    HWY_ALIGN double tm[kLanes], len[kLanes], live[kLanes], buf[kLanes];
    LaneWalk walk[kLanes];
    for (std::size_t l = 0; l < L; ++l) {
        const bool real = int(l) < count;
        const Ray& r = rays[real ? l : 0];
        ox[l] = r.origin.x;
        oy[l] = r.origin.y;
        oz[l] = r.origin.z;
        dx[l] = r.direction.x;
        dy[l] = r.direction.y;
        dz[l] = r.direction.z;
        walk[l] = LaneWalk{};
        if (real) walk[l].start(&intervals[l], in.step);
    }
    const V Ox = hn::Load(d, ox), Oy = hn::Load(d, oy), Oz = hn::Load(d, oz);
    const V Dx = hn::Load(d, dx), Dy = hn::Load(d, dy), Dz = hn::Load(d, dz);

    const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
    const V org[3] = {hn::Set(d, in.origin[0]), hn::Set(d, in.origin[1]), hn::Set(d, in.origin[2])};
    const V inv[3] = {hn::Set(d, in.inv_spacing[0]), hn::Set(d, in.inv_spacing[1]), hn::Set(d, in.inv_spacing[2])};
    V maxi[3], top[3];
    bool flat[3];
    for (int a = 0; a < 3; ++a) {
        maxi[a] = hn::Set(d, double(in.dims[a] - 1));
        top[a] = hn::Set(d, double(in.dims[a] - 2));
        flat[a] = in.dims[a] == 1;
    }
    const V nx = hn::Set(d, double(in.dims[0])), nxy = hn::Set(d, double(in.dims[0] * in.dims[1]));
    const std::int64_t sx = flat[0] ? 0 : 1, sy = flat[1] ? 0 : in.dims[0], sz = flat[2] ? 0 : in.dims[0] * in.dims[1];
    const auto offx = hn::Set(di, sx), offy = hn::Set(di, sy), offz = hn::Set(di, sz);

    V Cr = zero, Cg = zero, Cb = zero, tau_s = zero, tau_c = zero, opaque = zero;
    const V l_unit = hn::Set(d, in.unit_distance);
    const V threshold = hn::Set(d, in.threshold);

    for (;;) {
        bool any = false;
        for (std::size_t l = 0; l < L; ++l) {
            if (walk[l].active) {
                const Segment s = walk[l].current(in.step);
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
        if (!any) break;
        const V t = hn::Load(d, tm), seg = hn::Load(d, len);
        const M alive = hn::Gt(hn::Load(d, live), zero);

        // Position, continuous index (clamped), cell and fraction.
        const V X[3] = {hn::Add(Ox, hn::Mul(t, Dx)), hn::Add(Oy, hn::Mul(t, Dy)), hn::Add(Oz, hn::Mul(t, Dz))};
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
        const auto base = hn::ConvertTo(di, hn::Add(cell[0], hn::Mul(nx, cell[1])) /* i + nx j */);
        const auto idx = hn::Add(base, hn::ConvertTo(di, hn::Mul(nxy, cell[2])));
        const double* vox = in.voxels;
        const V f1 = hn::GatherIndex(d, vox, idx);
        const V f2 = hn::GatherIndex(d, vox, hn::Add(idx, offx));
        const V f3 = hn::GatherIndex(d, vox, hn::Add(hn::Add(idx, offx), offy));
        const V f4 = hn::GatherIndex(d, vox, hn::Add(idx, offy));
        const auto idz = hn::Add(idx, offz);
        const V f5 = hn::GatherIndex(d, vox, idz);
        const V f6 = hn::GatherIndex(d, vox, hn::Add(idz, offx));
        const V f7 = hn::GatherIndex(d, vox, hn::Add(hn::Add(idz, offx), offy));
        const V f8 = hn::GatherIndex(d, vox, hn::Add(idz, offy));
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

        // Transfer function.
        const V x = in.normalized ? hn::Mul(hn::Sub(v, hn::Set(d, in.lo)), hn::Set(d, in.inv_width)) : v;
        const TableLookup ot = locate_rows(d, in.opacity_x, in.opacity_rows, x);
        const V a = table_channel(d, ot, in.opacity_y, in.opacity_rows, 1, 0, x);
        const M visible = hn::And(alive, hn::Gt(a, zero));
        if (!hn::AllFalse(d, visible)) {
            const TableLookup ct = locate_rows(d, in.color_x, in.color_rows, x);
            const V cr = table_channel(d, ct, in.color_y, in.color_rows, 3, 0, x);
            const V cg = table_channel(d, ct, in.color_y, in.color_rows, 3, 1, x);
            const V cb = table_channel(d, ct, in.color_y, in.color_rows, 3, 2, x);
            const V T = hn::Exp(d, hn::Neg(hn::Add(tau_s, tau_c)));
            const M solid = hn::And(visible, hn::Ge(a, one));
            const M partial = hn::AndNot(solid, visible);
            // Partial: tau_k = -(d / l) log1p(-a), alpha = -expm1(-tau_k); opaque: alpha = 1.
            const V tau_k = hn::Mul(hn::Neg(hn::Div(seg, l_unit)), hn::Log1p(d, hn::Neg(hn::IfThenElseZero(partial, a))));
            const V alpha = hn::IfThenElse(solid, one, hn::Neg(hn::Expm1(d, hn::Neg(tau_k))));
            const V w = hn::IfThenElseZero(visible, hn::Mul(T, alpha));
            Cr = hn::Add(Cr, hn::IfThenElseZero(visible, hn::Mul(w, cr)));
            Cg = hn::Add(Cg, hn::IfThenElseZero(visible, hn::Mul(w, cg)));
            Cb = hn::Add(Cb, hn::IfThenElseZero(visible, hn::Mul(w, cb)));
            // Neumaier: t = s + x; c += |s| >= |x| ? (s - t) + x : (x - t) + s; s = t.
            const V sum = hn::Add(tau_s, tau_k);
            const V comp = hn::IfThenElse(hn::Ge(hn::Abs(tau_s), hn::Abs(tau_k)), hn::Add(hn::Sub(tau_s, sum), tau_k),
                                          hn::Add(hn::Sub(tau_k, sum), tau_s));
            tau_c = hn::IfThenElse(partial, hn::Add(tau_c, comp), tau_c);
            tau_s = hn::IfThenElse(partial, sum, tau_s);
            opaque = hn::IfThenElse(solid, one, opaque);
            M stop = solid;
            if (in.terminate)
                stop = hn::Or(stop, hn::And(partial, hn::Gt(hn::Neg(hn::Expm1(d, hn::Neg(hn::Add(tau_s, tau_c)))), threshold)));
            hn::Store(hn::IfThenElseZero(stop, one), d, buf);
            for (std::size_t l = 0; l < L; ++l)
                if (buf[l] != 0.0) walk[l].active = false;
        }
        for (std::size_t l = 0; l < L; ++l)
            if (walk[l].active) walk[l].advance(in.step);
    }
    const V A = hn::IfThenElse(hn::Gt(opaque, zero), one, hn::Neg(hn::Expm1(d, hn::Neg(hn::Add(tau_s, tau_c)))));
    HWY_ALIGN double r_[kLanes], g_[kLanes], b_[kLanes], a_[kLanes];
    hn::Store(Cr, d, r_);
    hn::Store(Cg, d, g_);
    hn::Store(Cb, d, b_);
    hn::Store(A, d, a_);
    for (int l = 0; l < count && l < int(L); ++l) out[l].rgba = glm::dvec4(r_[l], g_[l], b_[l], a_[l]);
}

}  // namespace

void CompositePacket(const PacketCompositeInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                     PixelValue* out, int count) {
    const int L = int(hn::Lanes(D()));
    for (int first = 0; first < count; first += L)
        composite_lanes(in, rays + first, intervals + first, out + first, std::min(L, count - first));
}

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace volref {
HWY_EXPORT(CompositePacket);

void composite_packet(const PacketCompositeInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                      PixelValue* out, int count) {
    HWY_DYNAMIC_DISPATCH(CompositePacket)(in, rays, intervals, out, count);
}
}  // namespace volref
#endif
