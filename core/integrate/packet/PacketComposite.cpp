// Highway's per-target compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/integrate/packet/PacketComposite.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <type_traits>

#include "core/Error.h"
#include "core/integrate/march/SpanStates.h"
#include "core/integrate/packet/PacketComposite.h"
#include "core/integrate/packet/PacketKernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using namespace packet;

// A piecewise-linear function of one channel of `ys` (rows of `stride` values) at v, as
// PiecewiseLinear::operator(): k = the number of rows with x <= v; k = 0 -> y_0, k = R -> y_{R-1},
// else y_{k-1} + (v - x_{k-1}) / (x_k - x_{k-1}) (y_k - y_{k-1}).
// Lane types of the kernels below: T = double (reference) or float (fast profile).
template <typename T>
using DT = hn::ScalableTag<T>;
template <typename T>
using VT = hn::Vec<DT<T>>;
template <typename T>
using MT = hn::Mask<DT<T>>;

// TableLookupLanes' index vector for lanes of T.
template <typename T>
using LaneIndex = decltype(hn::IndicesFromVec(DT<T>(), hn::Zero(hn::RebindToSigned<DT<T>>())));

template <typename T>
struct TableLookup {
    VT<T> lo_row, hi_row, lo_x, hi_x;  // row indices as T (exact)
    LaneIndex<T> lo_lane, hi_lane;     // register tables: the rows' lanes (RegisterTable::lane_of), shared by the columns
    VT<T> w;  // (v - x_lo) / (x_hi - x_lo), shared by the channels
    MT<T> below, above;
};

// A table of at most kParts vectors' worth of rows, held in registers (x, and y per channel, in parts
// of one vector each, the last padded with the last row): its rows are picked by TableLookupLanes
// within each part and a select between the parts instead of gathers (the same values; gathers are
// microcoded on AMD's CPUs, and a table of 5 rows is 2 parts on 4 double lanes). More rows: none
// (`in_register` false, the kernels gather).
template <typename T>
struct RegisterTable {
    static constexpr int kParts = 4;
    bool in_register = false;
    int parts = 0;
    VT<T> x[kParts], y[3][kParts];
    RegisterTable(DT<T> d, const T* xs, const T* ys, int rows, int stride) {
        const std::size_t n = hn::Lanes(d);
        if (rows < 1 || std::size_t(rows) > kParts * n) return;
        in_register = true;
        parts = int((std::size_t(rows) + n - 1) / n);
        HWY_ALIGN T buf[hn::MaxLanes(DT<T>())];
        auto row = [&](std::size_t i) { return std::min<std::size_t>(i, std::size_t(rows - 1)); };
        for (int p = 0; p < parts; ++p) {
            for (std::size_t i = 0; i < n; ++i) buf[i] = xs[row(p * n + i)];
            x[p] = hn::Load(d, buf);
            for (int c = 0; c < stride && c < 3; ++c) {
                for (std::size_t i = 0; i < n; ++i) buf[i] = ys[row(p * n + i) * std::size_t(stride) + std::size_t(c)];
                y[c][p] = hn::Load(d, buf);
            }
        }
    }
    // The lane of row `row` (exact integers as T, 0 <= row < rows) within its part: row mod n. The
    // integer is read from the mantissa of row + 2^m (m = 52 for double, 23 for float: the sum is
    // exact and its low bits are row), not by a conversion, which AVX2 lacks for double -> int64.
    static HWY_INLINE LaneIndex<T> lane_of(DT<T> d, VT<T> row) {
        const hn::RebindToSigned<DT<T>> di;
        using TI = hn::TFromD<decltype(di)>;
        constexpr T kMantissaUnit = sizeof(T) == 8 ? T(4503599627370496.0) : T(8388608.0);  // 2^52, 2^23
        const auto bits = hn::BitCast(di, hn::Add(row, hn::Set(d, kMantissaUnit)));
        return hn::IndicesFromVec(d, hn::And(bits, hn::Set(di, TI(hn::Lanes(d) - 1))));
    }
    // Row `row` of the column `v` (x or y[c]), at its lane (lane_of(row)): part row / n, lane row mod n.
    HWY_INLINE VT<T> pick(DT<T> d, const VT<T> (&v)[kParts], VT<T> row, LaneIndex<T> lane) const {
        VT<T> out = hn::TableLookupLanes(v[0], lane);
        for (int p = 1; p < parts; ++p)
            out = hn::IfThenElse(hn::Ge(row, hn::Set(d, T(p * hn::Lanes(d)))), hn::TableLookupLanes(v[p], lane), out);
        return out;
    }
};

