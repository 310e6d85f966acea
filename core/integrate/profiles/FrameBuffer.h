// A slicer's frame buffer (conventions section 9, "Slice-order renderers"): one pixel's
// (C, A), cleared to (0, 0, 0, 0), into which each slice fragment (c, a) (colour not premultiplied,
// alpha) is blended and stored in the buffer's format. The accumulator of placement "slices"
// (ProfileIntegrator::composite_slices), and of `volref explain composite`'s 8-bit blend.
//   src-alpha:      C <- c a + C (1 - a);   A <- a a + A (1 - a)  (blend_alpha src-alpha) | a + A (1 - a) (one)
//   premultiplied:  C <- (a c) + C (1 - a); A <- a + A (1 - a)
//   under (front to back, premultiplied): C <- C + (1 - A) a c; A <- A + (1 - A) a
//   max (GL_MAX):   C <- max(C, c);          A <- max(A, a)
// rgba8 blends integer codes q in [0, 255]: a fragment's channel x becomes q = R(255 clamp(x, 0, 1)); a
// blend with source code q_s and factor f_s, destination Q_d and factor f_d (factors as codes: q_a,
// 255 - q_a, 255) stores R((q_s f_s + Q_d f_d) / 255) (products "exact") or
// min(255, R(q_s f_s / 255) + R(Q_d f_d / 255)) (products "rounded", Mesa's llvmpipe); R is floor(x + 1/2)
// (rounding "nearest") or floor(x) ("truncate"). rgba32f computes in float32 (each product, the factor
// 1 - a and the sum rounded to nearest even) and stores float32; rgba16f the same, stored as binary16.
// double: no rounding.
//
// The band (`framebuffer_band`): per channel the interval [lo, hi] of what any rounding variant stores,
// carried blend by blend: rgba8 over {nearest, truncate} x {exact, rounded products} and both roundings
// of the fragment's conversion, float buffers the stored value moved one unit in the last place either
// way; every variant is non-decreasing in the stored colour (and non-increasing in the stored alpha under
// "under"), so the low end is the lowest variant at the low end and the high end the highest at the high.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/scene/Scene.h"

namespace volref {

namespace framebuffer {

// x rounded to the nearest binary16 (ties to even; subnormals below 2^-14; past 65504: infinity).
inline double to_half(double x) {
    if (x == 0.0 || !std::isfinite(x)) return x;
    int e = 0;
    std::frexp(x, &e);  // |x| = f 2^e, f in [1/2, 1)
    const int shift = std::min(11 - e, 24);  // 11 significant bits, or the subnormals' 2^-24 steps
    const double r = std::ldexp(std::nearbyint(std::ldexp(x, shift)), -shift);
    return std::fabs(r) > 65504.0 ? std::copysign(INFINITY, r) : r;
}

// x rounded to binary16 toward zero (Mesa's llvmpipe stores RGBA16F so; tests/gpu/slicing/gl_probe).
inline double to_half_toward_zero(double x) {
    if (x == 0.0 || !std::isfinite(x)) return x;
    int e = 0;
    std::frexp(x, &e);
    const int shift = std::min(11 - e, 24);
    const double r = std::ldexp(std::trunc(std::ldexp(x, shift)), -shift);
    return std::fabs(r) > 65504.0 ? std::copysign(65504.0, r) : r;
}

inline double to_float(double x) { return double(static_cast<float>(x)); }

// llvmpipe's 8-bit product of codes a, b: (t + (t >> 8) + 128) >> 8 with t = a b (round(t / 255) but for
// 24 pairs of codes >= 152, one less: 152 x 229 gives 136; tests/gpu/slicing/gl_probe checks it).
inline double llvmpipe_product(double a, double b) {
    const long t = long(a) * long(b);
    return double((t + (t >> 8) + 128) >> 8);
}

}  // namespace framebuffer

class SliceFrameBuffer {
public:
    using Format = ProfileRules::FrameBuffer;
    using Rounding = ProfileRules::Rounding;
    using Products = ProfileRules::BlendProducts;
    using Blend = ProfileRules::Blend;
    using BlendAlpha = ProfileRules::BlendAlpha;

    SliceFrameBuffer(Format f, Rounding r, Products p, Blend b, BlendAlpha ba, bool under, bool band)
        : format_(f), rounding_(r), products_(p), blend_(b), blend_alpha_(ba), under_(under), band_(band) {}

