// ProfileIntegrator's placement "slices" (conventions section 9, "Slice-order renderers"): a
// slicer's pixel as the sequence of frame-buffer blends of the fragments its centre ray crosses. The
// surfaces are Slices.h's, the frame buffer FrameBuffer.h's; this file is what one fragment computes
// (the texture's texels and filter, the table or the transfer function, the alpha) and the loop.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/integrate/profiles/FrameBuffer.h"
#include "core/integrate/profiles/ProfileIntegrator.h"
#include "core/integrate/profiles/Slices.h"
#include "geometry/MeshIntervals.h"
#include "geometry/TriangleMesh.h"
#include "transfer/OpacityCorrection.h"
#include "transfer/TransferFunction.h"

namespace volref {

namespace {

double quantise(double x, double levels) { return std::floor(levels * std::clamp(x, 0.0, 1.0) + 0.5) / levels; }

// llvmpipe's 8-bit filter (texture_filter "fixed8"; tests/gpu/slicing/gl_probe measures it): on an axis of
// n texels the float32 coordinate x = (c + 1/2) / n becomes i = rint(x 256 n) - 128 (ties to even), texels
// i >> 8 and i >> 8 + 1 (clamped to the edge) and the weight w = i & 255 in 1/256.
struct Fixed8Axis {
    std::int64_t t0 = 0, t1 = 0;
    long w = 0;
};
Fixed8Axis fixed8_axis_at(float x, std::int64_t n) {  // x: the normalised float32 coordinate
    const long i = long(std::nearbyint(double(x * float(256 * n)))) - 128;
    Fixed8Axis a;
    a.t0 = std::clamp<std::int64_t>(i >> 8, 0, n - 1);
    a.t1 = std::clamp<std::int64_t>((i >> 8) + 1, 0, n - 1);
    a.w = i & 255;
    return a;
}
Fixed8Axis fixed8_axis(double c, std::int64_t n) { return fixed8_axis_at(float((c + 0.5) / double(n)), n); }
// The 1D table's coordinate from a filtered code k, as llvmpipe hands it on: s = fl(k fl(1/255)) (not
// the correctly rounded k / 255 for 126 codes; gl_probe's texel8 check); "texture": x = s; "linear":
// x = fl(fl(fl(s (N - 1)) + 1/2) / N), the colour table's position s (N - 1) as a normalised coordinate.
float fixed8_table_coordinate(double s, int n, bool linear) {
    const float k = float(std::lround(255.0 * s));
    const float sf = k * (1.0f / 255.0f);
    if (!linear) return sf;
    return (sf * float(n - 1) + 0.5f) / float(n);
}
// One lerp of codes: v0 + ((w (v1 - v0) + 128) >> 8), the shift arithmetic (floor).
long fixed8_lerp(long v0, long v1, long w) { return v0 + ((w * (v1 - v0) + 128) >> 8); }

// The transfer function's rows as data values: the first and last of the colour and opacity rows.
bool transfer_rows(const TransferFunction& tf, double& lo, double& hi) {
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    const std::array<double, 2> w = tf.window();
    auto value = [&](double x) { return tf.normalized() ? w[0] + x * (w[1] - w[0]) : x; };
    for (const std::vector<double>* xs : {&tf.color_function().xs(), &tf.opacity_function().xs()})
        for (double x : *xs) {
            lo = std::min(lo, value(x));
            hi = std::max(hi, value(x));
        }
    return lo < hi;
}

}  // namespace

void ProfileIntegrator::prepare_slices(const Volume& volume, const SliceFrame& frame) {
    const ProfileRules& r = ctx_.render.profile_rules;
    auto fail = [](const std::string& key, const std::string& why) { throw Error("render.profile." + key + ": " + why); };
    const Projection proj = ctx_.render.projection;
    if (proj != Projection::Composite && proj != Projection::Mip)
        fail(r.placement ? "placement" : "base", "a slicer composites its slices (projection \"composite\") or takes their maximum (\"mip\" with blend \"max\")");
    if (proj == Projection::Mip && p_.blend != Profile::Blend::Max) fail("blend", "the mip projection of a slicer is GL_MAX (blend \"max\")");
    if (proj == Projection::Composite && p_.blend == Profile::Blend::Max) fail("blend", "\"max\" is the mip projection's (render.projection \"mip\")");
    if (ctx_.pipeline.shaded() && is_composite(proj)) fail("placement", "\"slices\" does not shade (remove volume.shading)");
    if (p_.slices.order == ProfileRules::Slices::Order::FrontToBack && p_.blend == Profile::Blend::SrcAlpha)
        fail("slices", "front to back blends the premultiplied fragment under the frame buffer (blend \"premultiplied\")");
    if (band_) throw Error("render.profile_options.texture_band: not derived for placement \"slices\" (framebuffer_band is its band)");
    if (texture_unit_ != ProfileOptions::TextureUnit::Exact)
        throw Error("render.profile.texture_unit: placement \"slices\" filters its texels exactly");
    if (!ctx_.pipeline.view().cartesian || !frame.camera) fail("placement", "\"slices\" needs a Cartesian grid (box or mesh bounds)");
    if (p_.texture_filter == Profile::TextureFilter::Fixed8) {
        if (p_.texel_format != Profile::TexelFormat::Unorm8) fail("texture_filter", "\"fixed8\" filters 8-bit texels (texture_format \"unorm8\")");
        if (p_.classify != Profile::SliceClassify::Post) fail("texture_filter", "\"fixed8\" filters the value texture (classify \"post\")");
        if (p_.table_entries > 1 && p_.table_lookup != Profile::TableLookup::Nearest && p_.table_format != Profile::TableFormat::Unorm8)
            fail("texture_filter", "\"fixed8\" filters a linearly read table of 8-bit entries (table_format \"unorm8\")");
    }
    if (p_.correction != Profile::Correction::None && p_.correction != Profile::Correction::Exact)
        fail("correction", "a slice's alpha is the table's opacity (\"none\") or corrected for its spacing (\"exact\")");
    // The window [lo, hi] of the texels.
    window_lo_ = lo_;
    window_width_ = width_;
    if (p_.texture_window == Profile::TextureWindow::Given) {
        window_lo_ = p_.texture_window_given.x;
        window_width_ = p_.texture_window_given.y - p_.texture_window_given.x;
    } else if (p_.texture_window == Profile::TextureWindow::TransferRows) {
        double lo = 0.0, hi = 0.0;
        if (const TransferFunction* tf = ctx_.pipeline.view().transfer_function; tf && transfer_rows(*tf, lo, hi)) {
            window_lo_ = lo;
            window_width_ = hi - lo;
        }
    }
    if (!(window_width_ > 0.0)) window_width_ = 1.0;  // a constant volume: every texel 0
    // The table: entries over the window, stored in the table's format.
    if (p_.table_entries > 1) {
        const int n = p_.table_entries;
        slice_table_.resize(std::size_t(n));
        for (int j = 0; j < n; ++j) {
            const Classified k = ctx_.pipeline.classifier().classify(window_lo_ + double(j) * window_width_ / double(n - 1), 0.0);
            glm::dvec4 e(k.color, std::clamp(k.opacity, 0.0, 1.0));
            if (p_.table_format == Profile::TableFormat::Unorm8)
                for (int c = 0; c < 4; ++c) e[c] = quantise(e[c], 255.0);
            slice_table_[std::size_t(j)] = e;
        }
    }
    const double step_scale = ctx_.step / ctx_.render.step;  // world units per unit of render.step_units
    lattice_ = std::make_unique<SliceLattice>(make_slice_lattice(p_, *frame.camera, *frame.spec, frame.box_lo, frame.box_hi,
                                                                 volume.origin, volume.spacing, volume.dims, ctx_.step, step_scale));
    framebuffer_band_ = ctx_.render.profile_options.framebuffer_band;
    if (frame.overlap) overlap_ = std::make_shared<const TriangleMesh>(*frame.overlap);
    // 8-bit texels: the band covers both units that filter them (exact weights, llvmpipe's fixed8).
    band_units_ = framebuffer_band_ && p_.texel_format == Profile::TexelFormat::Unorm8 && p_.classify == Profile::SliceClassify::Post &&
                  (slice_table_.empty() || p_.table_lookup == Profile::TableLookup::Nearest || p_.table_format == Profile::TableFormat::Unorm8);
}

// A texel as the texture holds it: s = clamp((v - lo) / (hi - lo), 0, 1) in the texture's format.
double ProfileIntegrator::slice_texel(std::int64_t i, std::int64_t j, std::int64_t k) const {
    const double s = std::clamp((texels_->at(i, j, k) - window_lo_) / window_width_, 0.0, 1.0);
    switch (p_.texel_format) {
        case Profile::TexelFormat::Unorm8: return quantise(s, 255.0);
        case Profile::TexelFormat::Unorm16: return quantise(s, 65535.0);
        case Profile::TexelFormat::Float: break;
    }
    return double(static_cast<float>(s));
}

// (c, a) at the texture's value s: the table by its lookup, or the transfer function at lo + s (hi - lo).
glm::dvec4 ProfileIntegrator::slice_lookup(double s, bool fixed8) const {
    if (slice_table_.empty()) {
        const Classified k = ctx_.pipeline.classifier().classify(window_lo_ + s * window_width_, 0.0);
        return glm::dvec4(k.color, std::clamp(k.opacity, 0.0, 1.0));
    }
    const int n = int(slice_table_.size());
    if (p_.table_lookup == Profile::TableLookup::Nearest) {  // OpenGL's colour-table index round(s (N - 1))
        const int j = std::clamp(int(std::floor(s * double(n - 1) + 0.5)), 0, n - 1);
        return slice_table_[std::size_t(j)];
    }
    const double pos = p_.table_lookup == Profile::TableLookup::Linear ? s * double(n - 1)
                                                                       : std::clamp(s * double(n) - 0.5, 0.0, double(n - 1));
    if (fixed8 && p_.table_format == Profile::TableFormat::Unorm8) {  // the 1D table, 8-bit weights
        const Fixed8Axis a = fixed8_axis_at(fixed8_table_coordinate(s, n, p_.table_lookup == Profile::TableLookup::Linear), n);
        glm::dvec4 e;
        for (int c = 0; c < 4; ++c)
            e[c] = double(fixed8_lerp(std::lround(255.0 * slice_table_[std::size_t(a.t0)][c]),
                                      std::lround(255.0 * slice_table_[std::size_t(a.t1)][c]), a.w)) / 255.0;
        return e;
    }
    const int i = std::clamp(int(std::floor(pos)), 0, n - 2);
    const double w = std::clamp(pos - double(i), 0.0, 1.0);
    return slice_table_[std::size_t(i)] + w * (slice_table_[std::size_t(i) + 1] - slice_table_[std::size_t(i)]);
}

// One fragment at x (on level `level`), standing for the length d along its ray. The texture's filter:
// the continuous index u = (x - origin) / spacing clamped to [0, n - 1] (section 2), cell i0 =
// min(floor(u), n - 2), w = u - i0; 2D textures: u on the slicing axis is the level's own layer, w = 0.
ProfileIntegrator::Fragment ProfileIntegrator::slice_fragment(const glm::dvec3& x, std::size_t level, double d, bool fixed8) const {
    const Volume& v = *texels_;
    glm::dvec3 u = (x - v.origin) / v.spacing;
    std::array<std::int64_t, 3> i0{}, i1{};
    glm::dvec3 w(0.0);
    const bool layers = p_.texture == Profile::Texture::Texture2d;
    for (int a = 0; a < 3; ++a) {
        const std::int64_t n = v.dims[std::size_t(a)];
        if (layers && a == lattice_->axis) {
            const std::int64_t layer = lattice_->normal[a] > 0.0 ? n - 1 - std::int64_t(level) : std::int64_t(level);
            i0[std::size_t(a)] = i1[std::size_t(a)] = layer;
            continue;
        }
        const double c = std::clamp(u[a], 0.0, double(n - 1));
        i0[std::size_t(a)] = n > 1 ? std::min(std::int64_t(std::floor(c)), n - 2) : 0;
        i1[std::size_t(a)] = n > 1 ? i0[std::size_t(a)] + 1 : 0;
        w[a] = n > 1 ? c - double(i0[std::size_t(a)]) : 0.0;
    }
    // Corners in Levoy's order of x fastest: c = x + 2 y + 4 z; trilinear as x, then y, then z.
    auto corner = [&](int c) {
        return std::array<std::int64_t, 3>{(c & 1) ? i1[0] : i0[0], (c & 2) ? i1[1] : i0[1], (c & 4) ? i1[2] : i0[2]};
    };
    auto lerp3 = [&](auto value) {
        using T = decltype(value(0));
        T x00 = value(0) + w.x * (value(1) - value(0)), x10 = value(2) + w.x * (value(3) - value(2));
        T x01 = value(4) + w.x * (value(5) - value(4)), x11 = value(6) + w.x * (value(7) - value(6));
        T y0 = x00 + w.y * (x10 - x00), y1 = x01 + w.y * (x11 - x01);
        return T(y0 + w.z * (y1 - y0));
    };
    Fragment f;
    glm::dvec4 ca;
    if (fixed8) {  // llvmpipe's 8-bit filter on the texels' codes
        std::array<Fixed8Axis, 3> ax;
        for (int a = 0; a < 3; ++a) {
            const std::int64_t n = v.dims[std::size_t(a)];
            if (layers && a == lattice_->axis) {
                ax[std::size_t(a)] = Fixed8Axis{i0[std::size_t(a)], i0[std::size_t(a)], 0};
                continue;
            }
            ax[std::size_t(a)] = fixed8_axis(std::clamp(u[a], 0.0, double(n - 1)), n);
        }
        auto q = [&](int c) {
            return std::lround(255.0 * slice_texel((c & 1) ? ax[0].t1 : ax[0].t0, (c & 2) ? ax[1].t1 : ax[1].t0, (c & 4) ? ax[2].t1 : ax[2].t0));
        };
        const long x00 = fixed8_lerp(q(0), q(1), ax[0].w), x10 = fixed8_lerp(q(2), q(3), ax[0].w);
        const long x01 = fixed8_lerp(q(4), q(5), ax[0].w), x11 = fixed8_lerp(q(6), q(7), ax[0].w);
        const long y0 = fixed8_lerp(x00, x10, ax[1].w), y1 = fixed8_lerp(x01, x11, ax[1].w);
        f.s = double(fixed8_lerp(y0, y1, ax[2].w)) / 255.0;
        ca = slice_lookup(f.s, fixed8);
    } else if (p_.classify == Profile::SliceClassify::PreUnweighted) {  // each texel looked up, then (c, a) filtered
        std::array<glm::dvec4, 8> e;
        std::array<double, 8> s;
        for (int c = 0; c < 8; ++c) {
            const auto k = corner(c);
            s[std::size_t(c)] = slice_texel(k[0], k[1], k[2]);
            e[std::size_t(c)] = slice_lookup(s[std::size_t(c)], false);
        }
        ca = lerp3([&](int c) { return e[std::size_t(c)]; });
        f.s = lerp3([&](int c) { return s[std::size_t(c)]; });
    } else {
        std::array<double, 8> s;
        for (int c = 0; c < 8; ++c) {
            const auto k = corner(c);
            s[std::size_t(c)] = slice_texel(k[0], k[1], k[2]);
        }
        f.s = lerp3([&](int c) { return s[std::size_t(c)]; });
        ca = slice_lookup(f.s, fixed8);
    }
    f.color = glm::dvec3(ca);
    f.opacity = std::clamp(ca.a, 0.0, 1.0);
    f.alpha = p_.correction == Profile::Correction::Exact
                  ? opacity_for_length(f.opacity, d, ctx_.pipeline.classifier().unit_distance())
                  : f.opacity;
    return f;
}

template <class Rec>
PixelValue ProfileIntegrator::slices(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    const bool under = p_.slices.order == ProfileRules::Slices::Order::FrontToBack;
    SliceFrameBuffer fb(p_.framebuffer, p_.framebuffer_rounding, p_.blend_products, p_.blend, p_.blend_alpha, under,
                        framebuffer_band_);
    // overlap "count": the boundary's crossings along the whole line; the winding number at t, the number
    // of tetrahedra covering the fragment, is minus the windings of the crossings past t (0 beyond the last).
    std::vector<std::pair<double, int>> windings;
    if (overlap_) {
        const RayTriangleFrame frame(ray);
        for (const auto& tri : overlap_->triangles) {
            double t = 0.0;
            int w = 0;
            if (frame.cross(overlap_->vertices[tri[0]], overlap_->vertices[tri[1]], overlap_->vertices[tri[2]], t, w)) windings.emplace_back(t, w);
        }
    }
    auto covering = [&](double t) {
        int m = 0;
        for (const auto& [tc, w] : windings)
            if (tc > t) m -= w;
        return std::max(m, 1);  // a fragment inside the intervals is covered at least once
    };
    lattice_->for_each_crossing(ray, intervals, [&](double t, double d, std::size_t k) {
        const int times = overlap_ ? covering(t) : 1;
        for (int copy = 0; copy < times; ++copy) {
        const glm::dvec3 x = ray.at(t);
        const bool fixed8 = p_.texture_filter == Profile::TextureFilter::Fixed8;
        const Fragment f = slice_fragment(x, k, d, fixed8);
        if (band_units_) {  // the band: the fragment as the other 8-bit unit filters it too
            const Fragment g = slice_fragment(x, k, d, !fixed8);
            const glm::dvec4 other(g.color, g.alpha);
            fb.blend(f.color, f.alpha, &other);
        } else {
            fb.blend(f.color, f.alpha);
        }
        if constexpr (Rec::kOn) {
            SampleRecord r{};
            rec.begin(r, t - 0.5 * d, t + 0.5 * d);
            r.t = t;
            r.length = d;
            r.sample.position = x;
            r.sample.value = window_lo_ + f.s * window_width_;
            r.sample.classified = true;
            r.sample.classified_color = f.color;
            r.sample.color = f.color;
            r.sample.opacity = f.opacity;
            r.composited = true;
            r.alpha = f.alpha;
            r.surface = std::int64_t(k);
            r.accumulated = fb.pixel();
            r.blend_exact = fb.last_exact();
            rec.recorder.record(r);
        }
        }
        return true;
    });
    PixelValue out;
    out.rgba = fb.pixel();
    out.error = fb.band();
    return out;
}

template PixelValue ProfileIntegrator::slices<NoRecording>(const Ray&, const std::vector<Interval>&, NoRecording&) const;
template PixelValue ProfileIntegrator::slices<Recording>(const Ray&, const std::vector<Interval>&, Recording&) const;

}  // namespace volref