// k = the number of rows with x <= v: one compare per row, the count a compile-time R for tables of up
// to 8 rows (the loop unrolled: 2% fewer instructions on the benchmark frame than a runtime bound),
// else `rows` (R = 0).
template <int R, typename T>
HWY_INLINE VT<T> rows_at_or_below(DT<T> d, const T* xs, int rows, VT<T> v) {
    const int n = R > 0 ? R : rows;
    const VT<T> one = hn::Set(d, T(1));
    VT<T> k = hn::Zero(d);
    for (int r = 0; r < n; ++r) k = hn::Add(k, hn::IfThenElseZero(hn::Le(hn::Set(d, xs[r]), v), one));
    return k;
}
template <typename T>
HWY_INLINE VT<T> rows_at_or_below(DT<T> d, const T* xs, int rows, VT<T> v) {
    switch (rows) {
        case 1: return rows_at_or_below<1, T>(d, xs, rows, v);
        case 2: return rows_at_or_below<2, T>(d, xs, rows, v);
        case 3: return rows_at_or_below<3, T>(d, xs, rows, v);
        case 4: return rows_at_or_below<4, T>(d, xs, rows, v);
        case 5: return rows_at_or_below<5, T>(d, xs, rows, v);
        case 6: return rows_at_or_below<6, T>(d, xs, rows, v);
        case 7: return rows_at_or_below<7, T>(d, xs, rows, v);
        case 8: return rows_at_or_below<8, T>(d, xs, rows, v);
        default: return rows_at_or_below<0, T>(d, xs, rows, v);
    }
}

template <typename T>
HWY_INLINE TableLookup<T> locate_rows(DT<T> d, const T* xs, int rows, VT<T> v, const RegisterTable<T>& reg) {
    const hn::RebindToSigned<DT<T>> di;
    const VT<T> k = rows_at_or_below<T>(d, xs, rows, v);
    const VT<T> one = hn::Set(d, T(1));
    TableLookup<T> t;
    t.below = hn::Eq(k, hn::Zero(d));
    t.above = hn::Eq(k, hn::Set(d, T(rows)));
    t.lo_row = hn::Max(hn::Sub(k, one), hn::Zero(d));
    t.hi_row = hn::Min(k, hn::Set(d, T(rows - 1)));
    if (reg.in_register) {
        t.lo_lane = RegisterTable<T>::lane_of(d, t.lo_row);
        t.hi_lane = RegisterTable<T>::lane_of(d, t.hi_row);
        t.lo_x = reg.pick(d, reg.x, t.lo_row, t.lo_lane);
        t.hi_x = reg.pick(d, reg.x, t.hi_row, t.hi_lane);
    } else {
        t.lo_x = hn::GatherIndex(d, xs, hn::ConvertTo(di, t.lo_row));
        t.hi_x = hn::GatherIndex(d, xs, hn::ConvertTo(di, t.hi_row));
    }
    t.w = row_weight<SimdLanes<T>>(v, t.lo_x, t.hi_x);  // PiecewiseLinear's formula (PiecewiseLinear-inl.h)
    return t;
}

template <typename T>
HWY_INLINE VT<T> table_channel(DT<T> d, const TableLookup<T>& t, const T* ys, int rows, int stride, int channel,
                               const RegisterTable<T>& reg) {
    const hn::RebindToSigned<DT<T>> di;
    VT<T> y0, y1;
    if (reg.in_register) {
        y0 = reg.pick(d, reg.y[channel], t.lo_row, t.lo_lane);
        y1 = reg.pick(d, reg.y[channel], t.hi_row, t.hi_lane);
    } else {
        const VT<T> s = hn::Set(d, T(stride)), c = hn::Set(d, T(channel));
        y0 = hn::GatherIndex(d, ys, hn::ConvertTo(di, hn::Add(hn::Mul(t.lo_row, s), c)));
        y1 = hn::GatherIndex(d, ys, hn::ConvertTo(di, hn::Add(hn::Mul(t.hi_row, s), c)));
    }
    const VT<T> inner = between_rows<SimdLanes<T>>(t.w, y0, y1);
    const VT<T> first = hn::Set(d, ys[channel]), last = hn::Set(d, ys[(rows - 1) * stride + channel]);
    return hn::IfThenElse(t.below, first, hn::IfThenElse(t.above, last, inner));
}

// grad f at (x, y, z), where f(x, y, z) = fx, by GradientField's scheme, operation by operation.
template <typename T>
struct PacketGradient {
    using D = DT<T>;
    using V = VT<T>;
    const VolumeView& in;
    const PacketTrilinearT<T>& f;
    const PacketTrilinearT<T>* cached[3];
    const double* shift;  // the fast profile's local coordinates: the domain relative to this; else null

