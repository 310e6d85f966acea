// CudaCurvilinearKernel: seed 001's CUDA kernel (tests/gpu/cuda/cuda_curvilinear.cu) as it runs on an NVIDIA GPU,
// in float32 on the CPU: the bounding triangles the host builds (volref's tessellation, minus the
// centre, in float), rayIntersectTriangles with baryTriangleCoefs and its fallback as written, the march
// `for (float s = outAbs; s >= inAbs; s -= step)` at O + s vect, cartToCyl / cartToSpher, the data texture
// (unsigned shorts, read as normalised float through the texture unit: TextureUnit.h, exact or h100), the
// 9-entry float4 table, sum = lerp(sum, col, col.w density) or the x-ray maximum. nvcc contracts a * b + c
// into fma (its default -fmad=true): the emulation uses fmaf where NVVM forms one (conventions section 9,
// "cuda-curvilinear and seed 001"); atan2f and rsqrtf are CUDA's own approximations (2 ulp), here the
// correctly rounded values. What that may change is the error channel (band()).
//
// A ray whose loop cannot end (`s -= step` leaves s unchanged in float32: s >= 2^24 step about) is a
// fault: the real program hangs there. The pixel is NaN with fault = true and the reason recorded.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/camera/Ray.h"

namespace volref {

struct BoundsSpec;
struct RenderSpec;
struct Volume;
class Classifier;

// What seed 001's host hands its kernel (cuda_curvilinear_host.cpp builds the same frame).
struct Seed001Frame {
    int geom_type = 0;                     // 0 cylinder (R, angle, H), 1 sphere (R, longitude, latitude)
    std::array<float, 3> geom_size{};      // radians for the angles
    glm::dvec3 center{0.0};
    std::vector<std::array<float, 3>> vertices;  // 3 per triangle, world - centre, outward
    std::array<std::int64_t, 3> dims{};
    std::vector<std::uint16_t> data;       // round(s 65535), s over the data range, x fastest
    std::array<std::array<float, 4>, 9> table{};  // colour and opacity at min + j (max - min) / 8
    float step = 0.01f, density = 1.0f, reg_brightness = 1.0f, xray_brightness = 1.0f, iso = 0.0f,
          transfer_scale = 1.0f;
    bool xray = false;
    bool tricubic = false;                 // render.profile_options.tricubic: the seed's triCubic = 1
};

// Seed 001's cubicInterpolate in exact arithmetic, at the unnormalised texture coordinate t: per axis
// i = floor(t), a = t - i, the weights w0 = -a^3 + 2a^2 - a, w1 = a^3 - 2a^2 + 1, w2 = -a^3 + a^2 + a,
// w3 = a^3 - a^2 (Keys' cubic with parameter -1) folded into two linear reads at the mixture coordinates
// m0 = i - w0 / (w0 + w1) = i + a (1 - a) and m1 = i + 1 + w3 / (w2 + w3) = i + 1 - a (1 - a), mixed with
// weight w2 + w3 = a. `fetch(m)` is the linear texture read at m (tex3D's convention: texel j centred at
// j + 0.5, so m0 and m1 read texels i - 1 .. i + 1: the seed does not add the half texel). Every lerp
// weight lies in [0, 1] and every read is a convex combination, so the value is one too (no overshoot).
template <class Fetch>
double seed001_cubic(const std::array<double, 3>& t, const Fetch& fetch) {
    std::array<double, 3> m0{}, m1{}, g{};
    for (int k = 0; k < 3; ++k) {
        const double i = std::floor(t[std::size_t(k)]), a = t[std::size_t(k)] - i;
        m0[std::size_t(k)] = i + a * (1.0 - a);
        m1[std::size_t(k)] = i + 1.0 - a * (1.0 - a);
        g[std::size_t(k)] = a;
    }
    auto lerp = [](double a, double b, double w) { return a + w * (b - a); };
    double v[2][2][2];  // [x][y][z]: 0 at m0, 1 at m1
    for (int c = 0; c < 8; ++c)
        v[c & 1][(c >> 1) & 1][c >> 2] = fetch(std::array<double, 3>{(c & 1) ? m1[0] : m0[0], (c & 2) ? m1[1] : m0[1],
                                                                    (c & 4) ? m1[2] : m0[2]});
    const double z0 = lerp(lerp(v[0][0][0], v[1][0][0], g[0]), lerp(v[0][1][0], v[1][1][0], g[0]), g[1]);
    const double z1 = lerp(lerp(v[0][0][1], v[1][0][1], g[0]), lerp(v[0][1][1], v[1][1][1], g[0]), g[1]);
    return lerp(z0, z1, g[2]);
}

// The host's frame for a scene: `volume` on the shell of `bounds` (tessellate segments per turn, 64
// when absent), the table from `classifier`, the render's profile options, `step` (world units).
Seed001Frame seed001_frame(const Volume& volume, const BoundsSpec& bounds, const Classifier& classifier,
                           const RenderSpec& render, double step);

// Why a ray faulted, for trace and explain.
struct Seed001Fault {
    int triangle = -1;    // the triangle whose s set outAbs
    float d = 0.0f;       // its dot(n, vect)
    float out_abs = 0.0f, in_abs = 0.0f;
    float ulp = 0.0f;     // the float32 spacing at outAbs
    float step = 0.0f;
    std::string text() const;
};

struct Seed001Pixel {
    glm::dvec4 rgba{0.0};   // NaN when fault
    double error = 0.0;     // the band: how far the program's float32 can be (band() only)
    bool fault = false;
    Seed001Fault why;
    bool hit = false;       // rayIntersectTriangles returned true and outAbs >= 0
    float in_abs = 0.0f, out_abs = 0.0f;
    std::int64_t samples = 0;
};

class CudaCurvilinearKernel {
public:
    // h100: the data and table fetches through TextureUnit.h's H100 rule (else exact weights, rounded
    // to float32); band: also compute the error channel.
    CudaCurvilinearKernel(Seed001Frame frame, bool h100, bool band);
    // One pixel: the host's float ray (origin - centre, normalize(direction)) through the kernel.
    Seed001Pixel pixel(const Ray& ray) const;
    // Every sample of one ray as the kernel takes it, for trace: (s, the point in the seed's frame, the
    // sample, used (>= isoValue), the running sum after it).
    struct Sample {
        float s;
        std::array<float, 3> point;
        float sample;
        bool used;
        std::array<float, 4> sum;
    };
    Seed001Pixel pixel(const Ray& ray, std::vector<Sample>* samples) const;
    const Seed001Frame& frame() const { return f_; }
    // The float32 value at a point (interpolateCyl / interpolateSpher with outVal 0).
    float sample_at(const std::array<float, 3>& point) const;
    // tex3D at an unnormalised coordinate (the h100 rule or exact weights rounded to float32), and the
    // seed's cubicInterpolate in float32 (8 of them).
    float fetch(const std::array<float, 3>& tex) const;
    float cubic(const std::array<float, 3>& tex) const;
    // The exact linear read at an unnormalised coordinate, in data units [0, 1].
    double exact_fetch(const std::array<double, 3>& tex) const;

