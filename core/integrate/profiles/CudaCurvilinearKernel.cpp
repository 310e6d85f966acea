// Seed 001's kernel in float32 (CudaCurvilinearKernel.h). Every float operation below is the kernel's, in its
// order; `fma` marks where nvcc (NVVM, -fmad=true) contracts a * b + c: a sum of products a*b + c*d
// becomes fma(a, b, c*d), a*b - c*d becomes fma(a, b, -(c*d)), x + s*v becomes fma(s, v, x), and a
// three-term dot product fma(a.z, b.z, fma(a.x, b.x, a.y*b.y)). The project compiles with
// -ffp-contract=off, so nothing else is fused here.
#include "core/integrate/profiles/CudaCurvilinearKernel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/grid/Volume.h"
#include "core/integrate/march/March.h"
#include "core/integrate/profiles/TextureUnit.h"
#include "core/scene/Scene.h"
#include "geometry/ShellTessellation.h"
#include "transfer/Classifier.h"

namespace volref {

namespace tu = texture_unit;

namespace {

using F3 = std::array<float, 3>;

// double -> float as the host's casts do, with values past the float range taken as +-inf (a plain cast of
// those is undefined behaviour in C++; on every GPU host it gives inf).
float to_f(double x) {
    constexpr double kMax = double(std::numeric_limits<float>::max());
    if (x > kMax) return x < kMax * (1.0 + 0x1p-25) ? std::numeric_limits<float>::max() : std::numeric_limits<float>::infinity();
    if (x < -kMax) return x > -kMax * (1.0 + 0x1p-25) ? -std::numeric_limits<float>::max() : -std::numeric_limits<float>::infinity();
    return static_cast<float>(x);
}

F3 sub(const F3& a, const F3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
F3 scale(float s, const F3& a) { return {s * a[0], s * a[1], s * a[2]}; }
F3 along(const F3& o, float s, const F3& v) {  // o + s * v, contracted
    return {std::fma(s, v[0], o[0]), std::fma(s, v[1], o[1]), std::fma(s, v[2], o[2])};
}
// CUDA's rsqrtf (2 ulp); here 1 / sqrt correctly rounded.
float rsqrt(float x) { return to_f(1.0 / std::sqrt(double(x))); }
float dot(const F3& a, const F3& b) { return std::fma(a[2], b[2], std::fma(a[0], b[0], a[1] * b[1])); }
F3 cross(const F3& a, const F3& b) {
    return {std::fma(a[1], b[2], -(a[2] * b[1])), std::fma(a[2], b[0], -(a[0] * b[2])), std::fma(a[0], b[1], -(a[1] * b[0]))};
}

F3 normalize(const F3& a) { return scale(rsqrt(dot(a, a)), a); }
float det(float ux, float uy, float vx, float vy) { return std::fma(ux, vy, -(uy * vx)); }
// CUDA's atan2f / atanf (2 ulp); here correctly rounded.
float atan2_f(float y, float x) { return static_cast<float>(std::atan2(double(y), double(x))); }
const float kAtan1 = static_cast<float>(std::atan(1.0));  // atanf(1.0f)

F3 bary(const F3& P0, const F3& P1, const F3& P2, const F3& point) {
    const F3 u = normalize(sub(P1, P0));
    const F3 v = normalize(cross(cross(u, sub(P2, P0)), u));
    const F3 a = sub(point, P0), b = sub(point, P1), c = sub(point, P2);
    const float p0x = dot(a, u), p0y = dot(a, v), p1x = dot(b, u), p1y = dot(b, v), p2x = dot(c, u), p2y = dot(c, v);
    const float A = det(p1x, p1y, p2x, p2y), B = det(p2x, p2y, p0x, p0y), C = det(p0x, p0y, p1x, p1y);
    const float delta = A + B + C;
    return {A / delta, B / delta, C / delta};
}

double norm(const F3& a) { return std::sqrt(double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2]); }

constexpr float kTwoPiCyl = 8.0f * 0.785398185253143310546875f;  // 8 atanf(1): cartToCyl's 2 pi
constexpr double kU = 0x1p-24;                                   // float32 unit roundoff
constexpr double kAmbiguousBary = 0x1p-14;   // a barycentric coordinate this close to 0 may take either sign
constexpr double kAmbiguousD = 0x1p-18;      // |d| <= this |n|: the sign of d is not decided
constexpr int kMostAmbiguous = 6;            // 2^6 alternatives at most; more: the band is infinite
constexpr double kMostSteps = 0x1p26;        // a loop longer than this is taken as one that does not end

}  // namespace

std::string Seed001Fault::text() const {
    char buf[400];
    if (double(ulp) > 2.0 * double(step) || !std::isfinite(out_abs))
        std::snprintf(buf, sizeof buf,
                      "the mirrored loop cannot end: triangle %d (d = dot(n, vect) = %.9g) sets outAbs = %.9g (inAbs %.9g); "
                      "the float32 spacing there is %.9g, so s -= %.9g leaves s unchanged",
                      triangle, double(d), double(out_abs), double(in_abs), double(ulp), double(step));
    else
        std::snprintf(buf, sizeof buf,
                      "the mirrored loop does not end in 2^26 steps: triangle %d (d = dot(n, vect) = %.9g) sets outAbs = %.9g "
                      "(inAbs %.9g), (outAbs - inAbs) / step = %.6g steps of %.9g",
                      triangle, double(d), double(out_abs), double(in_abs),
                      (double(out_abs) - double(in_abs)) / double(step), double(step));
    return buf;
}

Seed001Frame seed001_frame(const Volume& volume, const BoundsSpec& bounds, const Classifier& classifier,
                           const RenderSpec& render, double step) {
    Seed001Frame f;
    const int segments = bounds.tessellate > 0 ? bounds.tessellate : 64;
    const double rad = std::numbers::pi / 180.0;
    TriangleMesh mesh;
    if (bounds.type == BoundsSpec::Type::Cylindrical) {
        const CylindricalShell& c = bounds.cylinder;
        if (c.r0 != 0.0 || c.a0 != 0.0 || c.h0 != 0.0)
            throw Error("render.profile_options.kernel: \"float32\" is seed 001's kernel, whose cylinder starts at radius, angle and height 0 (volume.bounds; kernel \"double\" renders any shell)");
        f.geom_type = 0;
        f.geom_size = {to_f(c.r1), to_f(c.a1 * rad), to_f(c.h1)};
        f.center = c.center;
        mesh = tessellate(c, segments);
    } else if (bounds.type == BoundsSpec::Type::Spherical) {
        const SphericalShell& s = bounds.sphere;
        if (s.r0 != 0.0 || s.lon0 != 0.0 || s.lat0 != -s.lat1 || s.axes != std::array<int, 3>{0, 1, 2})
            throw Error("render.profile_options.kernel: \"float32\" is seed 001's kernel, whose sphere has radius and longitude from 0, latitude [-F, F] and the default axes (volume.bounds; kernel \"double\" renders any shell)");
        f.geom_type = 1;
        f.geom_size = {to_f(s.r1), to_f(s.lon1 * rad), to_f(s.lat1 * rad)};
        f.center = s.center;
        mesh = tessellate(s, segments);
    } else {
        throw Error("render.profile_options.kernel: \"float32\" needs cylindrical or spherical bounds (seed 001's shells)");
    }
    for (const auto& t : mesh.triangles)
        for (std::uint32_t k : t) {
            const glm::dvec3 v = mesh.vertices[k] - f.center;
            f.vertices.push_back({to_f(v.x), to_f(v.y), to_f(v.z)});
        }
    const auto [vmin, vmax] = volume.value_range();
    f.dims = volume.dims;
    f.data.resize(volume.values.size());
    for (std::size_t i = 0; i < f.data.size(); ++i) {
        f.data[i] = tu::unorm16(vmax > vmin ? (volume.values[i] - vmin) / (vmax - vmin) : 0.0);
    }
    for (int j = 0; j < 9; ++j) {
        const Classified k = classifier.classify(vmin + double(j) * (vmax - vmin) / 8.0, 0.0);
        f.table[std::size_t(j)] = {to_f(k.color.r), to_f(k.color.g), to_f(k.color.b), to_f(k.opacity)};
    }
    const ProfileOptions& o = render.profile_options;
    f.step = to_f(step);
    f.density = to_f(o.density);
    f.xray_brightness = to_f(o.brightness);
    f.iso = to_f(o.iso_threshold);
    f.transfer_scale = to_f(o.transfer_scale);
    f.xray = is_line_integral(render.projection);  // the kernel runs composite or x-ray (ProfileIntegrator)
    f.tricubic = o.tricubic;
    return f;
}

CudaCurvilinearKernel::CudaCurvilinearKernel(Seed001Frame frame, bool h100, bool band) : f_(std::move(frame)), h100_(h100), band_(band) {
    const float nx = float(f_.dims[0]), ny = float(f_.dims[1]), nz = float(f_.dims[2]);
    if (f_.geom_type == 0) step_ = {f_.geom_size[0] / nx, f_.geom_size[1] / ny, f_.geom_size[2] / nz};
    else step_ = {f_.geom_size[0] / nz, f_.geom_size[1] / nx, 2.0f * f_.geom_size[2] / ny};  // length, long, lat
}

// --- rayIntersectTriangles ------------------------------------------------------------------------
CudaCurvilinearKernel::Span CudaCurvilinearKernel::intersect(const F3& O, const F3& V, std::vector<Hit>* hits) const {
    Span sp;
    bool in_found = false, out_found = false;
    float in_v = 0.0f, out_v = 0.0f;
    const std::size_t n = f_.vertices.size() / 3;
    for (std::size_t i = 0; i < n; ++i) {
        const F3& P0 = f_.vertices[3 * i];
        const F3& P1 = f_.vertices[3 * i + 1];
        const F3& P2 = f_.vertices[3 * i + 2];
        const F3 nrm = cross(sub(P1, P0), sub(P2, P0));
        const float d = dot(nrm, V);
        if (d == 0.0f && !hits) continue;
        const F3 toP0 = sub(P0, O);
        const float s = d != 0.0f ? dot(nrm, toP0) / d : 0.0f;
        const F3 b = d != 0.0f ? bary(P0, P1, P2, along(O, s, V)) : F3{-1.0f, -1.0f, -1.0f};
        const bool inside = b[0] >= 0 && b[1] >= 0 && b[2] >= 0;
        if (d > 0 && inside) {
            if (!out_found || s > out_v) sp.out_triangle = int(i);
            out_v = out_found ? std::fmax(out_v, s) : s;
            out_found = true;
        }
        if (d < 0 && inside) {
            if (!in_found || s < in_v) sp.in_triangle = int(i);
            in_v = in_found ? std::fmin(in_v, s) : s;
            in_found = true;
        }
        if (hits) {
            const double nn = norm(nrm);
            const double bmin = std::min({double(b[0]), double(b[1]), double(b[2])});
            const bool d_unsure = std::fabs(double(d)) <= kAmbiguousD * nn;
            const bool near = d != 0.0f && std::isfinite(bmin) && bmin > -kAmbiguousBary;
            if (near || (d_unsure && d != 0.0f)) {
                // the uncertainty of s = dot(n, P0 - O) / d (a few roundings of each, relative to the terms)
                const double eps = d != 0.0f ? 4.0 * kU * nn * (norm(toP0) + std::fabs(double(s))) / std::fabs(double(d)) : 0.0;
                hits->push_back({int(i), s, d, d < 0, (d != 0.0f) && inside, (near && bmin < kAmbiguousBary) || d_unsure, eps});
            }
        }
    }
    // The seed's fallback: the missing value is assigned, its flag is not, so the ray is not rendered.
    if (in_found && !out_found) out_v = in_v + 2 * f_.geom_size[0] / static_cast<float>(std::sqrt(double(dot(V, V))));
    if (!in_found && out_found) in_v = out_v - 2 * f_.geom_size[0] / static_cast<float>(std::sqrt(double(dot(V, V))));
    sp.in_abs = in_v;
    sp.out_abs = out_v;
    sp.ok = out_v >= in_v && out_found && in_found;
    return sp;
}

CudaCurvilinearKernel::Span CudaCurvilinearKernel::span_of(const std::vector<Hit>& hits, const std::vector<char>& accepted, float geom_r) {
    Span sp;
    bool in_found = false, out_found = false;
    float in_v = 0.0f, out_v = 0.0f;
    double in_eps = 0.0, out_eps = 0.0;
    for (std::size_t k = 0; k < hits.size(); ++k) {
        if (!accepted[k]) continue;
        const Hit& h = hits[k];
        if (!h.entry) {
            if (!out_found || h.s > out_v) out_v = h.s, sp.out_triangle = h.triangle, out_eps = h.eps;
            out_found = true;
        } else {
            if (!in_found || h.s < in_v) in_v = h.s, sp.in_triangle = h.triangle, in_eps = h.eps;
            in_found = true;
        }
    }
    if (in_found && !out_found) out_v = in_v + 2 * geom_r;
    if (!in_found && out_found) in_v = out_v - 2 * geom_r;
    sp.in_abs = in_v;
    sp.out_abs = out_v;
    sp.ok = out_v >= in_v && out_found && in_found;
    sp.eps = std::max(in_eps, out_eps);
    return sp;
}

// --- interpolateCyl / interpolateSpher and the texture unit -----------------------------------------
float CudaCurvilinearKernel::sample_at(const F3& p) const {
    F3 tex;
    if (f_.geom_type == 0) {
        float angle = atan2_f(-p[2], p[0]);
        if (angle < 0) angle += kTwoPiCyl;
        const float r = std::sqrt(std::fma(p[2], p[2], p[0] * p[0]));
        tex = {r / step_[0], angle / step_[1], p[1] / step_[2]};
    } else {
        const float r = std::sqrt(std::fma(p[2], p[2], p[0] * p[0]));
        const float R = std::sqrt(std::fma(p[2], p[2], std::fma(p[0], p[0], p[1] * p[1])));
        float lon = atan2_f(-p[2], p[0]);
        if (lon < 0) lon += 2.0f * (4.0f * kAtan1);
        const float lat = atan2_f(p[1], r) + f_.geom_size[2];
        tex = {lon / step_[1], lat / step_[2], R / step_[0]};
    }
    for (int a = 0; a < 3; ++a)
        if (tex[std::size_t(a)] < 0 || tex[std::size_t(a)] > float(f_.dims[std::size_t(a)] - 1)) return 0.0f;  // outVal
    return f_.tricubic ? cubic(tex) : fetch(tex);
}

// tex3D(dataTex, x, y, z): unnormalised coordinates, clamped to the edge, the unsigned shorts read as q / 65535.
float CudaCurvilinearKernel::fetch(const F3& tex) const {
    if (!h100_) return static_cast<float>(exact_fetch({double(tex[0]), double(tex[1]), double(tex[2])}));
    const tu::Fetch3d fe = tu::locate_3d({double(tex[0]), double(tex[1]), double(tex[2])}, f_.dims);
    std::array<std::uint16_t, 8> q;
    for (int c = 0; c < 8; ++c) {
        const auto i = fe.corner_index(c);
        q[std::size_t(c)] = f_.data[std::size_t(i[0] + f_.dims[0] * (i[1] + f_.dims[1] * i[2]))];
    }
    return tu::filter_unorm16(fe.w.data(), q.data(), 8);
}

double CudaCurvilinearKernel::exact_fetch(const std::array<double, 3>& tex) const {
    const tu::Fetch3d fe = tu::locate_3d(tex, f_.dims);
    const std::array<double, 8> e = tu::exact_weights(fe.axis);
    double v = 0.0;
    for (int c = 0; c < 8; ++c) {
        const auto i = fe.corner_index(c);
        v += e[std::size_t(c)] * (double(f_.data[std::size_t(i[0] + f_.dims[0] * (i[1] + f_.dims[1] * i[2]))]) / 65535.0);
    }
    return v;
}

namespace {

// cubicInterpMixture as the kernel computes it, each operation rounded to float32: 2 * a2 is exact, so
// whether NVVM fuses a * a2 into the sums that follow changes w0 .. w3 by one rounding at most (not
// measured on hardware; the band covers it). A 0 / 0 (a = 0: w2 + w3 = 0) gives a NaN coordinate whose
// read is weighted by exactly 0.
F3 cubic_mixture(float x) {
    const float i = std::floor(x);
    const float a = x - i;
    const float a2 = a * a;
    const float a3 = a * a2;
    const float w0 = -a3 + (2.0f * a2) - a;
    const float w1 = a3 - (2.0f * a2) + 1.0f;
    const float w2 = -a3 + a2 + a;
    const float w3 = a3 - a2;
    return {i - (w0 / (w0 + w1)), i + 1.0f + (w3 / (w2 + w3)), w2 + w3};
}

float lerp_f(float a, float b, float t) { return std::fma(t, b - a, a); }  // a + t * (b - a), contracted

}  // namespace

// cubicInterpolate: 8 tex3D reads at the mixture coordinates, then lerps along x, y, z in the seed's order.
float CudaCurvilinearKernel::cubic(const F3& tex) const {
    const F3 mx = cubic_mixture(tex[0]), my = cubic_mixture(tex[1]), mz = cubic_mixture(tex[2]);
    const float v000 = fetch({mx[0], my[0], mz[0]}), v010 = fetch({mx[0], my[1], mz[0]});
    const float v001 = fetch({mx[0], my[0], mz[1]}), v011 = fetch({mx[0], my[1], mz[1]});
    const float v100 = fetch({mx[1], my[0], mz[0]}), v110 = fetch({mx[1], my[1], mz[0]});
    const float v101 = fetch({mx[1], my[0], mz[1]}), v111 = fetch({mx[1], my[1], mz[1]});
    const float y0z0 = lerp_f(v000, v100, mx[2]), y1z0 = lerp_f(v010, v110, mx[2]);
    const float z0 = lerp_f(y0z0, y1z0, my[2]);
    const float y0z1 = lerp_f(v001, v101, mx[2]), y1z1 = lerp_f(v011, v111, mx[2]);
    const float z1 = lerp_f(y0z1, y1z1, my[2]);
    return lerp_f(z0, z1, mz[2]);
}

std::array<float, 4> CudaCurvilinearKernel::table_fetch(float u) const {
    std::array<float, 4> out{};
    if (h100_) {
        const tu::AxisRead r = tu::axis_read(tu::unnormalized(double(u), 9), 9);
        const int w[2] = {tu::kWeightOne - r.a, r.a};
        for (int c = 0; c < 4; ++c) {
            const float t[2] = {f_.table[std::size_t(r.i0)][std::size_t(c)], f_.table[std::size_t(r.i1)][std::size_t(c)]};
            out[std::size_t(c)] = tu::filter_float(w, t, 2, 1);
        }
        return out;
    }
    const double t = std::clamp(double(u) * 9.0 - 0.5, 0.0, 8.0);
    const int i = std::min(int(t), 7);
    const double w = t - double(i);
    for (int c = 0; c < 4; ++c) {
        const double a = f_.table[std::size_t(i)][std::size_t(c)], b = f_.table[std::size_t(i) + 1][std::size_t(c)];
        out[std::size_t(c)] = static_cast<float>(a + w * (b - a));
    }
    return out;
}

// --- the kernel ------------------------------------------------------------------------------------
Seed001Pixel CudaCurvilinearKernel::pixel(const Ray& ray) const { return pixel(ray, nullptr); }

namespace {

// The kernel's loop over [in, out] by float32 steps from the exit (March.h, FromExitFloatSteps).
std::vector<Interval> hull(float in, float out) { return {Interval{double(in), double(out)}}; }
MarchOptions float_from_exit(float step) {
    MarchOptions o;
    o.step = double(step);
    o.placement.kind = MarchPlacement::Kind::FromExitFloatSteps;
    return o;
}

}  // namespace

Seed001Pixel CudaCurvilinearKernel::pixel(const Ray& ray, std::vector<Sample>* samples) const {
    // The host: origin - centre and the unit direction, in double, then float.
    const glm::dvec3 o = ray.origin - f_.center, dv = glm::normalize(ray.direction);
    const F3 O{to_f(o.x), to_f(o.y), to_f(o.z)}, V{to_f(dv.x), to_f(dv.y), to_f(dv.z)};
    std::vector<Hit> hits;
    const Span sp = intersect(O, V, band_ ? &hits : nullptr);
    Seed001Pixel px;
    px.in_abs = sp.in_abs;
    px.out_abs = sp.out_abs;
    bool may_fault = false;
    if (sp.ok && sp.out_abs >= 0.0f) {
        px.hit = true;
        const float in = std::fmax(0.0f, sp.in_abs);
        px.in_abs = in;
        // s -= step cannot move s (or s is not finite), or more than kMostSteps steps (a practical end)
        if (!(sp.out_abs - f_.step != sp.out_abs) || !((double(sp.out_abs) - double(in)) / double(f_.step) < kMostSteps)) {
            px.fault = true;
            px.why = {sp.out_triangle, 0.0f, sp.out_abs, in, 0.0f, f_.step};
            if (std::isfinite(sp.out_abs))
                px.why.ulp = std::nextafter(sp.out_abs, std::numeric_limits<float>::infinity()) - sp.out_abs;
            if (sp.out_triangle >= 0) {
                const std::size_t i = std::size_t(sp.out_triangle);
                px.why.d = dot(cross(sub(f_.vertices[3 * i + 1], f_.vertices[3 * i]), sub(f_.vertices[3 * i + 2], f_.vertices[3 * i])), V);
            }
            const double nan = std::numeric_limits<double>::quiet_NaN();
            px.rgba = glm::dvec4(nan);
            return px;
        }
        std::array<float, 4> sum{0.0f, 0.0f, 0.0f, 0.0f};
        float max_val = 0.0f;
        // The loop `for (float s = outAbs; s >= inAbs; s -= step)`: march()'s FromExitFloatSteps placement.
        march(hull(in, sp.out_abs), float_from_exit(f_.step), [&](const MarchSample& m) {
            const float s = float(m.t);  // exact: m.t holds the float s
            const F3 point = along(O, s, V);
            const float sample = sample_at(point);
            const bool used = sample >= f_.iso;
            ++px.samples;
            if (used) {
                if (f_.xray) {
                    max_val = std::fmax(max_val, sample);
                } else {
                    const std::array<float, 4> col = table_fetch(sample * f_.transfer_scale);
                    const float t = col[3] * f_.density;
                    for (int c = 0; c < 4; ++c)
                        sum[std::size_t(c)] = std::fma(t, col[std::size_t(c)] - sum[std::size_t(c)], sum[std::size_t(c)]);
                }
            }
            if (samples) samples->push_back({s, point, sample, used, f_.xray ? std::array<float, 4>{max_val, max_val, max_val, 1.0f} : sum});
            return true;
        });
        if (f_.xray) {
            const float m = max_val * f_.xray_brightness;
            px.rgba = glm::dvec4(m, m, m, 1.0);
        } else {
            px.rgba = glm::dvec4(sum[0] * f_.reg_brightness, sum[1] * f_.reg_brightness, sum[2] * f_.reg_brightness,
                                 sum[3] * f_.reg_brightness);
        }
    }
    if (band_) {
        px.error = band(O, V, hits, sp, px.rgba, may_fault);
        if (may_fault) px.error = std::numeric_limits<double>::infinity();
    }
    return px;
}

// --- the band --------------------------------------------------------------------------------------
// The interval of the sample at `point` (seed frame) for every program whose positions lie within
// eps (world) of it and whose texture unit is of the h100 rule's family (TextureUnit.h): each texture
// coordinate moves by at most delta texels (the position's move through the coordinate map's
// derivatives, plus a few ulps for sqrtf, atan2f's 2 ulp and the divisions); where a coordinate may
// cross 0 or n - 1 the sample may be outVal (0); near the angle 0 the atan2 + 2 pi branch may flip
// (outVal); a move of half a texel or more: the whole data range [0, 1].
void CudaCurvilinearKernel::sample_range(const F3& p, double eps, double& lo, double& hi) const {
    const double x = p[0], y = p[1], z = p[2];
    const double rel = 0x1p-19;  // relative rounding of each texture coordinate (ulps of sqrt, atan2, divisions)
    std::array<double, 3> tex{}, delta{};
    bool angle_flip = false;
    const double r = std::sqrt(x * x + z * z);
    if (f_.geom_type == 0) {
        double angle = std::atan2(-z, x);
        if (angle < 0) angle += 2.0 * std::numbers::pi;
        const double dang = r > 0.0 ? 2.0 * eps / r : std::numeric_limits<double>::infinity();
        angle_flip = std::min(angle, 2.0 * std::numbers::pi - angle) <= dang + 8.0 * kU;
        tex = {r / step_[0], angle / step_[1], y / step_[2]};
        delta = {2.0 * eps / step_[0], (dang + 8.0 * kU * angle) / step_[1], 2.0 * eps / step_[2]};
    } else {
        const double R = std::sqrt(x * x + y * y + z * z);
        double lon = std::atan2(-z, x);
        if (lon < 0) lon += 2.0 * std::numbers::pi;
        const double lat = std::atan2(y, r) + f_.geom_size[2];
        const double dlon = r > 0.0 ? 2.0 * eps / r : std::numeric_limits<double>::infinity();
        const double dlat = R > 0.0 ? 2.0 * eps / R : std::numeric_limits<double>::infinity();
        angle_flip = std::min(lon, 2.0 * std::numbers::pi - lon) <= dlon + 8.0 * kU;
        tex = {lon / step_[1], lat / step_[2], R / step_[0]};
        delta = {(dlon + 8.0 * kU * lon) / step_[1], (dlat + 8.0 * kU * std::fabs(lat)) / step_[2], 2.0 * eps / step_[0]};
    }
    bool maybe_out = angle_flip, surely_out = false, huge = false;
    double delta_sum = 0.0;
    for (int a = 0; a < 3; ++a) {
        double& d = delta[std::size_t(a)];
        d += rel * std::fabs(tex[std::size_t(a)]) + 0x1p-30;
        const double t = tex[std::size_t(a)], n1 = double(f_.dims[std::size_t(a)] - 1);
        if (t + d < 0.0 || t - d > n1) surely_out = true;
        else if (t - d < 0.0 || t + d > n1) maybe_out = true;
        if (!(d < 0.5)) huge = true;
        delta_sum += d;
    }
    if (surely_out && !angle_flip) {
        lo = hi = 0.0;
        return;
    }
    if (surely_out) {  // outVal, or (the other branch of the angle) anything
        lo = 0.0;
        hi = 1.0;
        return;
    }
    if (huge) {
        lo = 0.0;
        hi = 1.0;
        return;
    }
    // the texels any position within delta reads: per axis the texel box around [t - d, t + d]; tricubic:
    // i - 1 .. i + 1 for every i = floor(t') with t' in [t - d, t + d] (seed001_cubic)
    std::array<std::int64_t, 3> i_lo{}, i_hi{};
    for (int a = 0; a < 3; ++a) {
        const double n1 = double(f_.dims[std::size_t(a)] - 1);
        if (f_.tricubic) {
            i_lo[std::size_t(a)] = std::max<std::int64_t>(0, std::int64_t(std::floor(tex[std::size_t(a)] - delta[std::size_t(a)])) - 1);
            i_hi[std::size_t(a)] = std::min(std::int64_t(std::floor(tex[std::size_t(a)] + delta[std::size_t(a)])) + 1, f_.dims[std::size_t(a)] - 1);
            continue;
        }
        const double tl = std::clamp(tex[std::size_t(a)] - delta[std::size_t(a)] - 0.5, 0.0, n1);
        const double th = std::clamp(tex[std::size_t(a)] + delta[std::size_t(a)] - 0.5, 0.0, n1);
        i_lo[std::size_t(a)] = std::int64_t(std::floor(tl));
        i_hi[std::size_t(a)] = std::min(std::int64_t(std::floor(th)) + 1, f_.dims[std::size_t(a)] - 1);
    }
    double vmin = 1.0, vmax = 0.0;
    for (std::int64_t k = i_lo[2]; k <= i_hi[2]; ++k)
        for (std::int64_t j = i_lo[1]; j <= i_hi[1]; ++j)
            for (std::int64_t i = i_lo[0]; i <= i_hi[0]; ++i) {
                const double v = double(f_.data[std::size_t(i + f_.dims[0] * (j + f_.dims[1] * k))]) / 65535.0;
                vmin = std::min(vmin, v);
                vmax = std::max(vmax, v);
            }
    if (f_.tricubic) {
        // The seed's cubic at the nominal coordinate, exactly; moved by delta per axis it changes by at most
        // 2 delta (vmax - vmin) per axis (d/da [(1 - a) F(m0) + a F(m1)] <= (1 + |1 - 2a|) D, F a linear read);
        // each read of a unit of the family by kL1Max / 2 of D; the float32 mixture (w0 .. w3 to a few
        // roundings each, the ratio's error over (1 - a) or a weighted by (1 - a) or a, the coordinate's own
        // rounding |m| u) by (24 + |t| + 1) u D per axis; the 7 lerps by 16 u; a read at an infinite
        // coordinate (w0 + w1 rounded to 0) weighs at most 2^-18.
        const double v = seed001_cubic(tex, [&](const std::array<double, 3>& m) { return exact_fetch(m); });
        double round = 0.0;
        for (int a = 0; a < 3; ++a) round += (25.0 + std::fabs(tex[std::size_t(a)])) * kU;
        const double b = (2.0 * delta_sum + 0.5 * tu::kL1Max + round) * (vmax - vmin) + tu::kUnorm16Rounding + 16.0 * kU + 0x1p-18;
        lo = std::max(0.0, v - b);
        hi = std::min(1.0, v + b);
        if (maybe_out) lo = 0.0;
        return;
    }
    // exact trilinear at the nominal coordinate
    const double v = exact_fetch(tex);
    const double b = tu::weight_factor(delta_sum) * (vmax - vmin) + tu::kUnorm16Rounding + 0x1p-24;
    lo = std::max(0.0, v - b);
    hi = std::min(1.0, v + b);
    if (maybe_out) lo = 0.0;
}

// The 9-entry table over normalised coordinates [ulo, uhi], the position widened by the 20-bit cut and the
// float32 product sample * transferScale: texture_unit::table_hull per channel.
void CudaCurvilinearKernel::table_range(double ulo, double uhi, double* lo, double* hi) const {
    const double move = 9.0 * tu::kNormalizedDelta + 9.0 * 2.0 * kU;
    const double plo = std::clamp(ulo * 9.0 - 0.5 - move, 0.0, 8.0), phi = std::clamp(uhi * 9.0 - 0.5 + move, 0.0, 8.0);
    for (int c = 0; c < 4; ++c)
        tu::table_hull([&](int j) { return double(f_.table[std::size_t(j)][std::size_t(c)]); }, 9, plo, phi, lo[c], hi[c]);
}

CudaCurvilinearKernel::Box CudaCurvilinearKernel::span_range(const F3& O, const F3& V, const Span& sp, bool& may_fault) const {
    Box box{};
    if (!sp.ok || !(sp.out_abs >= 0.0f)) return box;  // the pixel stays 0
    const float in = std::fmax(0.0f, sp.in_abs);
    // a loop that cannot end, or one longer than the GPU fixtures' guard (4,000,000 steps): infinite band
    if (!(sp.out_abs - f_.step != sp.out_abs) || !((double(sp.out_abs) - double(in)) / double(f_.step) < 4.0e6)) {
        may_fault = true;
        return box;
    }
    const double eps_end = sp.eps + 4.0 * kU * std::fabs(double(sp.in_abs));
    double sum_lo[4] = {0, 0, 0, 0}, sum_hi[4] = {0, 0, 0, 0};
    double max_lo = 0.0, max_hi = 0.0;
    std::int64_t n = 0;
    auto add = [&](float s, bool maybe) {
        const F3 p = along(O, s, V);
        const double eps = sp.eps + 4.0 * kU * (norm(O) + std::fabs(double(s)));
        double vlo, vhi;
        sample_range(p, eps, vlo, vhi);
        const double iso = f_.iso;
        const bool surely = vlo >= iso && !maybe, possibly = vhi >= iso;
        ++n;
        if (!possibly) return;
        if (f_.xray) {
            if (surely) max_lo = std::max(max_lo, vlo);
            max_hi = std::max(max_hi, vhi);
            return;
        }
        double clo[4], chi[4];
        const double ts = f_.transfer_scale;
        table_range(std::max(vlo, iso) * ts, vhi * ts, clo, chi);
        const double wlo = std::max(0.0, clo[3]) * f_.density, whi = chi[3] * f_.density;
        for (int c = 0; c < 4; ++c) {
            double l = std::numeric_limits<double>::infinity(), h = -l;
            for (double sv : {sum_lo[c], sum_hi[c]})
                for (double cv : {clo[c], chi[c]})
                    for (double wv : {std::min(wlo, whi), whi}) {
                        const double r = sv + wv * (cv - sv);
                        l = std::min(l, r);
                        h = std::max(h, r);
                    }
            if (!surely) l = std::min(l, sum_lo[c]), h = std::max(h, sum_hi[c]);
            sum_lo[c] = l;
            sum_hi[c] = h;
        }
    };
    // The kernel's samples (march()'s FromExitFloatSteps, as pixel()), at most 2^26.
    float last = sp.out_abs;
    std::int64_t count = 0;
    bool capped = false;
    march(hull(in, sp.out_abs), float_from_exit(f_.step), [&](const MarchSample& m) {
        last = float(m.t);
        add(last, double(last) - double(in) <= eps_end);
        capped = ++count > (std::int64_t(1) << 26);
        return !capped;
    });
    // one more sample where the end test could pass within rounding: the loop's next s
    const float s = capped ? last : last - f_.step;
    if (count > 0 && double(in) - double(s) <= eps_end && s != last) add(s, true);
    const double round = double(n) * 2.0 * kU;  // each lerp's float32 rounding (or the max: exact)
    if (f_.xray) {
        const double b = f_.xray_brightness;
        for (int c = 0; c < 3; ++c) box.lo[c] = max_lo * b, box.hi[c] = max_hi * b;
        box.lo[3] = box.hi[3] = 1.0;
    } else {
        for (int c = 0; c < 4; ++c) box.lo[c] = sum_lo[c] - round, box.hi[c] = sum_hi[c] + round;
    }
    return box;
}

double CudaCurvilinearKernel::band(const F3& O, const F3& V, const std::vector<Hit>& hits, const Span& nominal,
                           const glm::dvec4& rendered, bool& may_fault) const {
    std::vector<std::size_t> unsure;
    std::vector<char> accepted(hits.size());
    for (std::size_t k = 0; k < hits.size(); ++k) {
        accepted[k] = hits[k].accepted;
        if (hits[k].ambiguous) unsure.push_back(k);
    }
    if (unsure.size() > std::size_t(kMostAmbiguous)) return std::numeric_limits<double>::infinity();
    const float geom_r = f_.geom_size[0] / static_cast<float>(std::sqrt(double(dot(V, V))));
    Box hull{};
    bool any = false;
    std::vector<std::array<float, 3>> seen;
    for (std::uint32_t mask = 0; mask < (1u << unsure.size()); ++mask) {
        std::vector<char> a = accepted;
        for (std::size_t k = 0; k < unsure.size(); ++k) {
            const Hit& h = hits[unsure[k]];
            // an ambiguous hit may be accepted or not (d's sign unsure: also counted as either side)
            a[unsure[k]] = ((mask >> k) & 1u) ? char(h.d != 0.0f) : char(0);
        }
        const Span sp = span_of(hits, a, geom_r);
        const std::array<float, 3> key{sp.ok ? 1.0f : 0.0f, sp.in_abs, sp.out_abs};
        if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
        seen.push_back(key);
        const Box b = span_range(O, V, sp, may_fault);
        for (int c = 0; c < 4; ++c) {
            hull.lo[c] = any ? std::min(hull.lo[c], b.lo[c]) : b.lo[c];
            hull.hi[c] = any ? std::max(hull.hi[c], b.hi[c]) : b.hi[c];
        }
        any = true;
    }
    // the nominal span too (its hits list may leave out triangles far from the line)
    if (std::find(seen.begin(), seen.end(), std::array<float, 3>{nominal.ok ? 1.0f : 0.0f, nominal.in_abs, nominal.out_abs}) == seen.end()) {
        Span sp = nominal;
        for (const Hit& h : hits)
            if (h.triangle == sp.in_triangle || h.triangle == sp.out_triangle) sp.eps = std::max(sp.eps, h.eps);
        const Box b = span_range(O, V, sp, may_fault);
        for (int c = 0; c < 4; ++c) {
            hull.lo[c] = any ? std::min(hull.lo[c], b.lo[c]) : b.lo[c];
            hull.hi[c] = any ? std::max(hull.hi[c], b.hi[c]) : b.hi[c];
        }
        any = true;
    }
    double e = 0.0;
    for (int c = 0; c < 4; ++c) e = std::max({e, hull.hi[c] - rendered[c], rendered[c] - hull.lo[c]});
    return e + 1e-9;
}

}  // namespace volref