    HWY_INLINE void operator()(const V X[3], V fx, V g[3]) const {
        const D d;
        if (in.gradient == VolumeView::Gradient::Cached) {
            for (int a = 0; a < 3; ++a) g[a] = (*cached[a])(X[0], X[1], X[2]);
            return;
        }
        // GradientField's differences: the same template (GradientDifference-inl.h) on lanes.
        auto field = [&](const V P[3]) HWY_ATTR { return f(P[0], P[1], P[2]); };
        auto at_x = [&]() HWY_ATTR { return fx; };
        const bool central = in.gradient == VolumeView::Gradient::Central;
        for (int a = 0; a < 3; ++a) {
            g[a] = hn::Zero(d);
            if (f.flat[a]) continue;
            const V h = hn::Set(d, T(in.spacing[a]));
            const V lo = hn::Set(d, T(shift ? in.domain_lo[a] - shift[a] : in.domain_lo[a]));
            const V hi = hn::Set(d, T(shift ? in.domain_hi[a] - shift[a] : in.domain_hi[a]));
            g[a] = difference<SimdLanes<T>>(central, X, a, h, lo, hi, field, at_x);
        }
    }
};

// The packet's shading coefficients as the shading template reads them (built once per packet).
HWY_INLINE ShadingConstants shading_constants(const VolumeView& in) {
    ShadingConstants k;
    k.ka = in.ka;
    k.kd = in.kd;
    k.ks = in.ks;
    k.n = in.n;
    k.kc = in.kc;
    k.kl = in.kl;
    k.two_sided = in.two_sided;
    k.phong = in.phong;
    return k;
}

// Shader::shade for a packet (the same template, transfer/Shading-inl.h): m = the material colour,
// g = grad f, view = -direction, depth = t.
template <typename T>
HWY_INLINE void shade(const VolumeView& in, const ShadingConstants& k, VT<T> m[3], const VT<T> g[3],
                      const VT<T> view[3], VT<T> depth) {
    using L = SimdLanes<T>;
    using V = VT<T>;
    auto light_at = [&](int i, V* Ld, double* I) HWY_ATTR {
        const VolumeView::Light& light = in.lights[i];
        for (int c = 0; c < 3; ++c) {
            Ld[c] = light.headlight ? view[c] : L::splat(light.direction[c]);
            I[c] = light.color[c];
        }
    };
    V N[3];
    typename L::M lit;
    shade_lanes<L>(k, in.zero_gradient_tolerance, in.light_count, light_at, m, g, view, depth, N, lit,
                   [](int, const LightLanes<L>&) HWY_ATTR {});
}

// The transfer function's coordinate of the values v: (v - lo) / width on a normalised domain, else v
// (TransferFunction::coordinate).
template <typename T>
HWY_INLINE VT<T> transfer_coordinate(const VolumeView& in, VT<T> v) {
    const DT<T> d;
    return in.normalized ? hn::Mul(hn::Sub(v, hn::Set(d, T(in.lo))), hn::Set(d, T(in.inv_width))) : v;
}

// One pre-integrated segment per lane (transfer/PreIntegration.h; conventions section 9b): the values
// at its ends a = t - len / 2 and b = t + len / 2 (the back end's trilinear sample; the front end's is
// the lane's previous back value where the segment starts within 1e-3 len of where the previous one
// ended, else sampled), their coordinates x_f, x_b, the table read bilinearly at (x_f, x_b) (indices
// clamped to [0, n]), tau = max(sigma_bar, 0) len, and the colour c_bar. Float lanes only.
template <typename T>
struct PreSample {
    hn::Mask<DT<T>> visible;
    VT<T> tau, colour[3];
};