    struct Span {
        bool ok = false;
        float in_abs = 0.0f, out_abs = 0.0f;
        int in_triangle = -1, out_triangle = -1;
        double eps = 0.0;        // the uncertainty of the positions (world units; span_of sets it, intersect leaves 0)
    };
    struct Hit {                 // one triangle's test, for the band's alternatives
        int triangle;
        float s, d;
        bool entry;              // d < 0
        bool accepted;
        bool ambiguous;          // acceptance (or the sign of d) within rounding
        double eps;              // the uncertainty of s
    };
    // rayIntersectTriangles; `hits` (optional) receives every triangle with d != 0 the ray's line meets
    // or nearly meets.
    Span intersect(const std::array<float, 3>& O, const std::array<float, 3>& V, std::vector<Hit>* hits) const;
    static Span span_of(const std::vector<Hit>& hits, const std::vector<char>& accepted, float geom_r);

private:
    std::array<float, 4> table_fetch(float u) const;
    double band(const std::array<float, 3>& O, const std::array<float, 3>& V, const std::vector<Hit>& hits,
                const Span& nominal, const glm::dvec4& rendered, bool& may_fault) const;
    struct Box {
        double lo[4], hi[4];
    };
    // The interval of the program's output over a span, its positions uncertain by eps.
    Box span_range(const std::array<float, 3>& O, const std::array<float, 3>& V, const Span& sp, bool& may_fault) const;
    void sample_range(const std::array<float, 3>& point, double eps, double& lo, double& hi) const;
    void table_range(double ulo, double uhi, double* lo, double* hi) const;

    Seed001Frame f_;
    bool h100_, band_;
    std::array<float, 3> step_{};  // lengthStep, angleStep / longStep, heightStep / latStep as the kernel has them
};

}  // namespace volref
