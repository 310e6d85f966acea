// Highway's per-target compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/integrate/PacketComposite.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include "core/integrate/PacketComposite.h"
#include "core/integrate/PacketKernels-inl.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using namespace packet;

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

// grad f at (x, y, z), where f(x, y, z) = fx, by GradientField's scheme, operation by operation.
struct PacketGradient {
    const PacketCompositeInputs& in;
    const PacketTrilinear& f;
    const PacketTrilinear* cached[3];

    HWY_INLINE void operator()(const V X[3], V fx, V g[3]) const {
        const D d;
        if (in.gradient == PacketCompositeInputs::Gradient::Cached) {
            for (int a = 0; a < 3; ++a) g[a] = (*cached[a])(X[0], X[1], X[2]);
            return;
        }
        for (int a = 0; a < 3; ++a) {
            g[a] = hn::Zero(d);
            if (f.flat[a]) continue;
            const V h = hn::Set(d, in.spacing[a]), lo = hn::Set(d, in.domain_lo[a]), hi = hn::Set(d, in.domain_hi[a]);
            const V c = hn::Max(hn::Sub(X[a], h), lo);
            V P[3] = {X[0], X[1], X[2]};
            if (in.gradient == PacketCompositeInputs::Gradient::Central) {
                const V b = hn::Min(hn::Add(X[a], h), hi);
                P[a] = b;
                const V fb = f(P[0], P[1], P[2]);
                P[a] = c;
                const V fc = f(P[0], P[1], P[2]);
                g[a] = hn::Div(hn::Sub(fb, fc), hn::Sub(b, c));
            } else {  // forward where x + h <= hi, else backward over x - c
                const V xh = hn::Add(X[a], h);
                P[a] = xh;
                const V forward = hn::Div(hn::Sub(f(P[0], P[1], P[2]), fx), h);
                P[a] = c;
                const V backward = hn::Div(hn::Sub(fx, f(P[0], P[1], P[2])), hn::Sub(X[a], c));
                g[a] = hn::IfThenElse(hn::Le(xh, hi), forward, backward);
            }
        }
    }
};

HWY_INLINE V dot3(const V a[3], const V b[3]) {
    return hn::Add(hn::Add(hn::Mul(a[0], b[0]), hn::Mul(a[1], b[1])), hn::Mul(a[2], b[2]));
}

// Shader::shade for a packet: m = the material colour, g = grad f, view = -direction, depth = t.
HWY_INLINE void shade(const PacketCompositeInputs& in, V m[3], const V g[3], const V view[3], V depth) {
    const D d;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
    const V glen = hn::Sqrt(dot3(g, g));
    const M lit = hn::Gt(glen, hn::Set(d, in.zero_gradient_tolerance));
    if (hn::AllFalse(d, lit)) return;
    const V N[3] = {hn::Div(hn::Neg(g[0]), glen), hn::Div(hn::Neg(g[1]), glen), hn::Div(hn::Neg(g[2]), glen)};
    auto clamp_dot = [&](V x) { return in.two_sided ? hn::Abs(x) : hn::Max(x, zero); };
    const V cue = hn::Div(one, hn::Add(hn::Set(d, in.kc), hn::Mul(hn::Set(d, in.kl), depth)));
    V out[3] = {zero, zero, zero};
    for (int li = 0; li < in.light_count; ++li) {
        const PacketCompositeInputs::Light& light = in.lights[li];
        V L[3];
        for (int c = 0; c < 3; ++c) L[c] = light.headlight ? view[c] : hn::Set(d, light.direction[c]);
        const V n_dot_l_raw = dot3(N, L);
        const V n_dot_l = clamp_dot(n_dot_l_raw);
        V spec_dot;
        if (in.phong) {
            const V s2 = hn::Mul(hn::Set(d, 2.0), n_dot_l_raw);
            const V R[3] = {hn::Sub(hn::Mul(s2, N[0]), L[0]), hn::Sub(hn::Mul(s2, N[1]), L[1]),
                            hn::Sub(hn::Mul(s2, N[2]), L[2])};
            spec_dot = hn::Max(dot3(R, view), zero);
        } else {
            V H[3] = {hn::Add(L[0], view[0]), hn::Add(L[1], view[1]), hn::Add(L[2], view[2])};
            const V inv = hn::Div(one, hn::Sqrt(dot3(H, H)));
            for (int c = 0; c < 3; ++c) H[c] = hn::Mul(H[c], inv);
            spec_dot = clamp_dot(dot3(N, H));
        }
        V specular = zero;
        if (in.ks != 0.0) {
            // s^n = exp(n log s) for s > 0; 0^n = 0 (n > 0), s^0 = 1.
            const V power = in.n == 0.0 ? one
                                        : hn::IfThenElseZero(hn::Gt(spec_dot, zero),
                                                             hn::Exp(d, hn::Mul(hn::Set(d, in.n), hn::Log(d, spec_dot))));
            specular = hn::Mul(hn::Mul(hn::Set(d, in.ks), power), cue);
        }
        for (int c = 0; c < 3; ++c) {
            const V I = hn::Set(d, light.color[c]);
            const V ambient = hn::Mul(I, hn::Mul(hn::Set(d, in.ka), m[c]));
            const V diffuse = hn::Mul(I, hn::Mul(hn::Mul(hn::Mul(hn::Set(d, in.kd), m[c]), n_dot_l), cue));
            V term = hn::Add(ambient, diffuse);
            if (in.ks != 0.0) term = hn::Add(term, hn::Mul(I, specular));
            out[c] = hn::Add(out[c], term);
        }
    }
    for (int c = 0; c < 3; ++c) m[c] = hn::IfThenElse(lit, out[c], m[c]);
}