template <typename T, class Trilinear>
HWY_INLINE PreSample<T> pre_sample(const VolumeView& in, const Trilinear& trilinear, VT<T> Ox, VT<T> Oy, VT<T> Oz,
                                   VT<T> Dx, VT<T> Dy, VT<T> Dz, VT<T> t, VT<T> seg, hn::Mask<DT<T>> alive, VT<T>& prev_end,
                                   VT<T>& prev_value) {
    using D = DT<T>;
    using V = VT<T>;
    const D d;
    const hn::RebindToSigned<D> di;
    const V half = hn::Set(d, T(0.5)), zero = hn::Zero(d);
    const V ta = hn::Sub(t, hn::Mul(half, seg)), tb = hn::Add(t, hn::Mul(half, seg));
    const V vb = trilinear(hn::Add(Ox, hn::Mul(tb, Dx)), hn::Add(Oy, hn::Mul(tb, Dy)), hn::Add(Oz, hn::Mul(tb, Dz)));
    const auto joined = hn::Le(hn::Abs(hn::Sub(ta, prev_end)), hn::Mul(hn::Set(d, T(1e-3)), seg));
    V vf = prev_value;
    if (!hn::AllTrue(d, hn::Or(joined, hn::Not(alive)))) {
        const V va = trilinear(hn::Add(Ox, hn::Mul(ta, Dx)), hn::Add(Oy, hn::Mul(ta, Dy)), hn::Add(Oz, hn::Mul(ta, Dz)));
        vf = hn::IfThenElse(joined, prev_value, va);
    }
    prev_end = hn::IfThenElse(alive, tb, prev_end);
    prev_value = hn::IfThenElse(alive, vb, prev_value);
    using SL = SimdLanes<T>;
    const V x0 = hn::Set(d, T(in.pre_x0)), inv_dx = hn::Set(d, T(in.pre_inv_dx)), n = hn::Set(d, T(in.pre_n));
    V i0, j0, wi, wj;
    preintegration_axis<SL>(transfer_coordinate<T>(in, vf), x0, inv_dx, n, i0, wi);
    preintegration_axis<SL>(transfer_coordinate<T>(in, vb), x0, inv_dx, n, j0, wj);
    const int row = 4 * (in.pre_n + 1);
    const auto idx = hn::Add(hn::Mul(hn::ConvertTo(di, i0), hn::Set(di, row)), hn::Mul(hn::ConvertTo(di, j0), hn::Set(di, 4)));
    const auto idx_down = hn::Add(idx, hn::Set(di, row));
    const auto next = hn::Set(di, 4);
    V e[4];
    for (int c = 0; c < 4; ++c) {
        const T* base = in.preintegration + c;
        e[c] = preintegration_blend<SL>(hn::GatherIndex(d, base, idx), hn::GatherIndex(d, base, hn::Add(idx, next)),
                                        hn::GatherIndex(d, base, idx_down), hn::GatherIndex(d, base, hn::Add(idx_down, next)),
                                        wi, wj);
    }
    PreSample<T> s;
    s.tau = hn::Mul(hn::Max(e[0], zero), seg);
    s.visible = hn::And(alive, hn::Gt(s.tau, zero));
    for (int c = 0; c < 3; ++c) s.colour[c] = e[1 + c];
    return s;
}

// A call's constants on this target's lanes (the transfer function's register tables, the samplers,
// the shading constants, the skipping grid's), built once per call to CompositePacket and shared by its
// packets.
template <typename T>
struct CompositeShared {
    static constexpr bool kFast = std::is_same_v<T, float>;
    const VolumeView& in;
    const PacketRun& run;
    const TransferRows<T>& tab;
    const GridView& grid;  // the lanes' voxels (VolumeView::grid_of)
    // Float lanes work in coordinates local to the volume (RayPacketT): positions relative to its origin.
    const double* local;
    double zero_origin[3] = {0.0, 0.0, 0.0};
    const double* origin;
    const bool pre;  // pre-integrated segments (FastProfile.h)
    VectorSkip vskip;  // skipping decided on the lanes (PacketKernels-inl.h), in the lanes' coordinates
    const PacketTrilinearT<T> trilinear;
    // The cached gradient components share the volume's grid (built only where the gradient is cached).
    PacketTrilinearT<T> component[3];  // unset unless cached
    const PacketGradient<T> gradient;
    const ShadingConstants shading;
    const RegisterTable<T> opacity_reg, color_reg, gradient_reg;
    // The opacity correction's d / l (sample_opacity) as (d (1 / l)) / 1 on float lanes, 1 / l rounded to
    // float once (conventions section 9b: no division per step); d / l itself on double lanes.
    const T segment_scale, unit_distance;

    CompositeShared(const VolumeView& inputs, const PacketRun& settings)
        : in(inputs),
          run(settings),
          tab(inputs.rows_of<T>()),
          grid(inputs.grid_of<T>()),
          local(kFast ? grid.origin : nullptr),
          origin(kFast ? zero_origin : grid.origin),
          pre(kFast && inputs.preintegration != nullptr),
          trilinear(grid.voxels, grid.voxel_type, grid.dims, origin, grid.inv_spacing),
          gradient{inputs, trilinear, {&component[0], &component[1], &component[2]}, local},
          shading(shading_constants(inputs)),
          opacity_reg(DT<T>(), tab.opacity_x, tab.opacity_y, inputs.opacity_rows, 1),
          color_reg(DT<T>(), tab.color_x, tab.color_y, inputs.color_rows, 3),
          gradient_reg(DT<T>(), tab.gradient_opacity_x, tab.gradient_opacity_y, inputs.gradient_opacity_rows, 1),
          segment_scale(kFast ? T(1.0 / inputs.unit_distance) : T(1)),
          unit_distance(kFast ? T(1) : T(inputs.unit_distance)) {
        if (skips()) {
            vskip.radius = in.skip_radius;
            for (int a = 0; a < 3; ++a) {
                vskip.counts[a] = run.macrocells->counts()[a];
                vskip.dims[a] = grid.dims[a];
                vskip.origin[a] = origin[a];
                vskip.inv_spacing[a] = grid.inv_spacing[a];
            }
            vskip.end_margin = pre ? 0.5 * run.step : 0.0;
        }
        if (in.gradient == VolumeView::Gradient::Cached)
            for (int a = 0; a < 3; ++a)
                component[a] = PacketTrilinearT<T>(tab.cached_gradient[a], kFast ? ScalarType::F32 : ScalarType::F64, grid.dims,
                                                   origin, grid.inv_spacing);
    }
    // Skipping decided on the lanes: the run's macrocells with the view's radii.
    bool skips() const { return run.macrocells && in.skip_radius; }
    CompositeShared(const CompositeShared&) = delete;
    CompositeShared& operator=(const CompositeShared&) = delete;
};

