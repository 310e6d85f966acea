// The H100 texture unit's rule (TextureUnit.h states it and its source).
#include "core/integrate/profiles/TextureUnit.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace volref::texture_unit {

namespace {

int rnd(int p) { return (p + 128) >> 8; }  // round half up of p / 256

// hi + lo (exact, |lo| <= ulp(hi) / 2) rounded to float32, ties away from zero.
float round_half_away(double hi, double lo) {
    const double total = hi + lo;
    if (total == 0.0) return 0.0f;
    const double s = total < 0.0 ? -1.0 : 1.0;
    const double h = s * hi, l = s * lo;  // h > 0 up to lo's sign
    float down = static_cast<float>(h);
    if (double(down) > h) down = std::nextafter(down, 0.0f);
    const float up = std::nextafter(down, std::numeric_limits<float>::infinity());
    const double mid = 0.5 * (double(down) + double(up));  // exact: floats have 24 bits
    const float r = (h > mid || (h == mid && l >= 0.0)) ? up : down;
    return static_cast<float>(s) * r;
}

}  // namespace

double unnormalized(double u, std::int64_t n) {
    return std::floor(std::ldexp(u, kNormalizedFractionBits)) * std::ldexp(1.0, -kNormalizedFractionBits) * double(n);
}

AxisRead axis_read(double x, std::int64_t n) {
    AxisRead r;
    r.x = x;
    r.t = std::clamp(x - 0.5, 0.0, double(std::max<std::int64_t>(n - 1, 0)));
    if (!(r.t == r.t)) r.t = 0.0;  // NaN coordinate: texel 0 (never reached by the profiles)
    r.i0 = std::int64_t(std::floor(r.t));
    r.i1 = std::min(r.i0 + 1, n - 1);
    r.a = int(std::floor((r.t - double(r.i0)) * 256.0 + 0.5));
    return r;
}

std::array<int, 8> corner_weights(int ax, int ay, int az) {
    std::array<int, 8> w{};
    for (int k = 0; k < 2; ++k) {
        const int zk = k ? az : kWeightOne - az;
        const int x1 = rnd(ax * zk), x0 = zk - x1;
        const int w11 = rnd(ay * x1), w00 = rnd((kWeightOne - ay) * x0);
        w[std::size_t(3 + 4 * k)] = w11;
        w[std::size_t(1 + 4 * k)] = x1 - w11;
        w[std::size_t(0 + 4 * k)] = w00;
        w[std::size_t(2 + 4 * k)] = x0 - w00;
    }
    return w;
}

float filter_float(const int* w, const float* v, int count, int slices, FloatSteps* steps) {
    const int per = count / slices;
    bool finite = true;
    for (int c = 0; c < count; ++c) finite = finite && std::isfinite(v[c]);
    if (!finite) {  // outside the measured rule: the plain sum
        double s = 0.0;
        for (int c = 0; c < count; ++c) s += w[c] * double(v[c]);
        return static_cast<float>(s / 256.0);
    }
    double hi = 0.0, lo = 0.0;
    for (int g = 0; g < slices; ++g) {
        double vmax = 0.0;
        for (int c = g * per; c < (g + 1) * per; ++c)
            if (w[c] != 0) vmax = std::max(vmax, std::fabs(double(v[c])));
        int e = 0;
        if (vmax > 0.0) std::frexp(vmax, &e);  // 2^(e-1) <= vmax < 2^e
        const double q = std::ldexp(1.0, e - kTexelMantissaBits);
        double part = 0.0;  // exact: < 2^38 multiples of q
        for (int c = g * per; c < (g + 1) * per; ++c) {
            const double vq = vmax > 0.0 ? std::trunc(double(v[c]) / q) * q : 0.0;
            if (steps) steps->truncated[std::size_t(c)] = vq;
            part += double(w[c]) * vq;
        }
        part /= 256.0;
        if (steps) steps->exponent[std::size_t(g)] = vmax > 0.0 ? e : 0;
        // TwoSum: hi + lo stays the exact total
        const double s = hi + part, bp = s - hi;
        lo += (hi - (s - bp)) + (part - bp);
        hi = s;
    }
    // renormalise so that |lo| <= ulp(hi) / 2
    const double s = hi + lo;
    lo = lo - (s - hi);
    hi = s;
    if (steps) {
        steps->exact_sum = hi;
        steps->exact_sum_lo = lo;
    }
    return round_half_away(hi, lo);
}

float filter_unorm16(const int* w, const std::uint16_t* q, int count, std::int64_t* sum, std::int64_t* n) {
    std::int64_t s = 0;
    for (int c = 0; c < count; ++c) s += std::int64_t(w[c]) * std::int64_t(q[c]);
    const std::int64_t N = (s + 128) >> 8;
    if (sum) *sum = s;
    if (n) *n = N;
    return static_cast<float>(double(N) / 65535.0);
}

Fetch3d locate_3d(const std::array<double, 3>& x, const std::array<std::int64_t, 3>& n) {
    Fetch3d f;
    for (int a = 0; a < 3; ++a) f.axis[std::size_t(a)] = axis_read(x[std::size_t(a)], n[std::size_t(a)]);
    f.w = corner_weights(f.axis[0].a, f.axis[1].a, f.axis[2].a);
    return f;
}

std::array<double, 8> exact_weights(const std::array<AxisRead, 3>& axis) {
    double fr[3];
    for (int a = 0; a < 3; ++a) fr[a] = axis[std::size_t(a)].t - double(axis[std::size_t(a)].i0);
    std::array<double, 8> e{};
    for (int c = 0; c < 8; ++c) {
        double p = 1.0;
        for (int a = 0; a < 3; ++a) p *= ((c >> a) & 1) ? fr[a] : 1.0 - fr[a];
        e[std::size_t(c)] = p;
    }
    return e;
}

std::uint64_t Admissible::mix(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

namespace {
std::uint64_t bits_of(double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}
}  // namespace

Admissible::Admissible(std::uint64_t seed, double a, double b, double c)
    : state(mix(mix(mix(mix(seed) ^ bits_of(a)) ^ bits_of(b)) ^ bits_of(c))) {}

double Admissible::next() {
    state = mix(state);
    if ((state & 3u) == 0u) return (state & 4u) ? 1.0 : -1.0;
    return double(state >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

std::array<double, 8> admissible_weights(const std::array<double, 8>& exact, Admissible& r) {
    std::array<double, 8> d{};
    double mean = 0.0;
    for (double& x : d) mean += (x = r.next());
    mean /= 8.0;
    double l1 = 0.0;
    for (double& x : d) l1 += std::fabs(x -= mean);
    const double size = std::fabs(r.next()) * kL1Max * (1.0 - 1e-12);  // a quarter of the time kL1Max
    std::array<double, 8> w = exact;
    if (l1 > 0.0)
        for (int c = 0; c < 8; ++c) w[std::size_t(c)] += d[std::size_t(c)] * size / l1;
    return w;
}

}  // namespace volref::texture_unit
