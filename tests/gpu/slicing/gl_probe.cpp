// gl_probe: measures the GL implementation's arithmetic that a slicer's image depends on, against the
// models of docs/conventions.md ("Slice-order renderers: slices and frame buffers") and the models of
// llvmpipe (Mesa's gallivm) that tests/gpu/slicing/derive_tolerance.py takes:
//
//   convert   a float fragment x stored in GL_RGBA8, for the floats next to every rounding tie
//             (k + 1/2) / 255: against floor(255 x + 1/2), RNE(255 x) and llvmpipe's
//             q = RNE(fl(x 255/256) 256) (x (255/256) + 2^15 in float, the low 8 bits of the mantissa)
//   blend8    every (q_src, q_a, Q_dst) in 0..255^3 through GL_RGBA8 blending, for src-alpha (alpha
//             src-alpha and ONE), premultiplied (ONE, ONE_MINUS_SRC_ALPHA), the under operator
//             (ONE_MINUS_DST_ALPHA, ONE) and GL_MAX: against the contract's "exact" R((q_src f_src +
//             Q_dst f_dst) / 255) and "rounded" R(q_src f_src / 255) + R(Q_dst f_dst / 255) saturated (R
//             nearest or truncate), and llvmpipe's products mul8(a, f) = (t + (t >> 8) + 128) >> 8, t = a f
//             (f = 255: a), summed and saturated
//   blend8f   random float fragments over codes: is a fragment converted to codes (convert's q) first and
//             then blended with llvmpipe's products?
//   blendf    random (c, a, d) in [0, 1] through GL_RGBA32F and GL_RGBA16F src-alpha blending: float32
//             c a + d (1 - a) with each product and the sum rounded, or fused; binary16 storage to
//             nearest even or toward zero
//   filter    GL_LINEAR reads of 3D textures (GL_R8, GL_R16, GL_R32F), a 2D array (GL_R8) and 1D tables
//             (GL_RGBA8, GL_RGBA32F) at random points: against exact weights of the stored values, and
//             (8-bit formats) llvmpipe's 8.8 fixed-point filter (taps8 / lerp8 below)
//   texel8    every code of an 8-bit texture as the shader reads it: against float(k / 255) and llvmpipe's
//             fl(k fl(1/255)) (--filter fixed8 requires the latter: it addresses the 1D table)
//   interp    a perspective polygon's interpolated world position at the pixel centres against the
//             exact crossing of the pixel's ray (are attributes interpolated from snapped vertices? how far
//             off are they?): an oblique square, and a slice of viewport-volumizer's box
//
//   gl_probe [--require-renderer S] [--egl-device] [--check [--filter exact|fixed8]]
// prints one line per measurement. With --check it exits 1 unless llvmpipe's models hold exactly
// (conversion, products, conversion before the blend, unfused float32 blends, binary16 storage either
// way) and, with --filter, the 8-bit formats filter with exact weights (exact: every read within 2e-7) or
// by the 8.8 fixed-point model (fixed8: every read).
// Exit status: 0; 1 no GL context, a GL error, or (--check) a model that does not hold.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "tests/gpu/gl_context.h"

namespace {

using gl_headless::check_gl;
using gl_headless::gl_fail;

const char* kQuadVs = "#version 330 core\nvoid main() {\n"
                      "  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);\n"
                      "  gl_Position = vec4(p, 0.0, 1.0);\n}\n";

// Round to nearest, ties to even, of a non-negative double.
double rne(double x) { return std::nearbyint(x); }

// binary16 rounding of a float in [0, 1] (normal and subnormal range), as a float: to nearest even, or
// toward zero (`truncate`).
float to_half(float x, bool truncate) {
    if (x == 0.0f) return 0.0f;
    int e = 0;
    std::frexp(x, &e);                                   // x = m 2^e, m in [0.5, 1)
    const int exp = std::max(e - 1, -14);                // binary16: 10 fraction bits, min normal 2^-14
    const double ulp = std::ldexp(1.0, exp - 10);
    return float((truncate ? std::floor(double(x) / ulp) : std::nearbyint(double(x) / ulp)) * ulp);
}

// A texture of floats (GL_RGBA32F, 2D, W x H) read with texelFetch: exact inputs for the fragment shader.
GLuint float_texture(const std::vector<float>& rgba, int W, int H, GLenum unit) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glActiveTexture(unit);
    glBindTexture(GL_TEXTURE_2D, t);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, W, H, 0, GL_RGBA, GL_FLOAT, rgba.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    check_gl("float texture");
    return t;
}