// A sample for composite_step (march/Accumulators-inl.h) from two callables: opacity() and colour(m).
template <class Opacity, class Colour>
struct LaneSample {  // (a reference to each: the step's locals stay the step's)
    Opacity& opacity_of;
    Colour& colour_of;
    HWY_INLINE auto opacity() { return opacity_of(); }
    template <class V>
    HWY_INLINE void colour(V m[3]) { colour_of(m); }
};

// One packet's front-to-back march: constructed (its lanes' states in), stepped (step(): one step of
// every lane, or run_preintegrated()), then finish() (its lanes' values or states out). A packet is a
// value of its own, so that CompositePacket can interleave two packets' steps (composite_all).
template <typename T>
class CompositeLanes {
    using D = DT<T>;
    using V = VT<T>;
    using M = MT<T>;
    static constexpr bool kFast = std::is_same_v<T, float>;
    using SL = SimdLanes<T>;
    // The reference composites with the compensated optical depth, the fast profile with a
    // transmittance product in float (march/Accumulators.h).
    static constexpr TransmittanceRule kRule = kFast ? TransmittanceRule::Product : TransmittanceRule::OpticalDepthSum;
    static constexpr int kState = FrontToBack<SL, kRule>::kStateValues;
    // Float lanes request the voxels kPrefetchSteps segments ahead of each step they fetch, along the
    // ray (p + 4 len d: where the lane will be unless it skips or its interval ends), for every
    // kPrefetchLaneStride-th lane: lanes 0, 5, 10, 15 of a 4 x 4 packet, its diagonal (neighbouring
    // lanes read mostly the same cache lines). The one-step-ahead fetch hides what the core's reorder
    // window can hold; these hints retire at once. Measured (the variants: docs/performance.md,
    // "What did not help"): 3-5% on the fast profile's frame; every lane instead (64 hints a step) or 2
    // steps ahead: slower.
    static constexpr int kPrefetchSteps = 4;
    static constexpr int kPrefetchLaneStride = 5;

public:
    CompositeLanes(const CompositeShared<T>& shared, const Ray* rays, const std::vector<Interval>* intervals, PixelValue* out,
                   int count, const RaySpan* spans, RayState* states)
        : s_(shared),
          in_(shared.in),
          packet_(rays, intervals, count, shared.run.step, shared.run.macrocells, nullptr, true, shared.local, spans,
                  shared.skips() ? &shared.vskip : nullptr),
          out_(out),
          count_(count),
          states_(states) {
        const D d;
        L_ = packet_.lanes;
        O_[0] = hn::Load(d, packet_.ox);
        O_[1] = hn::Load(d, packet_.oy);
        O_[2] = hn::Load(d, packet_.oz);
        D_[0] = hn::Load(d, packet_.dx);
        D_[1] = hn::Load(d, packet_.dy);
        D_[2] = hn::Load(d, packet_.dz);
        t_ref_ = hn::Load(d, packet_.t_ref_lane);  // 0 on double lanes
        for (int a = 0; a < 3; ++a) view_[a] = hn::Neg(D_[a]);
        done_ = hn::FirstN(d, 0);
        // Resuming (march/SpanStates.h, composite_state): each lane's FrontToBack state in; a stopped ray
        // takes no sample. (The reference's composite_state, the fast profile's product_state.)
        if (states_) {
            V init[kState];
            for (int k = 0; k < kState; ++k) {
                for (std::size_t l = 0; l < L_; ++l)
                    buf_[l] = int(l) < count_ ? T(kFast ? product_state::load_value(states_[l], k) : states_[l].v[k]) : T(kFast && k == 0);
                init[k] = hn::Load(d, buf_);
            }
            for (std::size_t l = 0; l < L_; ++l) buf_[l] = int(l) < count_ && states_[l].v[8] != 0.0 ? T(1) : T(0);
            acc_.load(init, hn::Gt(hn::Load(d, buf_), hn::Zero(d)));
            for (int l = 0; l < count_ && l < int(L_); ++l)
                if (states_[l].stopped != 0.0) {
                    stopped_[l] = true;
                    packet_.retire(std::size_t(l));
                }
        }
        if (!s_.pre) have_ = fetch(steps_[0]);
    }
    CompositeLanes(const CompositeLanes&) = delete;
    CompositeLanes& operator=(const CompositeLanes&) = delete;

