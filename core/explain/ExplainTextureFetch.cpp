// explain texture-fetch: one linearly filtered 3D texture fetch worked out step by step with
// the renderer's own rule (core/integrate/profiles/TextureUnit.h): the coordinate as the unit takes it,
// the integer axis weights, the eight integer corner weights, the texels (truncated for float32), the
// sum and its rounding, the result, and exact trilinear filtering at the same position beside it.
#include <cmath>
#include <cstdint>
#include <string>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "core/grid/Volume.h"
#include "core/integrate/profiles/TextureUnit.h"

namespace volref::explain {

namespace tu = texture_unit;

namespace {

constexpr const char* kAxis[3] = {"x", "y", "z"};

bool is_unorm16(const Volume& v) {
    if (v.values.type() == ScalarType::U16) return true;
    if (v.values.type() == ScalarType::F32) return false;
    throw Error(std::string("--volume: texture-fetch reads u16 (as unorm16) or f32 (as float) volumes, this one holds ") +
                scalar_type_name(v.values.type()) + " values");
}

// What one fetch computes (the steps are kept for the explanation).
struct Worked {
    std::array<double, 3> given{}, coordinate{};  // as given; as the unit takes it (float32, normalised: cut, times n)
    tu::Fetch3d f;
    std::array<double, 8> texel{};  // the stored values (unorm16: the integer q)
    std::array<double, 8> value{};  // as the filter reads them (float32, or q / 65535)
    tu::FloatSteps steps;
    std::int64_t sum16 = 0, n16 = 0;
    float fetch = 0.0f;
    double exact = 0.0;
    std::array<double, 8> e{};
};

// `option`: the command-line option the point came from (for messages).
Worked work(const Volume& v, const glm::dvec3& at, bool h100, bool normalized, const char* option) {
    const bool unorm16 = is_unorm16(v);
    Worked w;
    for (int a = 0; a < 3; ++a) {
        const float c = static_cast<float>(at[a]);
        if (!std::isfinite(c))
            throw Error(std::string(option) + ": the " + kAxis[a] + " coordinate is not a finite float32, got " + std::to_string(at[a]));
        w.given[std::size_t(a)] = at[a];
        w.coordinate[std::size_t(a)] = normalized ? tu::unnormalized(tu::to_float32(at[a]), v.dims[std::size_t(a)]) : tu::to_float32(at[a]);
    }
    w.f = tu::locate_3d(w.coordinate, v.dims);
    std::array<float, 8> fv{};
    std::array<std::uint16_t, 8> q{};
    for (int c = 0; c < 8; ++c) {
        const auto i = w.f.corner_index(c);
        const double raw = v.at(i[0], i[1], i[2]);
        w.texel[std::size_t(c)] = raw;
        if (unorm16) {
            q[std::size_t(c)] = static_cast<std::uint16_t>(raw);
            w.value[std::size_t(c)] = raw / 65535.0;
        } else {
            fv[std::size_t(c)] = static_cast<float>(raw);
            w.value[std::size_t(c)] = raw;
        }
    }
    w.e = tu::exact_weights(w.f.axis);
    for (int c = 0; c < 8; ++c) w.exact += w.e[std::size_t(c)] * w.value[std::size_t(c)];
    if (!h100) w.fetch = static_cast<float>(w.exact);
    else if (unorm16) w.fetch = tu::filter_unorm16(w.f.w.data(), q.data(), 8, &w.sum16, &w.n16);
    else w.fetch = tu::filter_float(w.f.w.data(), fv.data(), 8, 2, &w.steps);
    return w;
}

std::string corner_name(int c) {
    return "(" + std::to_string(c & 1) + "," + std::to_string((c >> 1) & 1) + "," + std::to_string((c >> 2) & 1) + ")";
}

}  // namespace

Explanation texture_fetch(const Volume& v, const glm::dvec3& at, bool h100, bool normalized) {
    const bool unorm16 = is_unorm16(v);
    const Worked w = work(v, at, h100, normalized, "--at");
    Explanation e;
    e.topic = "texture-fetch";
    Section& tex = e.section("texture");
    add(tex, "dims", {double(v.dims[0]), double(v.dims[1]), double(v.dims[2])}, "texels per axis, texel i centred at i + 0.5");
    tex.notes.push_back(std::string("texels: ") + (unorm16 ? "u16 read as normalised float (unorm16, q / 65535)" : "float32") +
                        "; linear filter, clamp addressing; unit: " + (h100 ? "h100 (TextureUnit.h)" : "exact trilinear"));
    for (int a = 0; a < 3; ++a) {
        Section& s = e.section(std::string("axis ") + kAxis[a]);
        const tu::AxisRead& r = w.f.axis[std::size_t(a)];
        const double n = double(v.dims[std::size_t(a)]);
        if (normalized) {
            add(s, "u", w.given[std::size_t(a)], "the normalised coordinate as given");
            add(s, "u32", tu::to_float32(w.given[std::size_t(a)]), "u as a float32");
            add(s, "u20", std::floor(std::ldexp(tu::to_float32(w.given[std::size_t(a)]), 20)) * 0x1p-20,
                "floor(u32 2^20) / 2^20 (20 fractional bits)");
            add(s, "x", r.x, "u20 n, n = " + std::to_string(std::int64_t(n)));
        } else {
            add(s, "x", w.given[std::size_t(a)], "the coordinate as given (texels)");
            add(s, "x32", r.x, "x as a float32");
        }
        add(s, "t", r.t, "clamp(x - 0.5, 0, n - 1)");
        add(s, "i0", double(r.i0), "floor(t)");
        add(s, "i1", double(r.i1), "min(i0 + 1, n - 1)");
        add(s, "frac", r.t - double(r.i0), "t - i0 (the exact weight of i1)");
        add(s, "a", double(r.a), "floor(frac 256 + 0.5): the unit's weight of i1, in 256ths");
    }
    Section& cw = e.section("corner weights (integers summing to 256; corner (i,j,k) = texel (i0 or i1) per axis)");
    const int ax = w.f.axis[0].a, az = w.f.axis[2].a;
    auto rnd = [](int p) { return (p + 128) >> 8; };
    for (int k = 0; k < 2; ++k) {
        const int zk = k ? az : 256 - az;
        const int x1 = rnd(ax * zk);
        const std::string K = std::to_string(k);
        add(cw, "Z" + K, double(zk), k ? "a_z" : "256 - a_z");
        add(cw, "X1," + K, double(x1), "rnd(a_x Z" + K + ") = (a_x Z" + K + " + 128) >> 8");
        add(cw, "X0," + K, double(zk - x1), "Z" + K + " - X1," + K);
    }
    static constexpr const char* kRule[8] = {"rnd((256 - a_y) X0,k)", "X1,k - w(1,1,k)", "X0,k - w(0,0,k)", "rnd(a_y X1,k)"};
    for (int c = 0; c < 8; ++c)
        add(cw, "w" + corner_name(c), double(w.f.w[std::size_t(c)]),
            std::string(kRule[c & 3]) + ", k = " + std::to_string(c >> 2) + (h100 ? "" : " (not used: exact unit)"));
    Section& tx = e.section("texels");
    for (int c = 0; c < 8; ++c) {
        const auto i = w.f.corner_index(c);
        add(tx, "index" + corner_name(c), {double(i[0]), double(i[1]), double(i[2])});
        add(tx, "v" + corner_name(c), w.texel[std::size_t(c)], unorm16 ? "q (u16)" : "float32 texel");
    }
    if (h100 && !unorm16) {
        for (int k = 0; k < 2; ++k)
            add(tx, "E" + std::to_string(k), double(w.steps.exponent[std::size_t(k)]),
                "slice z = " + std::to_string(k) + ": 2^(E-1) <= max |v| with w != 0 < 2^E");
        for (int c = 0; c < 8; ++c)
            add(tx, "v'" + corner_name(c), w.steps.truncated[std::size_t(c)], "v truncated to a multiple of 2^(E - 28) of its slice");
    }
    Section& sum = e.section("sum and rounding");
    if (!h100) {
        for (int c = 0; c < 8; ++c) add(sum, "e" + corner_name(c), w.e[std::size_t(c)], "exact trilinear weight (product of frac or 1 - frac)");
        add(sum, "sum", w.exact, unorm16 ? "sum e_c q_c / 65535 (double)" : "sum e_c v_c (double)");
    } else if (unorm16) {
        add(sum, "S", double(w.sum16), "sum w_c q_c (an integer)");
        add(sum, "N", double(w.n16), "(S + 128) >> 8 (a 16-bit result, ties up)");
        add(sum, "N/65535", double(w.n16) / 65535.0, "in double");
    } else {
        add(sum, "sum", w.steps.exact_sum, "sum w_c v'_c / 256, exact (this double and the next add up to it)");
        add(sum, "sum_rest", w.steps.exact_sum_lo, "what the double above leaves out (0 when it is exact)");
    }
    Section& res = e.section("result");
    add(res, "fetch", double(w.fetch), h100 ? (unorm16 ? "float32(N / 65535), correctly rounded" : "the sum rounded to float32, ties away from zero")
                                            : "the exact sum rounded to float32");
    add(res, "exact", w.exact, "exact trilinear: sum e_c v_c at the same t (double)");
    add(res, "fetch - exact", double(w.fetch) - w.exact);
    return e;
}

Explanation texture_fetch_points(const Volume& v, const std::vector<glm::dvec3>& points, bool h100, bool normalized) {
    is_unorm16(v);
    Explanation e;
    e.topic = "texture-fetch";
    Section& s = e.section("points");
    s.columns = {"x", "y", "z", "fetch"};
    for (const glm::dvec3& p : points) {
        const Worked w = work(v, p, h100, normalized, "--points");
        s.rows.push_back({p.x, p.y, p.z, double(w.fetch)});
    }
    return e;
}

}  // namespace volref::explain