void composite_lanes(const PacketCompositeInputs& in, const Ray* rays, const std::vector<Interval>* intervals,
                     PixelValue* out, int count) {
    const D d;
    RayPacket packet(rays, intervals, count, in.step, in.macrocells);
    const std::size_t L = packet.lanes;
    HWY_ALIGN double buf[RayPacket::kLanes];
    const V Ox = hn::Load(d, packet.ox), Oy = hn::Load(d, packet.oy), Oz = hn::Load(d, packet.oz);
    const V Dx = hn::Load(d, packet.dx), Dy = hn::Load(d, packet.dy), Dz = hn::Load(d, packet.dz);
    const PacketTrilinear trilinear(in.voxels, in.voxel_type, in.dims, in.origin, in.inv_spacing);
    // The cached gradient components share the volume's grid.
    const bool cached = in.gradient == PacketCompositeInputs::Gradient::Cached;
    const PacketTrilinear gx(cached ? static_cast<const void*>(in.cached_gradient[0]) : in.voxels,
                              cached ? ScalarType::F64 : in.voxel_type, in.dims, in.origin, in.inv_spacing);
    const PacketTrilinear gy(cached ? static_cast<const void*>(in.cached_gradient[1]) : in.voxels,
                              cached ? ScalarType::F64 : in.voxel_type, in.dims, in.origin, in.inv_spacing);
    const PacketTrilinear gz(cached ? static_cast<const void*>(in.cached_gradient[2]) : in.voxels,
                              cached ? ScalarType::F64 : in.voxel_type, in.dims, in.origin, in.inv_spacing);
    const PacketGradient gradient{in, trilinear, {&gx, &gy, &gz}};
    const V view[3] = {hn::Neg(Dx), hn::Neg(Dy), hn::Neg(Dz)};

    const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
    V Cr = zero, Cg = zero, Cb = zero, tau_s = zero, tau_c = zero, opaque = zero;
    const V l_unit = hn::Set(d, in.unit_distance);
    const V threshold = hn::Set(d, in.threshold);

    while (packet.next()) {
        const V t = hn::Load(d, packet.tm), seg = hn::Load(d, packet.len);
        const M alive = hn::Gt(hn::Load(d, packet.live), zero);
        const V P[3] = {hn::Add(Ox, hn::Mul(t, Dx)), hn::Add(Oy, hn::Mul(t, Dy)), hn::Add(Oz, hn::Mul(t, Dz))};
        const V v = trilinear(P[0], P[1], P[2]);
        // Transfer function.
        const V x = in.normalized ? hn::Mul(hn::Sub(v, hn::Set(d, in.lo)), hn::Set(d, in.inv_width)) : v;
        const TableLookup ot = locate_rows(d, in.opacity_x, in.opacity_rows, x);
        V a = table_channel(d, ot, in.opacity_y, in.opacity_rows, 1, 0, x);
        V g[3];
        bool have_gradient = false;
        if (in.gradient_opacity_rows > 0) {
            // a = clamp(a factor(|grad f|), 0, 1)
            gradient(P, v, g);
            have_gradient = true;
            const V glen = hn::Sqrt(dot3(g, g));
            const TableLookup gt = locate_rows(d, in.gradient_opacity_x, in.gradient_opacity_rows, glen);
            const V factor = table_channel(d, gt, in.gradient_opacity_y, in.gradient_opacity_rows, 1, 0, glen);
            a = hn::Min(hn::Max(hn::Mul(a, factor), zero), one);
        }
        const M visible = hn::And(alive, hn::Gt(a, zero));
        if (!hn::AllFalse(d, visible)) {
            const TableLookup ct = locate_rows(d, in.color_x, in.color_rows, x);
            V m[3] = {table_channel(d, ct, in.color_y, in.color_rows, 3, 0, x),
                      table_channel(d, ct, in.color_y, in.color_rows, 3, 1, x),
                      table_channel(d, ct, in.color_y, in.color_rows, 3, 2, x)};
            if (in.shaded) {
                if (!have_gradient) gradient(P, v, g);
                shade(in, m, g, view, t);
            }
            const V cr = m[0], cg = m[1], cb = m[2];
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
                if (buf[l] != 0.0) packet.active[l] = false;
        }
    }
    const V A = hn::IfThenElse(hn::Gt(opaque, zero), one, hn::Neg(hn::Expm1(d, hn::Neg(hn::Add(tau_s, tau_c)))));
    HWY_ALIGN double r_[RayPacket::kLanes], g_[RayPacket::kLanes], b_[RayPacket::kLanes], a_[RayPacket::kLanes];
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