    // Pre-integrated segments, the whole packet: each lane's last segment's back end (t, -inf before
    // the first) and value carried from step to step.
    void run_preintegrated() {
        if constexpr (kFast) {  // (pre is false on double lanes)
            const D d;
            V prev_end = hn::Set(d, -std::numeric_limits<T>::infinity()), prev_value = hn::Zero(d);
            while (packet_.next()) {
                const V t = hn::Load(d, packet_.tm), seg = hn::Load(d, packet_.len);
                const M alive = hn::Gt(hn::Load(d, packet_.live), hn::Zero(d));
                const PreSample<T> p = pre_sample<T>(in_, s_.trilinear, O_[0], O_[1], O_[2], D_[0], D_[1], D_[2], t, seg, alive,
                                                     prev_end, prev_value);
                if (hn::AllFalse(d, p.visible)) continue;
                const V alpha = segment_alpha<SL>(p.tau);
                acc_.add(p.visible, hn::FirstN(d, 0), p.tau, alpha, p.colour);  // never solid: a < 1
                retire(acc_.stops(p.visible, s_.run.termination));
            }
        }
    }

    // One step of every lane; false when the packet is done. Pipelined by one step: the next step is
    // placed and its voxels fetched before this step is classified and composited, so that the fetch's
    // latency overlaps this step's work (the branches below depend on the values). A lane that stops in
    // this step has its next step fetched already; `done_` masks it out. Each lane takes the same
    // samples in the same order.
    HWY_INLINE bool step() {
        if (!have_) return false;
        const D d;
        const Step& cur = steps_[current_];
        const bool have_next = fetch(steps_[current_ ^ 1]);
        const M alive = hn::AndNot(done_, cur.alive);
        // The one composite step (composite_step, march/Accumulators-inl.h) on these lanes: its sample's
        // opacity is the transfer function's at the value (times the gradient-magnitude factor, clamped
        // to [0, 1], where the function has one), its colour the colour rows at the same coordinate,
        // shaded where the scene shades; the gradient is computed once, by whichever needs it first.
        // They are lambdas over this step's locals, always inlined: written as a struct holding the
        // sample's state, the kernel ran 13% more instructions (valgrind's count on the benchmark's
        // composite) and 7% longer.
        const V v = cur.v;
        const TransferRows<T>& tab = s_.tab;
        V x, g[3];
        bool have_gradient = false;
        auto opacity = [&]() HWY_ATTR __attribute__((always_inline)) {
            x = transfer_coordinate<T>(in_, v);
            const TableLookup<T> ot = locate_rows(d, tab.opacity_x, in_.opacity_rows, x, s_.opacity_reg);
            V a = table_channel(d, ot, tab.opacity_y, in_.opacity_rows, 1, 0, s_.opacity_reg);
            if (in_.gradient_opacity_rows > 0) {
                // a = clamp(a factor(|grad f|), 0, 1)
                s_.gradient(cur.P, v, g);
                have_gradient = true;
                const V glen = hn::Sqrt(dot3<SL>(g, g));
                const TableLookup<T> gt = locate_rows(d, tab.gradient_opacity_x, in_.gradient_opacity_rows, glen, s_.gradient_reg);
                const V factor = table_channel(d, gt, tab.gradient_opacity_y, in_.gradient_opacity_rows, 1, 0, s_.gradient_reg);
                a = hn::Min(hn::Max(hn::Mul(a, factor), hn::Zero(d)), hn::Set(d, T(1)));
            }
            return a;
        };
        auto colour = [&](V m[3]) HWY_ATTR __attribute__((always_inline)) {
            const TableLookup<T> ct = locate_rows(d, tab.color_x, in_.color_rows, x, s_.color_reg);
            m[0] = table_channel(d, ct, tab.color_y, in_.color_rows, 3, 0, s_.color_reg);
            m[1] = table_channel(d, ct, tab.color_y, in_.color_rows, 3, 1, s_.color_reg);
            m[2] = table_channel(d, ct, tab.color_y, in_.color_rows, 3, 2, s_.color_reg);
            if (in_.shaded) {
                if (!have_gradient) s_.gradient(cur.P, v, g);
                shade<T>(in_, s_.shading, m, g, view_, kFast ? hn::Add(cur.t, t_ref_) : cur.t);  // depth: the world t
            }
        };
        LaneSample<decltype(opacity), decltype(colour)> sample{opacity, colour};
        const V seg = kFast ? hn::Mul(cur.seg, hn::Set(d, s_.segment_scale)) : cur.seg;
        LanesHooks hooks;
        const M stop = packet::composite_step<SL>(acc_, sample, alive, seg, hn::Set(d, s_.unit_distance), &s_.run.termination, hooks);
        if (hooks.visible) retire(stop);
        current_ ^= 1;  // the step fetched ahead is the current one
        have_ = have_next;
        return have_;
    }