    // One fragment: colour c (not premultiplied), alpha a. `other`: the same fragment as another texture
    // unit computes it (the band: 8-bit texels filtered exactly and by llvmpipe's fixed8 filter); the
    // band's ends are taken over both.
    void blend(const glm::dvec3& c, double a, const glm::dvec4* other = nullptr) {
        const double src[4] = {c.r, c.g, c.b, a};
        const double alt[4] = {other ? other->r : c.r, other ? other->g : c.g, other ? other->b : c.b, other ? other->a : a};
        if (format_ == Format::Rgba8) {
            blend8(src, a, alt);
            return;
        }
        std::array<double, 4> next;
        for (int ch = 0; ch < 4; ++ch) {
            next[std::size_t(ch)] = blend_float(ch, src, a, v_[std::size_t(ch)], v_[3]);
            exact_[std::size_t(ch)] = blend_float(ch, src, a, v_[std::size_t(ch)], v_[3], true);
        }
        if (band_) {
            std::array<double, 4> lo = lo_, hi = hi_;
            for (int ch = 0; ch < 4; ++ch) {
                double l = next[std::size_t(ch)], h = l;
                for (const double* f : {src, alt}) {
                    l = std::min(l, blend_float(ch, f, f[3], lo_[std::size_t(ch)], under_ ? hi_[3] : lo_[3]));
                    h = std::max(h, blend_float(ch, f, f[3], hi_[std::size_t(ch)], under_ ? lo_[3] : hi_[3]));
                }
                lo[std::size_t(ch)] = l - ulp(l);
                hi[std::size_t(ch)] = h + ulp(h);
            }
            lo_ = lo;
            hi_ = hi;
        }
        v_ = next;
    }

    // The pixel as the buffer holds it (rgba8: codes / 255).
    glm::dvec4 pixel() const { return scale(v_); }
    // max over R, G, B, A of max(hi - pixel, pixel - lo) (0 without the band).
    double band() const {
        if (!band_) return 0.0;
        const glm::dvec4 p = pixel(), l = scale(lo_), h = scale(hi_);
        double b = 0.0;
        for (int ch = 0; ch < 4; ++ch) b = std::max({b, h[ch] - p[ch], p[ch] - l[ch]});
        return b;
    }
    // The last blend's result before it was stored (rgba8: before the rounding, in codes / 255; float
    // buffers: in double from the stored value): pixel() - last_exact() is that blend's rounding.
    glm::dvec4 last_exact() const { return scale(exact_); }
    glm::dvec4 low() const { return scale(lo_); }
    glm::dvec4 high() const { return scale(hi_); }

private:
    glm::dvec4 scale(const std::array<double, 4>& v) const {
        const double k = format_ == Format::Rgba8 ? 255.0 : 1.0;  // code / 255, correctly rounded
        return glm::dvec4(v[0] / k, v[1] / k, v[2] / k, v[3] / k);
    }

    double store(double x) const {
        switch (format_) {
            case Format::Rgba32f: return framebuffer::to_float(x);
            case Format::Rgba16f: return rounding_ == Rounding::Truncate ? framebuffer::to_half_toward_zero(x) : framebuffer::to_half(x);
            default: return x;
        }
    }
    double ulp(double x) const {
        const double m = std::max(std::fabs(x), 0x1p-24);
        switch (format_) {
            case Format::Rgba32f: return std::ldexp(1.0, std::ilogb(m) - 23);
            case Format::Rgba16f: return std::ldexp(1.0, std::max(std::ilogb(m) - 10, -24));
            default: return 0.0;
        }
    }

    // A float buffer's blend of channel ch over the stored value dst (dst_alpha: the stored alpha).
    double blend_float(int ch, const double* src, double a, double dst, double dst_alpha, bool unrounded = false) const {
        const bool f32 = format_ != Format::Double && !unrounded;
        auto r = [&](double x) { return f32 ? framebuffer::to_float(x) : x; };
        auto store = [&](double x) { return unrounded ? x : this->store(x); };
        const double s = r(src[ch]), sa = r(a);
        if (blend_ == Blend::Max) return store(std::max(dst, s));
        const bool alpha = ch == 3;
        if (under_) {  // C + (1 - A) (a c): the source premultiplied in the shader
            const double source = alpha ? sa : r(sa * s);
            return store(r(dst + r(r(1.0 - dst_alpha) * source)));
        }
        double source = 0.0;
        if (blend_ == Blend::Premultiplied) source = alpha ? sa : r(r(sa * s));
        else source = alpha && blend_alpha_ == BlendAlpha::One ? sa : r(s * sa);
        return store(r(source + r(dst * r(1.0 - sa))));
    }