struct Gl {
    GLuint vao = 0;
    void draw() const {
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
};

// Fragment shader writing texelFetch(u_in, pixel) (an exact float per channel).
const char* kCopyFs = "#version 330 core\nuniform sampler2D u_in; out vec4 o;\n"
                      "void main() { o = texelFetch(u_in, ivec2(gl_FragCoord.xy), 0); }\n";

std::vector<std::uint8_t> read_bytes(int W, int H) {
    std::vector<std::uint8_t> px(std::size_t(W) * std::size_t(H) * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    check_gl("read bytes");
    return px;
}

std::vector<float> read_floats(int W, int H) {
    std::vector<float> px(std::size_t(W) * std::size_t(H) * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_FLOAT, px.data());
    check_gl("read floats");
    return px;
}

// --- convert: float -> unorm8 near every tie --------------------------------------------------------
bool probe_convert(const Gl& gl, bool& convert_holds) {
    const int W = 512, H = 255;  // row k: floats around (k + 1/2) / 255, 512 consecutive floats
    std::vector<float> in(std::size_t(W) * H * 4);
    for (int k = 0; k < H; ++k) {
        float x = float((k + 0.5) / 255.0);
        for (int j = 0; j < W / 2; ++j) x = std::nextafter(x, 0.0f);
        for (int j = 0; j < W; ++j, x = std::nextafter(x, 2.0f))
            for (int c = 0; c < 4; ++c) in[(std::size_t(k) * W + std::size_t(j)) * 4 + std::size_t(c)] = x;
    }
    const GLuint tex = float_texture(in, W, H, GL_TEXTURE1);
    gl_headless::make_framebuffer(GL_RGBA8, W, H);
    const GLuint prog = gl_headless::link_program(kQuadVs, kCopyFs);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_in"), 1);
    gl.draw();
    const auto px = read_bytes(W, H);
    long miss_nearest = 0, miss_llvmpipe = 0, miss_ties_even = 0;
    double worst_before = 0, worst_after = 0;  // how far before / past the tie the code switches (in 1/255 units)
    for (int k = 0; k < H; ++k)
        for (int j = 0; j < W; ++j) {
            const float x = in[(std::size_t(k) * W + std::size_t(j)) * 4];
            const int q = px[(std::size_t(k) * W + std::size_t(j)) * 4];
            const double exact = 255.0 * double(x);
            const int nearest = int(std::floor(exact + 0.5));
            const int even = int(rne(exact));
            const float scaled = x * (255.0f / 256.0f);  // llvmpipe: fl(x * 255/256), then + 2^15 rounds to 1/256
            const int lp = int(rne(double(scaled) * 256.0));
            miss_nearest += q != nearest;
            miss_ties_even += q != even;
            miss_llvmpipe += q != lp;
            if (q == k + 1 && exact < k + 0.5) worst_before = std::max(worst_before, k + 0.5 - exact);
            if (q == k && exact > k + 0.5) worst_after = std::max(worst_after, exact - (k + 0.5));
        }
    std::printf("convert: %d floats next to the 255 ties (k + 1/2) / 255: codes unlike floor(255 x + 1/2) %ld, unlike "
                "RNE(255 x) %ld, unlike llvmpipe's RNE(fl(x 255/256) 256) %ld; the code switches up to %.3g codes before "
                "the tie and %.3g after it\n",
                W * H, miss_nearest, miss_ties_even, miss_llvmpipe, worst_before, worst_after);
    glDeleteTextures(1, &tex);
    convert_holds = miss_llvmpipe == 0;
    return true;
}

// --- blend8: every (q_src, q_a, Q_dst) --------------------------------------------------------------
struct Blend8Result {
    long exact_n = 0, exact_t = 0, rounded_n = 0, rounded_t = 0, llvmpipe = 0;  // mismatches per model
    long total = 0;
};

int R(double x, bool nearest) { return int(nearest ? std::floor(x + 0.5) : std::floor(x)); }

// llvmpipe's unorm8 product (gallivm lp_build_mul_norm): t = a b, (t + (t >> 8) + 128) >> 8. It equals
// round(a b / 255) except for 24 of the 65536 pairs (e.g. 152 x 229: 136, not 137), where it is one less.
// A factor ONE (255) passes the value through unmultiplied.
int mul8(int a, int f) {
    if (f == 255) return a;
    const int t = a * f;
    return (t + (t >> 8) + 128) >> 8;
}

bool probe_blend8(const Gl& gl, bool& rounded_nearest_holds) {
    const int W = 4096, H = 4096;  // pixel p = y W + x: Q_dst = p & 255, q_a = (p >> 8) & 255, q_src = p >> 16
    gl_headless::make_framebuffer(GL_RGBA8, W, H);
    // Pass 1 (no blend) writes Q_dst / 255 in R, G, B, A (G: q_src's complement 255 - Q, so both colour
    // channels are exercised); pass 2 blends the fragment (q_src / 255, (255 - q_src) / 255, q_a / 255, q_a / 255).
    const std::string fs_dst = "#version 330 core\nout vec4 o;\nvoid main() {\n"
                               "  int p = int(gl_FragCoord.y) * 4096 + int(gl_FragCoord.x);\n"
                               "  float Q = float(p & 255);\n"
                               "  o = vec4(Q, 255.0 - Q, Q, Q) / 255.0;\n}\n";
    const std::string fs_src = "#version 330 core\nout vec4 o;\nvoid main() {\n"
                               "  int p = int(gl_FragCoord.y) * 4096 + int(gl_FragCoord.x);\n"
                               "  float qa = float((p >> 8) & 255), qs = float(p >> 16);\n"
                               "  o = vec4(qs, 255.0 - qs, qa, qa) / 255.0;\n}\n";
    const GLuint pd = gl_headless::link_program(kQuadVs, fs_dst), ps = gl_headless::link_program(kQuadVs, fs_src);
    struct Mode {
        const char* name;
        int kind;  // 0 src-alpha (alpha src-alpha), 1 src-alpha with alpha ONE, 2 premultiplied, 3 under, 4 max
    };
    const Mode modes[] = {{"src-alpha", 0}, {"src-alpha/alpha-one", 1}, {"premultiplied", 2}, {"under", 3}, {"max", 4}};
    rounded_nearest_holds = true;
    for (const Mode& m : modes) {
        glDisable(GL_BLEND);
        glUseProgram(pd);
        gl.draw();
        glEnable(GL_BLEND);
        glBlendEquation(m.kind == 4 ? GL_MAX : GL_FUNC_ADD);
        if (m.kind == 0) glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        if (m.kind == 1) glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        if (m.kind == 2) glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        if (m.kind == 3) glBlendFunc(GL_ONE_MINUS_DST_ALPHA, GL_ONE);
        glUseProgram(ps);
        gl.draw();
        glDisable(GL_BLEND);
        glBlendEquation(GL_FUNC_ADD);
        const auto px = read_bytes(W, H);
        Blend8Result r;
        long max_miss = 0;
        for (int p = 0; p < W * H; ++p) {
            const int Q = p & 255, qa = (p >> 8) & 255, qs = p >> 16;
            const int src[4] = {qs, 255 - qs, qa, qa};
            const int dst[4] = {Q, 255 - Q, Q, Q};
            for (int c = 0; c < 4; ++c) {
                const int got = px[std::size_t(p) * 4 + std::size_t(c)];
                if (m.kind == 4) {
                    max_miss += got != std::max(src[c], dst[c]);
                    continue;
                }
                // the factors' codes: f_src, f_dst
                int fs = 0, fd = 0;
                if (m.kind == 0) fs = qa, fd = 255 - qa;
                if (m.kind == 1) fs = c == 3 ? 255 : qa, fd = 255 - qa;
                if (m.kind == 2) fs = 255, fd = 255 - qa;
                if (m.kind == 3) fs = 255 - Q, fd = 255;  // Q_dst alpha = Q (channel A holds Q)
                const double ps_ = double(src[c]) * fs / 255.0, pd_ = double(dst[c]) * fd / 255.0;
                for (int nearest = 0; nearest < 2; ++nearest) {
                    const int ex = std::min(255, R(ps_ + pd_, nearest));
                    const int ro = std::min(255, R(ps_, nearest) + R(pd_, nearest));
                    (nearest ? r.exact_n : r.exact_t) += got != ex;
                    (nearest ? r.rounded_n : r.rounded_t) += got != ro;
                }
                r.llvmpipe += got != std::min(255, mul8(src[c], fs) + mul8(dst[c], fd));
                ++r.total;
            }
        }
        if (m.kind == 4) {
            std::printf("blend8 %s: %d channel values, unlike max(src, dst) %ld\n", m.name, W * H * 4, max_miss);
            rounded_nearest_holds &= max_miss == 0;
        } else {
            std::printf("blend8 %s: %ld channel values; mismatches: exact/nearest %ld, exact/truncate %ld, rounded/nearest "
                        "%ld, rounded/truncate %ld, llvmpipe's products (t + (t >> 8) + 128) >> 8 %ld\n",
                        m.name, r.total, r.exact_n, r.exact_t, r.rounded_n, r.rounded_t, r.llvmpipe);
            rounded_nearest_holds &= r.llvmpipe == 0;
        }
    }
    glDeleteProgram(pd);
    glDeleteProgram(ps);
    return true;
}

// --- blend8f: non-code fragments over codes -----------------------------------------------------------
bool probe_blend8f(const Gl& gl, bool& converted_holds) {
    const int W = 1024, H = 1024;
    std::mt19937 rng(54);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    std::uniform_int_distribution<int> C(0, 255);
    std::vector<float> dst(std::size_t(W) * H * 4), src(std::size_t(W) * H * 4);
    for (std::size_t i = 0; i < dst.size(); ++i) dst[i] = float(C(rng)) / 255.0f, src[i] = U(rng);
    const GLuint td = float_texture(dst, W, H, GL_TEXTURE1), ts = float_texture(src, W, H, GL_TEXTURE2);
    gl_headless::make_framebuffer(GL_RGBA8, W, H);
    const GLuint prog = gl_headless::link_program(kQuadVs, kCopyFs);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_in"), 1);
    gl.draw();
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUniform1i(glGetUniformLocation(prog, "u_in"), 2);
    gl.draw();
    glDisable(GL_BLEND);
    const auto px = read_bytes(W, H);
    auto q = [](float x) { return int(rne(double(x * (255.0f / 256.0f)) * 256.0)); };
    long miss_converted = 0, miss_float = 0, total = 0;
    for (std::size_t p = 0; p < std::size_t(W) * H; ++p) {
        const float a = src[p * 4 + 3];
        for (int c = 0; c < 4; ++c) {
            const int got = px[p * 4 + std::size_t(c)];
            const int Q = int(std::lround(dst[p * 4 + std::size_t(c)] * 255.0f));
            const int qs = q(src[p * 4 + std::size_t(c)]), qa = q(a);
            const int conv = std::min(255, mul8(qs, qa) + mul8(Q, 255 - qa));
            // the blend in float on the fragment as it is, then one conversion
            const double fl = double(src[p * 4 + std::size_t(c)]) * a + double(Q) / 255.0 * (1.0 - a);
            miss_converted += got != conv;
            miss_float += got != int(std::floor(255.0 * fl + 0.5));
            ++total;
        }
    }
    std::printf("blend8f src-alpha, random float fragments over random codes: %ld channel values; unlike "
                "'fragment converted to codes q(c), q(a), then llvmpipe's products' %ld; unlike 'blend in float, one "
                "rounding' %ld\n",
                total, miss_converted, miss_float);
    converted_holds = miss_converted == 0;
    glDeleteTextures(1, &td);
    glDeleteTextures(1, &ts);
    glDeleteProgram(prog);
    return true;
}

// --- blendf: float frame buffers -----------------------------------------------------------------------
bool probe_blendf(const Gl& gl, bool& float_holds, bool& half_truncates) {
    const int W = 1024, H = 1024;
    std::mt19937 rng(16);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    std::vector<float> dst(std::size_t(W) * H * 4), src(std::size_t(W) * H * 4);
    for (std::size_t i = 0; i < dst.size(); ++i) dst[i] = U(rng), src[i] = U(rng);
    const GLuint td = float_texture(dst, W, H, GL_TEXTURE1), ts = float_texture(src, W, H, GL_TEXTURE2);
    const GLuint prog = gl_headless::link_program(kQuadVs, kCopyFs);
    float_holds = true;
    for (const GLenum fmt : {GL_RGBA32F, GL_RGBA16F}) {
        const bool half = fmt == GL_RGBA16F;
        gl_headless::make_framebuffer(fmt, W, H);
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_in"), 1);
        gl.draw();
        const auto stored = read_floats(W, H);
        long store_miss[2] = {0, 0};  // binary16 nearest-even, toward zero
        for (std::size_t i = 0; i < dst.size(); ++i)
            for (int t = 0; t < 2; ++t) store_miss[t] += stored[i] != (half ? to_half(dst[i], t == 1) : dst[i]);
        const bool truncate = half && store_miss[1] < store_miss[0];
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        glUniform1i(glGetUniformLocation(prog, "u_in"), 2);
        gl.draw();
        glDisable(GL_BLEND);
        const auto px = read_floats(W, H);
        long miss_plain = 0, miss_fused = 0, miss_both = 0;
        for (std::size_t p = 0; p < std::size_t(W) * H; ++p) {
            const float a = src[p * 4 + 3];
            for (int c = 0; c < 4; ++c) {
                const std::size_t i = p * 4 + std::size_t(c);
                const float d = half ? to_half(dst[i], truncate) : dst[i];
                const float one_minus = 1.0f - a;
                volatile float prod_s = src[i] * a, prod_d = d * one_minus;  // each product rounded
                float plain = prod_s + prod_d;
                float fused = std::fma(d, one_minus, float(src[i] * a));
                if (half) plain = to_half(plain, truncate), fused = to_half(fused, truncate);
                miss_plain += px[i] != plain;
                miss_fused += px[i] != fused;
                miss_both += px[i] != plain && px[i] != fused;
            }
        }
        if (half)
            std::printf("blendf rgba16f: %zu stored floats unlike binary16 nearest-even %ld, unlike binary16 toward zero %ld\n",
                        dst.size(), store_miss[0], store_miss[1]);
        std::printf("blendf %s src-alpha: %zu channel values; results unlike float32 c a + d (1 - a) (products and sum "
                    "rounded%s) %ld, unlike fused d (1 - a) + fl(c a) %ld, unlike both %ld\n",
                    half ? "rgba16f" : "rgba32f", dst.size(), half ? (truncate ? ", stored toward zero" : ", stored nearest-even") : "",
                    miss_plain, miss_fused, miss_both);
        half_truncates = truncate;
        float_holds &= store_miss[truncate ? 1 : 0] == 0 && miss_plain == 0;
    }
    glDeleteTextures(1, &td);
    glDeleteTextures(1, &ts);
    glDeleteProgram(prog);
    return true;
}

// --- filter: linear texture reads --------------------------------------------------------------------
// Exact linear weights at texture coordinate u on n texels (GL_CLAMP_TO_EDGE): i0 = floor(u n - 1/2),
// w = u n - 1/2 - i0, taps clamped to [0, n - 1].
struct Taps {
    int i0, i1;
    double w;
};
Taps taps(double u, int n) {
    const double x = u * n - 0.5;
    const double i = std::floor(x), w = x - i;
    const int i0 = std::clamp(int(i), 0, n - 1), i1 = std::clamp(int(i) + 1, 0, n - 1);
    return {i0, i1, w};
}

// llvmpipe's 8-bit filtering (gallivm's AoS sampler, lp_bld_sample_aos.c, for formats that fit in unorm8):
// the texel coordinate in 8.8 fixed point, i = RNE(fl(u (256 n))) - 128 (iround of the coordinate times
// the size shifted left by 8, minus a half texel), tap i >> 8, weight w = i & 255 (of 256); each lerp in
// integer codes v0 + ((w (v1 - v0) + 128) >> 8) (pmulhrsw: (w (delta << 7) + 2^14) >> 15), x first, then
// y, then z.
struct Taps8 {
    int i0, i1, w;
};
Taps8 taps8(float u, int n) {
    const int fixed = int(std::nearbyint(u * float(n * 256))) - 128;
    const int i = fixed >> 8, w = fixed & 255;
    return {std::clamp(i, 0, n - 1), std::clamp(i + 1, 0, n - 1), w};
}
int lerp8(int w, int v0, int v1) { return v0 + ((w * (v1 - v0) + 128) >> 8); }

// exact_holds: every read within 2e-7 of exact weights; fixed8_holds: every 8-bit read as taps8/lerp8.
bool probe_filter(const Gl& gl, bool& exact_holds, bool& fixed8_holds) {
    exact_holds = fixed8_holds = true;
    const int n = 8;
    const int W = 256, H = 64;  // W H random sample points per texture
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> U(-0.05f, 1.05f);
    std::uniform_int_distribution<int> C(0, 255);
    std::uniform_int_distribution<int> C16(0, 65535);
    std::vector<float> coords(std::size_t(W) * H * 4);
    for (float& c : coords) c = U(rng);
    const GLuint tc = float_texture(coords, W, H, GL_TEXTURE1);
    gl_headless::make_framebuffer(GL_RGBA32F, W, H);
    struct Case {
        const char* name;
        GLenum target, internal, type;
    };
    const Case cases[] = {{"3d R8", GL_TEXTURE_3D, GL_R8, GL_UNSIGNED_BYTE},
                          {"3d R16", GL_TEXTURE_3D, GL_R16, GL_UNSIGNED_SHORT},
                          {"3d R32F", GL_TEXTURE_3D, GL_R32F, GL_FLOAT},
                          {"2d-array R8", GL_TEXTURE_2D_ARRAY, GL_R8, GL_UNSIGNED_BYTE},
                          {"1d RGBA8", GL_TEXTURE_1D, GL_RGBA8, GL_UNSIGNED_BYTE},
                          {"1d RGBA32F", GL_TEXTURE_1D, GL_RGBA32F, GL_FLOAT}};
    for (const Case& cs : cases) {
        const int texels = cs.target == GL_TEXTURE_1D ? n * 4 : n * n * n;  // 1D: n RGBA texels
        std::vector<double> value(static_cast<std::size_t>(texels));
        std::vector<std::uint8_t> b8(static_cast<std::size_t>(texels));
        std::vector<std::uint16_t> b16(static_cast<std::size_t>(texels));
        std::vector<float> f32(static_cast<std::size_t>(texels));
        for (int i = 0; i < texels; ++i) {
            if (cs.type == GL_UNSIGNED_BYTE) b8[std::size_t(i)] = std::uint8_t(C(rng)), value[std::size_t(i)] = b8[std::size_t(i)] / 255.0;
            if (cs.type == GL_UNSIGNED_SHORT) b16[std::size_t(i)] = std::uint16_t(C16(rng)), value[std::size_t(i)] = b16[std::size_t(i)] / 65535.0;
            if (cs.type == GL_FLOAT) f32[std::size_t(i)] = float(C16(rng)) / 65535.0f, value[std::size_t(i)] = f32[std::size_t(i)];
        }
        const void* data = cs.type == GL_UNSIGNED_BYTE ? static_cast<const void*>(b8.data())
                           : cs.type == GL_UNSIGNED_SHORT ? static_cast<const void*>(b16.data())
                                                          : static_cast<const void*>(f32.data());
        GLuint t = 0;
        glGenTextures(1, &t);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(cs.target, t);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        const GLenum fmt = cs.target == GL_TEXTURE_1D ? GL_RGBA : GL_RED;
        if (cs.target == GL_TEXTURE_1D) glTexImage1D(cs.target, 0, GLint(cs.internal), n, 0, fmt, cs.type, data);
        else glTexImage3D(cs.target, 0, GLint(cs.internal), n, n, n, 0, fmt, cs.type, data);
        glTexParameteri(cs.target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(cs.target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTexParameteri(cs.target, w, GL_CLAMP_TO_EDGE);
        check_gl("filter texture");
        const char* sampler = cs.target == GL_TEXTURE_3D ? "sampler3D" : cs.target == GL_TEXTURE_2D_ARRAY ? "sampler2DArray" : "sampler1D";
        // 2D array: the layer is the integer nearest to p.z (n - 1) (a layer index, no filtering across)
        const char* read = cs.target == GL_TEXTURE_3D ? "texture(u_t, p.xyz)"
                           : cs.target == GL_TEXTURE_2D_ARRAY ? "texture(u_t, vec3(p.xy, floor(p.z * 7.0 + 0.5)))"
                                                              : "texture(u_t, p.x)";
        const std::string fs = std::string("#version 330 core\nuniform sampler2D u_in; uniform ") + sampler +
                               " u_t; out vec4 o;\nvoid main() {\n  vec4 p = texelFetch(u_in, ivec2(gl_FragCoord.xy), 0);\n"
                               "  o = vec4(" + read + ");\n}\n";
        const GLuint prog = gl_headless::link_program(kQuadVs, fs);
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_in"), 1);
        glUniform1i(glGetUniformLocation(prog, "u_t"), 0);
        gl.draw();
        const auto px = read_floats(W, H);
        double err_exact = 0;
        long aos_miss = 0;
        for (std::size_t p = 0; p < std::size_t(W) * H; ++p) {
            const float* c = &coords[p * 4];
            for (int ch = 0; ch < (cs.target == GL_TEXTURE_1D ? 4 : 1); ++ch) {
                double v = 0;  // exact weights, in double
                if (cs.target == GL_TEXTURE_1D) {
                    const Taps a = taps(c[0], n);
                    v = (1 - a.w) * value[std::size_t(a.i0 * 4 + ch)] + a.w * value[std::size_t(a.i1 * 4 + ch)];
                } else {
                    const Taps a = taps(c[0], n), b = taps(c[1], n);
                    Taps z = taps(c[2], n);
                    if (cs.target == GL_TEXTURE_2D_ARRAY) {
                        const int layer = std::clamp(int(std::floor(double(float(c[2] * 7.0f)) + 0.5)), 0, n - 1);
                        z = {layer, layer, 0.0};
                    }
                    auto at = [&](int i, int j, int k) { return value[std::size_t((k * n + j) * n + i)]; };
                    for (int dk = 0; dk < 2; ++dk)
                        for (int dj = 0; dj < 2; ++dj)
                            for (int di = 0; di < 2; ++di)
                                v += (di ? a.w : 1 - a.w) * (dj ? b.w : 1 - b.w) * (dk ? z.w : 1 - z.w) *
                                     at(di ? a.i1 : a.i0, dj ? b.i1 : b.i0, dk ? z.i1 : z.i0);
                }
                const double got = px[p * 4 + std::size_t(ch)];
                err_exact = std::max(err_exact, std::fabs(got - v));
                if (cs.type == GL_UNSIGNED_BYTE) {
                    int code = 0;
                    if (cs.target == GL_TEXTURE_1D) {
                        const Taps8 a = taps8(c[0], n);
                        code = lerp8(a.w, b8[std::size_t(a.i0 * 4 + ch)], b8[std::size_t(a.i1 * 4 + ch)]);
                    } else {
                        const Taps8 a = taps8(c[0], n), b = taps8(c[1], n);
                        Taps8 z = taps8(c[2], n);
                        if (cs.target == GL_TEXTURE_2D_ARRAY) {
                            const int layer = std::clamp(int(std::floor(double(float(c[2] * 7.0f)) + 0.5)), 0, n - 1);
                            z = {layer, layer, 0};
                        }
                        auto at = [&](int i, int j, int k) { return int(b8[std::size_t((k * n + j) * n + i)]); };
                        int zs[2];
                        for (int dk = 0; dk < 2; ++dk) {
                            const int k = dk ? z.i1 : z.i0;
                            const int r0 = lerp8(a.w, at(a.i0, b.i0, k), at(a.i1, b.i0, k));
                            const int r1 = lerp8(a.w, at(a.i0, b.i1, k), at(a.i1, b.i1, k));
                            zs[dk] = lerp8(b.w, r0, r1);
                        }
                        code = lerp8(z.w, zs[0], zs[1]);
                    }
                    aos_miss += std::fabs(got - code / 255.0) > 1e-7;
                }
            }
        }
        std::printf("filter %s GL_LINEAR at %d random points: max |read - exact weights| %.3g (%.3g codes of 255)%s\n",
                    cs.name, W * H, err_exact, err_exact * 255.0,
                    cs.type == GL_UNSIGNED_BYTE ? (", unlike llvmpipe's 8-bit fixed-point lerps: " + std::to_string(aos_miss)).c_str() : "");
        exact_holds &= err_exact <= 2e-7;
        if (cs.type == GL_UNSIGNED_BYTE) fixed8_holds &= aos_miss == 0;
        glDeleteProgram(prog);
        glDeleteTextures(1, &t);
    }
    glDeleteTextures(1, &tc);
    return true;
}

// --- texel8: an 8-bit texel as the shader sees it ---------------------------------------------------------
// Every code k of a GL_R8 texture read by texelFetch and by GL_LINEAR at its centre, into RGBA32F: against
// the correctly rounded float(k / 255) and llvmpipe's fl(k fl(1/255)) (what a fixed8 value becomes before
// it addresses the 1D table; derive_tolerance.py's fixed8_fragments).
bool probe_texel8(const Gl& gl, bool& holds) {
    std::vector<std::uint8_t> codes(256);
    for (int k = 0; k < 256; ++k) codes[std::size_t(k)] = std::uint8_t(k);
    GLuint t = 0;
    glGenTextures(1, &t);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_3D, t);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R8, 256, 1, 1, 0, GL_RED, GL_UNSIGNED_BYTE, codes.data());
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl_headless::make_framebuffer(GL_RGBA32F, 256, 1);
    const GLuint prog = gl_headless::link_program(
        kQuadVs, "#version 330 core\nuniform sampler3D u_t; out vec4 o;\nvoid main() {\n"
                 "  o = vec4(texelFetch(u_t, ivec3(int(gl_FragCoord.x), 0, 0), 0).r,\n"
                 "           texture(u_t, vec3(gl_FragCoord.x / 256.0, 0.5, 0.5)).r, 0.0, 1.0);\n}\n");
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_t"), 0);
    gl.draw();
    const auto px = read_floats(256, 1);
    long miss_rounded = 0, miss_llvmpipe = 0;
    for (int k = 0; k < 256; ++k)
        for (int c = 0; c < 2; ++c) {
            const float got = px[std::size_t(k) * 4 + std::size_t(c)];
            miss_rounded += got != float(k / 255.0);
            miss_llvmpipe += got != float(k) * (1.0f / 255.0f);
        }
    std::printf("texel8: the 256 codes of GL_R8 (texelFetch and GL_LINEAR at the centre) as floats: unlike float(k / 255) "
                "%ld, unlike fl(k fl(1/255)) %ld\n", miss_rounded, miss_llvmpipe);
    holds = miss_llvmpipe == 0;
    glDeleteProgram(prog);
    glDeleteTextures(1, &t);
    return true;
}

// --- interp: a plane's world position at the pixel centres ---------------------------------------------
// An oblique square drawn under a perspective camera (eye E, forward f, fov 40, 128 x 128) with its world
// position as the attribute: at each covered pixel the interpolated position against the exact crossing of
// the pixel centre's ray with the plane (in double), in world units and in pixels (of the crossing's
// screen footprint). Rasterisers that interpolate over vertices snapped to 1/256 pixel are off by up to
// ~1/512 pixel; plane equations from the float vertices are off by float rounding only.
// `E`, `T`: the camera; the plane through T with normal `n0` (null: the view direction, a viewport slice);
// a square of half-size `half` around T in it.
bool probe_interp(const char* name, const double* E, const double* T, const double* n0, double half, double fov) {
    const int W = 128, H = 128;
    const double up[3] = {0, 0, 1};
    auto sub = [](const double* a, const double* b, double* o) { for (int i = 0; i < 3; ++i) o[i] = a[i] - b[i]; };
    auto dot = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    auto cross = [](const double* a, const double* b, double* o) {
        o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
    };
    auto norm = [&](double* a) { const double l = std::sqrt(dot(a, a)); for (int i = 0; i < 3; ++i) a[i] /= l; };
    double f[3], r[3], u[3];
    sub(T, E, f), norm(f), cross(f, up, r), norm(r), cross(r, f, u);
    const double tan_half = std::tan(fov / 2 * 3.14159265358979323846 / 180.0), aspect = 1.0, zn = 1.0, zf = 400.0;
    // view-projection (column-major): rows of the view are r, u, -f; perspective as glm::perspective
    double V[16] = {0}, P[16] = {0}, M[16] = {0};
    for (int i = 0; i < 3; ++i) V[i * 4 + 0] = r[i], V[i * 4 + 1] = u[i], V[i * 4 + 2] = -f[i];
    V[12] = -dot(r, E), V[13] = -dot(u, E), V[14] = dot(f, E), V[15] = 1;
    P[0] = 1 / (aspect * tan_half), P[5] = 1 / tan_half, P[10] = -(zf + zn) / (zf - zn), P[11] = -1, P[14] = -2 * zf * zn / (zf - zn);
    for (int c = 0; c < 4; ++c)
        for (int rr = 0; rr < 4; ++rr)
            for (int k = 0; k < 4; ++k) M[c * 4 + rr] += P[k * 4 + rr] * V[c * 4 + k];
    // the plane: n . x = n . T, n oblique; a square of half-size 60 around T in the plane
    double n[3] = {n0 ? n0[0] : f[0], n0 ? n0[1] : f[1], n0 ? n0[2] : f[2]}, a[3], b[3];
    norm(n), cross(n, up, a), norm(a), cross(n, a, b);
    float verts[4][3];
    const int sq[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int v = 0; v < 4; ++v)
        for (int i = 0; i < 3; ++i) verts[v][i] = float(T[i] + half * (sq[v][0] * a[i] + sq[v][1] * b[i]));
    GLuint vao = 0, vbo = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof verts, verts, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(0);
    const char* vs = "#version 330 core\nlayout(location = 0) in vec3 p; uniform mat4 u_m; out vec3 v_p;\n"
                     "void main() { v_p = p; gl_Position = u_m * vec4(p, 1.0); }\n";
    const char* fs = "#version 330 core\nin vec3 v_p; out vec4 o;\nvoid main() { o = vec4(v_p, 1.0); }\n";
    const GLuint prog = gl_headless::link_program(vs, fs);
    glUseProgram(prog);
    float Mf[16];
    for (int i = 0; i < 16; ++i) Mf[i] = float(M[i]);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_m"), 1, GL_FALSE, Mf);
    gl_headless::make_framebuffer(GL_RGBA32F, W, H);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glDrawArrays(GL_TRIANGLE_FAN, 0, 4);
    const auto px = read_floats(W, H);
    double worst = 0, worst_px = 0, sum = 0, X = 0;
    long covered = 0;
    for (int v = 0; v < 4; ++v) X = std::max(X, std::sqrt(double(verts[v][0]) * verts[v][0] + double(verts[v][1]) * verts[v][1] + double(verts[v][2]) * verts[v][2]));
    X = std::max(X, std::sqrt(E[0] * E[0] + E[1] * E[1] + E[2] * E[2]));
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* c = &px[(std::size_t(y) * W + std::size_t(x)) * 4];
            if (c[3] == 0) continue;
            ++covered;
            // the ray through the pixel centre (GL row y from the bottom)
            const double nx = 2.0 * (x + 0.5) / W - 1.0, ny = 2.0 * (y + 0.5) / H - 1.0;
            double d[3];
            for (int i = 0; i < 3; ++i) d[i] = f[i] + nx * tan_half * aspect * r[i] + ny * tan_half * u[i];
            norm(d);
            double q[3];
            sub(T, E, q);
            const double t = dot(n, q) / dot(n, d);
            double e2 = 0;
            for (int i = 0; i < 3; ++i) e2 += (c[i] - (E[i] + t * d[i])) * (c[i] - (E[i] + t * d[i]));
            // a pixel's footprint on the plane at distance t: 2 t tan_half / H / |n . d|
            const double footprint = 2.0 * t * tan_half / H / std::fabs(dot(n, d));
            worst = std::max(worst, std::sqrt(e2));
            sum += std::sqrt(e2);
            worst_px = std::max(worst_px, std::sqrt(e2) / footprint);
        }
    const double ulp = std::ldexp(1.0, -24);
    std::printf("interp %s: %ld covered pixels: |interpolated - exact crossing| max %.3g "
                "world units = %.3g u X, mean %.3g = %.3g u X (X = %.3g, the largest |vertex|, |E|); max %.3g pixels "
                "(1/256 pixel = %.3g)\n",
                name, covered, worst, worst / (ulp * X), sum / double(covered), sum / double(covered) / (ulp * X), X, worst_px, 1.0 / 256);
    glDeleteProgram(prog);
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    return true;
}

int run(int argc, char** argv) {
    std::string require_renderer;
    bool egl_device = false, check = false;
    std::string filter;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--require-renderer" && i + 1 < argc) require_renderer = argv[++i];
        else if (a == "--egl-device") egl_device = true;
        else if (a == "--check") check = true;
        else if (a == "--filter" && i + 1 < argc) filter = argv[++i];
        else gl_fail(2, "usage: gl_probe [--require-renderer S] [--egl-device] [--check [--filter exact|fixed8]]");
    }
    gl_headless::make_context("gl_probe", require_renderer, egl_device);
    Gl gl;
    glGenVertexArrays(1, &gl.vao);
    bool rounded = false, converted = false, floats = false, convert = false, exact = false, fixed8 = false;
    probe_convert(gl, convert);
    probe_blend8(gl, rounded);
    probe_blend8f(gl, converted);
    bool half_truncates = false;
    probe_blendf(gl, floats, half_truncates);
    probe_filter(gl, exact, fixed8);
    bool texel8 = false;
    probe_texel8(gl, texel8);
    {
        const double E1[3] = {70.3, -41.7, 55.1}, T1[3] = {20.2, 21.9, 19.7}, n1[3] = {0.3, 0.5, 0.81};
        probe_interp("oblique square (half-size 60, fov 40)", E1, T1, n1, 60.0, 40.0);
        const double E2[3] = {95.3, -41.2, 70.4}, T2[3] = {23.5, 23.5, 23.5};
        probe_interp("viewport slice of a 48^3 box (half-size 24, fov 30)", E2, T2, nullptr, 24.0, 30.0);
    }
    std::printf("models: fragments to unorm8 as RNE(fl(x 255/256) 256): %s; rgba8 blends with llvmpipe's products: %s; "
                "fragments converted before the blend: %s; float32 blends unfused, binary16 stored %s: %s; linear "
                "filtering exact: %s; 8-bit filtering in 8.8 fixed point: %s; 8-bit texels read as fl(k fl(1/255)): %s\n",
                convert ? "hold" : "DO NOT hold", rounded ? "hold" : "DO NOT hold", converted ? "hold" : "DO NOT hold",
                half_truncates ? "toward zero" : "nearest-even", floats ? "hold" : "DO NOT hold", exact ? "holds" : "does not hold",
                fixed8 ? "holds" : "does not hold", texel8 ? "hold" : "DO NOT hold");
    if (check) {
        const bool filter_ok = filter.empty() || (filter == "exact" && exact) || (filter == "fixed8" && fixed8 && texel8);
        if (!filter.empty() && filter != "exact" && filter != "fixed8") gl_fail(2, "--filter: exact or fixed8");
        if (!(convert && rounded && converted && floats && filter_ok)) {
            std::fprintf(stderr, "gl_probe: a model the slicing tests' tolerances rely on does not hold (above)\n");
            return 1;
        }
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const gl_headless::GlFail& f) {
        std::fprintf(stderr, "gl_probe: %s\n", f.what.c_str());
        return f.code;
    }
}