    // Each lane's value (or, resuming, its state) out.
    void finish() {
        const D d;
        if (states_) {  // each lane's state out
            V saved[kState];
            M opaque;
            acc_.save(saved, opaque);
            for (int k = 0; k < kState; ++k) {
                hn::Store(saved[k], d, buf_);
                for (int l = 0; l < count_ && l < int(L_); ++l) states_[l].v[k] = double(buf_[l]);
            }
            hn::Store(hn::IfThenElseZero(opaque, hn::Set(d, T(1))), d, buf_);
            for (int l = 0; l < count_ && l < int(L_); ++l) {
                states_[l].v[8] = buf_[l] != T(0) ? 1.0 : 0.0;
                states_[l].stopped = stopped_[l] ? 1.0 : 0.0;
                if constexpr (kFast) states_[l].v[9] = 1.0;  // holds a T
            }
            return;
        }
        const V A = acc_.alpha();
        const V Cr = acc_.color(0), Cg = acc_.color(1), Cb = acc_.color(2);
        HWY_ALIGN T r_[RayPacketT<T>::kLanes], g_[RayPacketT<T>::kLanes], b_[RayPacketT<T>::kLanes], a_[RayPacketT<T>::kLanes];
        hn::Store(Cr, d, r_);
        hn::Store(Cg, d, g_);
        hn::Store(Cb, d, b_);
        hn::Store(A, d, a_);
        for (int l = 0; l < count_ && l < int(L_); ++l) out_[l].rgba = glm::dvec4(r_[l], g_[l], b_[l], a_[l]);
    }

private:
    // One step of every lane: its segment (midpoint t, length seg), the live lanes, the sample
    // position and the reconstructed value.
    struct Step {
        V t, seg, P[3], v;
        M alive;
    };
    // composite_step's hooks: whether some lane took a visible sample (only then can one retire).
    struct LanesHooks {
        bool visible = false;
        template <class Acc>
        HWY_INLINE void transparent(const Acc&) { visible = false; }
        template <class O, class Acc>
        HWY_INLINE void composited(const O&, const Acc&) { visible = true; }
    };
    HWY_INLINE bool fetch(Step& st) {
        if (!packet_.next()) return false;
        const D d;
        st.t = hn::Load(d, packet_.tm);
        st.seg = hn::Load(d, packet_.len);
        st.alive = hn::Gt(hn::Load(d, packet_.live), hn::Zero(d));
        for (int a = 0; a < 3; ++a) st.P[a] = hn::Add(O_[a], hn::Mul(st.t, D_[a]));
        if constexpr (kFast) {  // a hint for a later step (kPrefetchSteps)
            const V ahead = hn::Mul(hn::Set(d, T(kPrefetchSteps)), st.seg);
            s_.trilinear.template prefetch<kPrefetchLaneStride>(hn::MulAdd(ahead, D_[0], st.P[0]), hn::MulAdd(ahead, D_[1], st.P[1]),
                                                                hn::MulAdd(ahead, D_[2], st.P[2]));
        }
        st.v = s_.trilinear(st.P[0], st.P[1], st.P[2]);
        return true;
    }
    // The lanes in `stop` (opaque, terminated) take no more samples; `done_` holds them as a mask for
    // a step already placed and fetched before they stopped.
    HWY_INLINE void retire(M stop) {
        const D d;
        if (hn::AllFalse(d, stop)) return;
        done_ = hn::Or(done_, stop);
        hn::Store(hn::IfThenElseZero(stop, hn::Set(d, T(1))), d, buf_);
        for (std::size_t l = 0; l < L_; ++l)
            if (buf_[l] != T(0)) {
                stopped_[l] = true;
                packet_.retire(l);
            }
    }

    const CompositeShared<T>& s_;
    const VolumeView& in_;
    RayPacketT<T> packet_;
    PixelValue* out_;
    int count_;
    RayState* states_;
    std::size_t L_ = 0;
    V O_[3], D_[3], t_ref_, view_[3];
    FrontToBack<SL, kRule> acc_;
    bool stopped_[RayPacketT<T>::kLanes] = {};
    M done_;
    Step steps_[2];  // the current step (current_) and the one fetched ahead
    int current_ = 0;
    bool have_ = false;
    HWY_ALIGN T buf_[RayPacketT<T>::kLanes];
};

}  // namespace