    double round8(double x, Rounding r) const { return std::clamp(r == Rounding::Nearest ? std::floor(x + 0.5) : std::floor(x), 0.0, 255.0); }
    double code(double x, Rounding r) const { return round8(255.0 * std::clamp(x, 0.0, 1.0), r); }

    // One 8-bit blend of channel ch by one variant: source code qs, the stored dst and dst alpha codes.
    double blend8_variant(int ch, const double* src, double qa, double dst, double dst_alpha, Rounding conv, Rounding r,
                          Products p, bool unrounded = false) const {
        const bool alpha = ch == 3;
        double qs = 0.0, fs = 0.0, fd = 0.0;
        if (blend_ == Blend::Max) return std::max(dst, code(src[ch], conv));
        if (under_) {
            qs = alpha ? qa : code(src[3] * src[ch], conv);
            fs = 255.0 - dst_alpha;
            fd = 255.0;
        } else if (blend_ == Blend::Premultiplied) {
            qs = alpha ? qa : code(src[3] * src[ch], conv);
            fs = 255.0;
            fd = 255.0 - qa;
        } else {
            qs = alpha ? qa : code(src[ch], conv);
            fs = alpha && blend_alpha_ == BlendAlpha::One ? 255.0 : qa;
            fd = 255.0 - qa;
        }
        if (unrounded) return (qs * fs + dst * fd) / 255.0;
        if (p == Products::Exact) return round8((qs * fs + dst * fd) / 255.0, r);
        if (p == Products::Llvmpipe) return std::min(255.0, framebuffer::llvmpipe_product(qs, fs) + framebuffer::llvmpipe_product(dst, fd));
        return std::min(255.0, round8(qs * fs / 255.0, r) + round8(dst * fd / 255.0, r));
    }

    void blend8(const double* src, double a, const double* alt) {
        std::array<double, 4> next;
        const double qa = code(a, rounding_);
        for (int ch = 0; ch < 4; ++ch) {
            next[std::size_t(ch)] = blend8_variant(ch, src, qa, v_[std::size_t(ch)], v_[3], rounding_, rounding_, products_);
            exact_[std::size_t(ch)] = blend8_variant(ch, src, qa, v_[std::size_t(ch)], v_[3], rounding_, rounding_, products_, true);
        }
        if (band_) {
            std::array<double, 4> lo = lo_, hi = hi_;
            for (int ch = 0; ch < 4; ++ch) {
                // Of the stored values' variants the lowest is truncated products (floor p1 + floor p2 <=
                // floor(p1 + p2) <= round(p1 + p2)) or llvmpipe's (round - 1 on 24 pairs), the highest one
                // rounding to nearest, with exact, rounded or llvmpipe's products; the fragment's conversion
                // (nearest or truncated) is tried both ways.
                double l = next[std::size_t(ch)], h = l;
                for (const double* f : {src, alt})
                for (Rounding conv : {Rounding::Nearest, Rounding::Truncate}) {
                    const double qa_v = code(f[3], conv);
                    const double dlo = lo_[std::size_t(ch)], dhi = hi_[std::size_t(ch)];
                    const double alo = under_ ? hi_[3] : lo_[3], ahi = under_ ? lo_[3] : hi_[3];
                    for (Products p : {Products::Rounded, Products::Llvmpipe})
                        l = std::min(l, blend8_variant(ch, f, qa_v, dlo, alo, conv, Rounding::Truncate, p));
                    for (Products p : {Products::Exact, Products::Rounded, Products::Llvmpipe})
                        h = std::max(h, blend8_variant(ch, f, qa_v, dhi, ahi, conv, Rounding::Nearest, p));
                }
                lo[std::size_t(ch)] = l;
                hi[std::size_t(ch)] = h;
            }
            lo_ = lo;
            hi_ = hi;
        }
        v_ = next;
    }

    Format format_;
    Rounding rounding_;
    Products products_;
    Blend blend_;
    BlendAlpha blend_alpha_;
    bool under_, band_;
    std::array<double, 4> v_{0.0, 0.0, 0.0, 0.0}, exact_{0.0, 0.0, 0.0, 0.0};
    std::array<double, 4> lo_{0.0, 0.0, 0.0, 0.0}, hi_{0.0, 0.0, 0.0, 0.0};
};

}  // namespace volref