// The voxels of each ray's first sample, requested before the packets are built (float lanes, whole
// rays). A prefetch retires at once, so the cache misses of a block's first samples (cold: nothing
// read them before in this frame) overlap with one another and with the packets' set-up; the loads
// themselves would hold up the core's reorder window. The cell of the first segment's midpoint
// t = (t0 + min(t0 + h, t1)) / 2 of the first interval (SamplePlacement.h; where the march samples
// first unless skipping moves it on), its four x-rows (y, z and their next): a hint, nothing is read.
// Measured (the variants: docs/performance.md, "What did not help"): 2-5% on the fast
// profile's frame, nothing on the reference's (double lanes, which do not take it), nothing more from
// the second sample as well.
HWY_INLINE void prefetch_first_samples(const GridView& grid, double step, const Ray* rays, const std::vector<Interval>* intervals,
                                       int count) {
    const auto* voxels = static_cast<const unsigned char*>(grid.voxels);
    if (!voxels) return;
    const std::int64_t bytes = std::int64_t(scalar_type_size(grid.voxel_type));
    const std::int64_t stride[3] = {bytes, bytes * grid.dims[0], bytes * grid.dims[0] * grid.dims[1]};
    for (int i = 0; i < count; ++i) {
        if (intervals[i].empty()) continue;
        const Interval& iv = intervals[i].front();
        const double t = 0.5 * (iv.t0 + std::min(iv.t0 + step, iv.t1));
        std::int64_t offset = 0;
        for (int a = 0; a < 3; ++a) {
            const double u = (rays[i].origin[a] + t * rays[i].direction[a] - grid.origin[a]) * grid.inv_spacing[a];
            const double top = double(std::max<std::int64_t>(grid.dims[a] - 2, 0));
            offset += std::int64_t(u > 0.0 ? std::min(u, top) : 0.0) * stride[a];  // (NaN: 0)
        }
        const unsigned char* q = voxels + offset;
        __builtin_prefetch(q);
        __builtin_prefetch(q + stride[1]);
        __builtin_prefetch(q + stride[2]);
        __builtin_prefetch(q + stride[2] + stride[1]);
    }
}

// The packets of `count` rays. Float lanes (the fast profile): two at a time, their steps interleaved (a
// packet's next step waits on its voxels and its skipping grid's cells; the other's work fills that
// wait). Double lanes (the reference), and pre-integrated segments: one packet after the other. Each
// packet's lanes take the same samples in the same order either way. Measured (more in flight: docs/performance.md,
// "What did not help"): on float lanes 2 in flight 2-3% faster than
// 1 and 4 slower; on double lanes 2 in flight 4% slower than 1 (twice the packets of a block, each
// twice the state).
template <typename T>
constexpr int kInFlight = std::is_same_v<T, float> ? 2 : 1;
template <typename T>
void composite_all(const VolumeView& in, const PacketRun& run, const Ray* rays, const std::vector<Interval>* intervals,
                   PixelValue* out, int count, const RaySpan* spans, RayState* states) {
    const int L = int(hn::Lanes(DT<T>()));
    const CompositeShared<T> shared(in, run);
    const int packets = (count + L - 1) / L;
    auto make = [&](std::optional<CompositeLanes<T>>& slot, int p) HWY_ATTR {
        const int first = p * L;
        slot.emplace(shared, rays + first, intervals + first, out ? out + first : nullptr, std::min(L, count - first),
                     spans ? spans + first : nullptr, states ? states + first : nullptr);
    };
    if (shared.pre) {
        for (int p = 0; p < packets; ++p) {
            std::optional<CompositeLanes<T>> job;
            make(job, p);
            job->run_preintegrated();
            job->finish();
        }
        return;
    }
    if (std::is_same_v<T, float> && !spans) prefetch_first_samples(shared.grid, run.step, rays, intervals, count);
    std::optional<CompositeLanes<T>> slot[kInFlight<T>];
    int next = 0;
    for (auto& s : slot)
        if (next < packets) make(s, next++);
    auto any = [&]() {
        for (auto& s : slot)
            if (s) return true;
        return false;
    };
    while (any())
        for (auto& s : slot)
            if (s && !s->step()) {
                s->finish();
                s.reset();
                if (next < packets) make(s, next++);
            }
}

void CompositePacket(const VolumeView& in, const PacketRun& run, const Ray* rays, const std::vector<Interval>* intervals,
                     PixelValue* out, int count, const RaySpan* spans, RayState* states) {
    on_lanes(run.fast, [&]<typename T>() HWY_ATTR { composite_all<T>(in, run, rays, intervals, out, count, spans, states); });
}

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace volref {
HWY_EXPORT(CompositePacket);

void composite_packet(const VolumeView& in, const PacketRun& run, const Ray* rays, const std::vector<Interval>* intervals,
                      PixelValue* out, int count, const RaySpan* spans, RayState* states) {
    HWY_DYNAMIC_DISPATCH(CompositePacket)(in, run, rays, intervals, out, count, spans, states);
}
}  // namespace volref
#endif
