// gl_slicer: a slice-based volume renderer in OpenGL (3.3 core, headless through EGL: Mesa's surfaceless
// platform, llvmpipe), an independent implementation of docs/conventions.md "Slice-order renderers: slices
// and frame buffers" (OpenGL Volumizer's image formation, seed 003) for checking volref's placement
// "slices" against a real GL pipeline: the levels are computed on the CPU, each plane is clipped against the
// volume's box on the CPU and drawn as a polygon (shells: a screen-covering triangle whose fragments
// intersect the pixel's ray with the sphere), textured from a 3D texture (or a 2D texture array), classified
// in the fragment shader and composited by the frame buffer's fixed-function blending.
//
//   gl_slicer SCENE.json OUT.exr [--set key=value]... [--define VARIANT]... [--require-renderer S] [--egl-device]
//             [--fragments X,Y]
//
// The scene's render.profile (an object: {"base": "volumizer" | "reference", "placement": "slices",
// "slices": {...}, ...}) is read here; the rest of the scene (volume, transfer function, camera, image,
// step) by volref's own loader, with render.profile and camera.near / camera.far taken out first (read
// here too). --set with a path under render.profile or camera.near / camera.far is applied here, any other
// is passed to volref's loader.
//
// --define VARIANT (tests showing the comparison sees each convention): SLICER_CORRECTED (correction exact
// where the scene says none), SLICER_HALF (first "half" where it says "bound"), SLICER_FLOAT_FB (an RGBA32F
// frame buffer where it says rgba8), SLICER_LINEAR_TABLE (table_lookup linear where it says nearest),
// SLICER_DATA_WINDOW (texture_window data-range where it says transfer-rows), SLICER_NO_NEAR_FAR (samples
// not clipped at camera.near / camera.far).
//
// --fragments X,Y prints each level's fragment at pixel (X, Y) (row 0 at the top), drawn alone and
// unblended into RGBA32F: what the shader hands the blend, for comparing with `volref trace`.
//
// Exit status: 0 written; 1 no GL context or a GL error (never a skip: a test that cannot get a context
// fails); 2 a scene the program does not render (one line naming what).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "core/film/ImageWriter.h"
#include "tests/gpu/gl_context.h"
#include "volref_core.h"

namespace {

using nlohmann::json;
using gl_headless::check_gl;
using gl_headless::gl_fail;

// kSliceSlack of the contract: n = floor((b_far - b_near) / s - o + kSliceSlack) + 1 and
// n = ceil(E / D - kSliceSlack).
constexpr double kSliceSlack = 1e-9;
// The GL near and far planes are moved outwards by this fraction of their distance, so a level lying on
// camera.near or camera.far (view_volume with first "bound": the first level on far, the last on near) is
// kept, as the contract's near <= (x - E) . f <= far keeps it; GL clipping at the exact plane would decide
// such a polygon by the rounding of its clip coordinates.
constexpr double kClipWiden = 1e-6;
constexpr int kMaxRows = 64;  // transfer-function rows passed to the shader (table 0)

// ---------------------------------------------------------------------------------------------------------
// The slice rules (render.profile), with the base's defaults.
struct Slicing {
    enum class Orientation { Viewport, Axis, Spherical } orientation = Orientation::Viewport;
    enum class Range { Object, ViewVolume } range = Range::Object;
    enum class Placement { Spacing, Count, Period } placement = Placement::Spacing;
    double spacing = 0;              // world units (after step_units); 0: the scene's step
    bool spacing_given = false;
    int count = 0;
    glm::dvec3 period{1.0};
    std::optional<int> max_count;
    bool first_half = false;         // first "half" (o = 1/2) or "bound"
    bool front_to_back = false;      // order
    bool texture_2d = false;
    enum class Format { Float, Unorm16, Unorm8 } texture_format = Format::Unorm8;
    enum class Window { Rows, DataRange, Given } window = Window::Rows;
    double window_lo = 0, window_hi = 1;
    int table = 256;
    enum class Lookup { Nearest, Linear, Texture } table_lookup = Lookup::Nearest;
    bool table_unorm8 = true;        // table_format unorm8 (else float)
    bool classify_pre = false;       // "pre-unweighted"
    bool correction_exact = false;   // "exact" (else "none")
    enum class Framebuffer { Rgba8, Rgba16f, Rgba32f } framebuffer = Framebuffer::Rgba8;
    enum class Blend { SrcAlpha, Premultiplied, Max } blend = Blend::SrcAlpha;
    bool blend_alpha_one = false;    // blend_alpha "one" (else "src-alpha")
};

[[noreturn]] void refuse(const std::string& what) { gl_fail(2, what); }

std::string str(const json& j, const std::string& key) {
    if (!j.is_string()) refuse("render.profile." + key + ": expected a string");
    return j.get<std::string>();
}

template <class E>
E pick(const json& j, const std::string& key, std::initializer_list<std::pair<const char*, E>> names) {
    const std::string v = str(j, key);
    for (const auto& [n, e] : names)
        if (v == n) return e;
    std::string list;
    for (const auto& [n, e] : names) list += std::string(list.empty() ? "" : ", ") + n;
    refuse("render.profile." + key + ": \"" + v + "\" is not one of " + list);
}

// render.profile as the scene gives it (a preset name or an object) -> the rules. The volumizer preset:
// viewport, object, spacing = the scene's step, first bound, back to front, 3D texture, unorm8 texels over
// the transfer function's rows, a 256-entry unorm8 table read nearest, post-classified, no correction, an
// RGBA8 frame buffer with src-alpha blending. Base "reference" with placement "slices": the contract's
// stated defaults (texture 3d, texture_window transfer-rows, table_lookup texture, classify post, blend
// src-alpha) and float texels, table 0, float table entries; its correction and frame buffer must be given
// (the reference's "pow" and "double" have no GL slicer).
Slicing read_profile(const json& profile_in) {
    json profile = profile_in.is_string() ? json{{"base", profile_in}} : profile_in;
    if (!profile.is_object()) refuse("render.profile: expected a preset name or an object");
    const std::string base = profile.contains("base") ? str(profile["base"], "base") : "reference";
    Slicing s;
    if (base == "volumizer") {
        if (profile.contains("placement") && str(profile["placement"], "placement") != "slices")
            refuse("render.profile.placement: gl_slicer renders placement \"slices\" only");
    } else if (base == "reference") {
        if (!profile.contains("placement") || str(profile["placement"], "placement") != "slices")
            refuse("render.profile.placement: gl_slicer renders placement \"slices\" only");
        s.texture_format = Slicing::Format::Float;
        s.table = 0;
        s.table_lookup = Slicing::Lookup::Texture;
        s.table_unorm8 = false;
        if (!profile.contains("correction")) refuse("render.profile.correction: base reference's \"pow\": give \"none\" or \"exact\"");
        if (!profile.contains("framebuffer")) refuse("render.profile.framebuffer: base reference's \"double\" has no GL format");
    } else {
        refuse("render.profile.base: \"" + base + "\": gl_slicer renders bases volumizer and reference");
    }
    static const std::set<std::string> known = {"base", "placement", "slices", "texture", "texture_format", "texture_window",
                                                "table", "table_lookup", "table_format", "classify", "correction",
                                                "framebuffer", "framebuffer_rounding", "blend_products", "blend", "blend_alpha",
                                                "texture_filter", "jitter"};
    for (const auto& [k, v] : profile.items())
        if (!known.contains(k)) refuse("render.profile." + k + ": not a rule gl_slicer renders");
    using S = Slicing;
    if (profile.contains("slices")) {
        const json& sl = profile["slices"];
        if (!sl.is_object()) refuse("render.profile.slices: expected an object");
        int given = 0;
        for (const auto& [k, v] : sl.items()) {
            const std::string key = "slices." + k;
            if (k == "orientation")
                s.orientation = pick<S::Orientation>(v, key, {{"viewport", S::Orientation::Viewport}, {"axis", S::Orientation::Axis},
                                                              {"spherical", S::Orientation::Spherical}});
            else if (k == "range")
                s.range = pick<S::Range>(v, key, {{"object", S::Range::Object}, {"view_volume", S::Range::ViewVolume}});
            else if (k == "spacing") {
                if (!v.is_number() || v.get<double>() <= 0) refuse("render.profile." + key + ": expected a number > 0");
                s.spacing = v.get<double>(), s.spacing_given = true, s.placement = S::Placement::Spacing, ++given;
            } else if (k == "count") {
                if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > (1LL << 30))
                    refuse("render.profile." + key + ": expected an integer >= 1");
                s.count = v.get<int>(), s.placement = S::Placement::Count, ++given;
            } else if (k == "period") {
                if (!v.is_array() || v.size() != 3) refuse("render.profile." + key + ": expected [p_x, p_y, p_z]");
                for (int a = 0; a < 3; ++a) {
                    if (!v[std::size_t(a)].is_number() || v[std::size_t(a)].get<double>() <= 0)
                        refuse("render.profile." + key + ": expected numbers > 0");
                    s.period[a] = v[std::size_t(a)].get<double>();
                }
                s.placement = S::Placement::Period, ++given;
            } else if (k == "max_count") {
                if (!v.is_number_integer() || v.get<long long>() < 1) refuse("render.profile." + key + ": expected an integer >= 1");
                s.max_count = int(std::min<long long>(v.get<long long>(), 1LL << 30));
            } else if (k == "first")
                s.first_half = pick<bool>(v, key, {{"bound", false}, {"half", true}});
            else if (k == "order")
                s.front_to_back = pick<bool>(v, key, {{"back-to-front", false}, {"front-to-back", true}});
            else
                refuse("render.profile." + key + ": not a slices key");
        }
        if (given > 1) refuse("render.profile.slices: more than one of spacing, count, period");
    }
    if (profile.contains("texture")) s.texture_2d = pick<bool>(profile["texture"], "texture", {{"3d", false}, {"2d", true}});
    if (profile.contains("texture_format"))
        s.texture_format = pick<S::Format>(profile["texture_format"], "texture_format",
                                           {{"float", S::Format::Float}, {"unorm16", S::Format::Unorm16}, {"unorm8", S::Format::Unorm8}});
    if (profile.contains("texture_window")) {
        const json& w = profile["texture_window"];
        if (w.is_array()) {
            if (w.size() != 2 || !w[0].is_number() || !w[1].is_number() || !(w[1].get<double>() > w[0].get<double>()))
                refuse("render.profile.texture_window: expected [lo, hi] with hi > lo");
            s.window = S::Window::Given, s.window_lo = w[0].get<double>(), s.window_hi = w[1].get<double>();
        } else {
            s.window = pick<S::Window>(w, "texture_window", {{"transfer-rows", S::Window::Rows}, {"data-range", S::Window::DataRange}});
        }
    }
    if (profile.contains("table")) {
        const json& t = profile["table"];
        if (!t.is_number_integer() || (t.get<long long>() != 0 && (t.get<long long>() < 2 || t.get<long long>() > (1 << 20))))
            refuse("render.profile.table: expected 0 or an integer in [2, 2^20]");
        s.table = t.get<int>();
    }
    if (profile.contains("table_lookup"))
        s.table_lookup = pick<S::Lookup>(profile["table_lookup"], "table_lookup",
                                         {{"nearest", S::Lookup::Nearest}, {"linear", S::Lookup::Linear}, {"texture", S::Lookup::Texture}});
    if (profile.contains("table_format"))
        s.table_unorm8 = pick<bool>(profile["table_format"], "table_format", {{"float", false}, {"unorm8", true}});
    if (profile.contains("classify"))
        s.classify_pre = pick<bool>(profile["classify"], "classify", {{"post", false}, {"pre-unweighted", true}});
    if (profile.contains("correction"))
        s.correction_exact = pick<bool>(profile["correction"], "correction", {{"none", false}, {"exact", true}});
    if (profile.contains("framebuffer"))
        s.framebuffer = pick<S::Framebuffer>(profile["framebuffer"], "framebuffer",
                                             {{"rgba8", S::Framebuffer::Rgba8}, {"rgba16f", S::Framebuffer::Rgba16f},
                                              {"rgba32f", S::Framebuffer::Rgba32f}});
    // How the frame buffer rounds and multiplies, and how 8-bit textures are filtered, are the GL
    // implementation's (gl_probe measures them; the filter is llvmpipe's fixed-point one unless
    // GALLIVM_PERF=no_aos_sampling): accepted, not used.
    if (profile.contains("framebuffer_rounding"))
        pick<int>(profile["framebuffer_rounding"], "framebuffer_rounding", {{"nearest", 0}, {"truncate", 1}});
    if (profile.contains("blend_products"))
        pick<int>(profile["blend_products"], "blend_products", {{"exact", 0}, {"rounded", 1}, {"llvmpipe", 2}});
    if (profile.contains("texture_filter"))
        pick<int>(profile["texture_filter"], "texture_filter", {{"exact", 0}, {"fixed8", 1}});
    if (profile.contains("jitter") && str(profile["jitter"], "jitter") != "off") refuse("render.profile.jitter: \"off\" only");
    if (profile.contains("blend"))
        s.blend = pick<S::Blend>(profile["blend"], "blend",
                                 {{"src-alpha", S::Blend::SrcAlpha}, {"premultiplied", S::Blend::Premultiplied}, {"max", S::Blend::Max}});
    if (profile.contains("blend_alpha"))
        s.blend_alpha_one = pick<bool>(profile["blend_alpha"], "blend_alpha", {{"src-alpha", false}, {"one", true}});
    if (s.texture_2d && s.orientation != S::Orientation::Axis) refuse("render.profile.texture: \"2d\" needs slices.orientation \"axis\"");
    if (s.front_to_back && s.blend != S::Blend::Premultiplied)
        refuse("render.profile.slices.order: \"front-to-back\" takes blend \"premultiplied\" only");
    return s;
}

// ---------------------------------------------------------------------------------------------------------
// --set PATH=VALUE: VALUE is JSON if it parses as JSON, otherwise a string.
json override_value(const std::string& text) {
    try {
        return json::parse(text);
    } catch (const json::parse_error&) {
        return json(text);
    }
}

// Sets the dotted `path` (no indices) in `root`, making objects on the way.
void set_path(json& root, const std::string& path, const json& value) {
    json* node = &root;
    std::size_t start = 0;
    while (true) {
        const std::size_t dot = path.find('.', start);
        const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        if (!node->is_object()) *node = json::object();
        if (dot == std::string::npos) {
            (*node)[key] = value;
            return;
        }
        node = &(*node)[key];
        start = dot + 1;
    }
}

// ---------------------------------------------------------------------------------------------------------
// Geometry in double.
using glm::dvec3;

struct Box {
    dvec3 lo, hi;
    std::array<dvec3, 8> corners() const {
        std::array<dvec3, 8> c;
        for (int i = 0; i < 8; ++i) c[std::size_t(i)] = dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        return c;
    }
};

// The convex polygon n . x = c inside the box: the box's vertices on the plane and the crossings of the
// edges whose ends lie strictly on opposite sides, sorted by angle around their centroid (in the plane's
// basis u, v). Fewer than 3 points: none.
std::vector<dvec3> clip_plane_to_box(const dvec3& n, double c, const Box& box) {
    const auto v = box.corners();
    std::array<double, 8> g;
    for (int i = 0; i < 8; ++i) g[std::size_t(i)] = glm::dot(n, v[std::size_t(i)]) - c;
    std::vector<dvec3> pts;
    for (int i = 0; i < 8; ++i)
        if (g[std::size_t(i)] == 0) pts.push_back(v[std::size_t(i)]);
    for (int i = 0; i < 8; ++i)
        for (int bit = 1; bit < 8; bit <<= 1) {
            if (i & bit) continue;
            const int j = i | bit;  // the 12 edges: vertex pairs differing in one bit
            const double gi = g[std::size_t(i)], gj = g[std::size_t(j)];
            if ((gi < 0 && gj > 0) || (gi > 0 && gj < 0))
                pts.push_back(v[std::size_t(i)] + (gi / (gi - gj)) * (v[std::size_t(j)] - v[std::size_t(i)]));
        }
    if (pts.size() < 3) return {};
    dvec3 centroid(0.0);
    for (const dvec3& p : pts) centroid += p;
    centroid /= double(pts.size());
    const dvec3 helper = std::fabs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
    const dvec3 u = glm::normalize(glm::cross(n, helper)), w = glm::cross(n, u);
    std::sort(pts.begin(), pts.end(), [&](const dvec3& a, const dvec3& b) {
        return std::atan2(glm::dot(a - centroid, w), glm::dot(a - centroid, u)) <
               std::atan2(glm::dot(b - centroid, w), glm::dot(b - centroid, u));
    });
    return pts;
}

// The camera's frame and frustum (conventions section 10).
struct View {
    bool ortho = false;
    dvec3 eye, f, r, u;
    double tan_half = 0, aspect = 1, half_height = 0;
    std::optional<double> near, far;  // camera.near / camera.far (eye depths)

    // The point at eye depth z through normalised image coordinates (nx, ny) in [-1, 1].
    dvec3 at_depth(double nx, double ny, double z) const {
        if (ortho) return eye + z * f + (nx * half_height * aspect) * r + (ny * half_height) * u;
        return eye + z * (f + (nx * tan_half * aspect) * r + (ny * tan_half) * u);
    }
    std::array<dvec3, 8> frustum_corners() const {
        std::array<dvec3, 8> c;
        for (int i = 0; i < 8; ++i) c[std::size_t(i)] = at_depth(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? *far : *near);
        return c;
    }
};

// The GL matrices, column-major, in double: the view (rows r, u, -f; the eye at the origin) and the
// projection (glm::perspective / glm::ortho conventions) over [zn, zf].
glm::dmat4 view_matrix(const View& v) {
    glm::dmat4 m(1.0);
    for (int i = 0; i < 3; ++i) m[i][0] = v.r[i], m[i][1] = v.u[i], m[i][2] = -v.f[i];
    m[3][0] = -glm::dot(v.r, v.eye), m[3][1] = -glm::dot(v.u, v.eye), m[3][2] = glm::dot(v.f, v.eye);
    return m;
}
glm::dmat4 projection_matrix(const View& v, double zn, double zf) {
    glm::dmat4 p(0.0);
    if (v.ortho) {
        const double t = v.half_height, rgt = t * v.aspect;
        p[0][0] = 1.0 / rgt, p[1][1] = 1.0 / t, p[2][2] = -2.0 / (zf - zn), p[3][2] = -(zf + zn) / (zf - zn), p[3][3] = 1.0;
    } else {
        p[0][0] = 1.0 / (v.aspect * v.tan_half), p[1][1] = 1.0 / v.tan_half, p[2][2] = -(zf + zn) / (zf - zn), p[2][3] = -1.0;
        p[3][2] = -2.0 * zf * zn / (zf - zn);
    }
    return p;
}

// ---------------------------------------------------------------------------------------------------------
// The transfer function: piecewise linear in the rows (x_k, y_k), constant beyond the ends, right-continuous
// at a jump (k = the first row with x_k > v), as transfer/PiecewiseLinear.h states it.
template <std::size_t N>
std::array<double, N> piecewise(const std::vector<std::array<double, N + 1>>& rows, double v) {
    std::array<double, N> out{};
    std::size_t k = 0;
    while (k < rows.size() && !(rows[k][0] > v)) ++k;
    const auto& a = rows[k == 0 ? 0 : k - 1];
    if (k == 0 || k == rows.size()) {
        for (std::size_t c = 0; c < N; ++c) out[c] = a[c + 1];
        return out;
    }
    const auto& b = rows[k];
    const double w = (v - a[0]) / (b[0] - a[0]);
    for (std::size_t c = 0; c < N; ++c) out[c] = a[c + 1] + w * (b[c + 1] - a[c + 1]);
    return out;
}

struct Transfer {
    std::vector<std::array<double, 4>> color;
    std::vector<std::array<double, 2>> opacity;
    double lo = 0, hi = 1;  // the texture window
    // (r, g, b, a) at the normalised texel s: the transfer function at lo + s (hi - lo).
    std::array<double, 4> at_s(double s) const { return at_value(lo + s * (hi - lo)); }
    // (r, g, b, a) at the data value v, the opacity clamped to [0, 1].
    std::array<double, 4> at_value(double v) const {
        const auto c = piecewise<3>(color, v);
        const auto a = piecewise<1>(opacity, v);
        return {c[0], c[1], c[2], std::clamp(a[0], 0.0, 1.0)};
    }
};

double quantise(double x, double levels) { return std::round(std::clamp(x, 0.0, 1.0) * levels) / levels; }

// The table's entries e_j = TF(lo + j (hi - lo) / (N - 1)), evaluated in that order (j (hi - lo), then / (N - 1),
// then lo +, as the contract states and volref does: an entry whose unorm8 code is a tie, x = (k + 1/2) / 255,
// rounds by the last bit of that position), stored per table_format.
std::vector<std::array<double, 4>> make_table(const Transfer& tf, int N, bool unorm8) {
    std::vector<std::array<double, 4>> t(static_cast<std::size_t>(N));
    for (int j = 0; j < N; ++j) {
        t[std::size_t(j)] = tf.at_value(tf.lo + double(j) * (tf.hi - tf.lo) / double(N - 1));
        if (unorm8)
            for (double& x : t[std::size_t(j)]) x = quantise(x, 255.0);
    }
    return t;
}

// A table read at s on the CPU (pre-unweighted classification): nearest j = floor(s (N - 1) + 1/2);
// linear at position s (N - 1); texture: GL_LINEAR at s N - 1/2 clamped to [0, N - 1].
std::array<double, 4> table_read(const std::vector<std::array<double, 4>>& t, double s, Slicing::Lookup lookup) {
    const int N = int(t.size());
    double pos = 0;
    if (lookup == Slicing::Lookup::Nearest)
        return t[std::size_t(std::clamp(int(std::floor(s * (N - 1) + 0.5)), 0, N - 1))];
    if (lookup == Slicing::Lookup::Linear) pos = s * (N - 1);
    else pos = std::clamp(s * N - 0.5, 0.0, double(N - 1));
    const int i = std::clamp(int(std::floor(pos)), 0, N - 2);
    const double w = pos - i;
    std::array<double, 4> out;
    for (int c = 0; c < 4; ++c) out[std::size_t(c)] = (1 - w) * t[std::size_t(i)][std::size_t(c)] + w * t[std::size_t(i + 1)][std::size_t(c)];
    return out;
}

// ---------------------------------------------------------------------------------------------------------
// The levels lambda_k (k = 0 farthest) and the level spacing (the distance between neighbouring levels,
// for the per-fragment d_k of correction "exact").
struct Levels {
    std::vector<double> lambda;
    std::vector<int> layer;  // texture "2d": the data layer of each level
    double spacing = 0;
    double b_near = 0, b_far = 0;
};

Levels place_levels(const Slicing& s, double b_near, double b_far, double spacing_world, double extent_voxels,
                    double period_voxels) {
    Levels L;
    L.b_near = b_near, L.b_far = b_far;
    const double o = s.first_half ? 0.5 : 0.0;
    auto by_count = [&](long long n) {
        for (long long k = 0; k < n; ++k) {
            if (s.first_half) L.lambda.push_back(b_far - (double(k) + 0.5) * (b_far - b_near) / double(n));
            else L.lambda.push_back(n == 1 ? b_far : b_far - double(k) * (b_far - b_near) / double(n - 1));
        }
        // n = 1 with "bound" has no neighbour: its spacing is taken as the range's extent.
        L.spacing = s.first_half || n == 1 ? (b_far - b_near) / double(n) : (b_far - b_near) / double(n - 1);
    };
    long long n = 0;
    switch (s.placement) {
    case Slicing::Placement::Spacing: {
        n = (long long)(std::floor((b_far - b_near) / spacing_world - o + kSliceSlack)) + 1;
        if (n < 0) n = 0;
        if (s.max_count) n = std::min<long long>(n, *s.max_count);
        if (double(n) > volref::conventions::kMaxSamplesPerRay) refuse("render.profile.slices: more levels than the per-ray sample limit");
        for (long long k = 0; k < n; ++k) L.lambda.push_back(b_far - (double(k) + o) * spacing_world);
        L.spacing = spacing_world;
        break;
    }
    case Slicing::Placement::Count:
        n = s.count;
        if (s.max_count) n = std::min<long long>(n, *s.max_count);
        by_count(n);
        break;
    case Slicing::Placement::Period: {
        const double q = std::ceil(extent_voxels / period_voxels - kSliceSlack);
        n = (long long)std::clamp(q, 1.0, s.max_count ? double(*s.max_count) : 1e18);
        if (double(n) > volref::conventions::kMaxSamplesPerRay) refuse("render.profile.slices: more levels than the per-ray sample limit");
        by_count(n);
        break;
    }
    }
    return L;
}

// ---------------------------------------------------------------------------------------------------------
// The shaders.
const char* kPlaneVs = R"(#version 330 core
layout(location = 0) in vec3 a_pos;      // world position of the polygon's vertex
layout(location = 1) in vec2 a_level;    // (data layer, level spacing)
uniform mat4 u_mvp;
out vec3 v_pos;
flat out vec2 v_level;
void main() {
    v_pos = a_pos;
    v_level = a_level;
    gl_Position = u_mvp * vec4(a_pos, 1.0);
}
)";

// A screen-covering triangle for one shell; v_ray is f + nx tan aspect r + ny tan u at the pixel (affine in
// the screen, interpolated without perspective).
const char* kShellVs = R"(#version 330 core
uniform vec3 u_f, u_r, u_u;
uniform float u_tan_half, u_aspect;
noperspective out vec3 v_ray;
void main() {
    vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
    v_ray = u_f + (p.x * u_tan_half * u_aspect) * u_r + (p.y * u_tan_half) * u_u;
    gl_Position = vec4(p, 0.0, 1.0);
}
)";

// The fragment: the sample's position x -> texture coordinate ((x - origin) / spacing + 1/2) / dims ->
// the filtered texel s (or, pre-unweighted, the filtered (c, a)) -> the classification -> the correction ->
// the blend's input.
const char* kFragment = R"(
uniform vec3 u_origin, u_spacing, u_dims;
uniform vec3 u_eye, u_f;
uniform int u_ortho;
uniform vec3 u_normal;          // planes: the unit normal; the correction's |n . d|
uniform float u_l;              // opacity_unit_distance
uniform int u_table_n;
uniform float u_lo, u_hi;       // the texture window (table 0)
uniform int u_ncolor, u_nopacity;
uniform vec4 u_color[64];       // (value, r, g, b)
uniform vec2 u_opacity[64];     // (value, a)
uniform ivec2 u_layer_axes;     // texture 2d: the two in-layer axes
uniform sampler1D u_table;
#if TEXTURE_2D
uniform sampler2DArray u_volume;
#else
uniform sampler3D u_volume;
#endif
out vec4 o_color;

// piecewise linear in the rows, constant beyond the ends, k the first row with x_k > v
vec3 color_at(float v) {
    int k = 0;
    while (k < u_ncolor && !(u_color[k].x > v)) ++k;
    if (k == 0) return u_color[0].yzw;
    if (k == u_ncolor) return u_color[u_ncolor - 1].yzw;
    vec4 a = u_color[k - 1], b = u_color[k];
    return a.yzw + ((v - a.x) / (b.x - a.x)) * (b.yzw - a.yzw);
}
float opacity_at(float v) {
    int k = 0;
    while (k < u_nopacity && !(u_opacity[k].x > v)) ++k;
    if (k == 0) return u_opacity[0].y;
    if (k == u_nopacity) return u_opacity[u_nopacity - 1].y;
    vec2 a = u_opacity[k - 1], b = u_opacity[k];
    return a.y + ((v - a.x) / (b.x - a.x)) * (b.y - a.y);
}

vec4 texel(vec3 x, float layer) {
    vec3 tc = ((x - u_origin) / u_spacing + 0.5) / u_dims;
#if TEXTURE_2D
    return texture(u_volume, vec3(tc[u_layer_axes.x], tc[u_layer_axes.y], layer));
#else
    return texture(u_volume, tc);
#endif
}

vec4 classify(vec4 t) {
#if CLASSIFY_PRE
    return t;                                   // (c, a) filtered from the classified voxels
#else
    float s = t.r;
    if (u_table_n == 0) {
        float v = u_lo + s * (u_hi - u_lo);
        return vec4(color_at(v), clamp(opacity_at(v), 0.0, 1.0));
    }
    float n = float(u_table_n);
#if LOOKUP == 0
    int j = clamp(int(floor(s * (n - 1.0) + 0.5)), 0, u_table_n - 1);
    return texelFetch(u_table, j, 0);
#elif LOOKUP == 1
    return texture(u_table, (s * (n - 1.0) + 0.5) / n);
#else
    return texture(u_table, s);
#endif
#endif
}

// The fragment at world position x, standing for a level spacing `spacing` along the surfaces' normal:
// d = spacing / |n . dir| on planes, spacing on shells; alpha = 1 - (1 - a)^(d / l) with correction exact.
vec4 fragment(vec3 x, float layer, float spacing, vec3 dir) {
    vec4 ca = classify(texel(x, layer));
    float a = ca.a;
#if CORRECTION_EXACT
#if SHELLS
    float d = spacing;
#else
    float d = spacing / abs(dot(u_normal, dir));
#endif
    a = a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - a, d / u_l);
#endif
#if PREMULTIPLIED
    return vec4(a * ca.rgb, a);
#else
    return vec4(ca.rgb, a);
#endif
}
)";

const char* kPlaneMain = R"(
in vec3 v_pos;
flat in vec2 v_level;
void main() {
    vec3 dir = u_ortho == 1 ? u_f : normalize(v_pos - u_eye);
    o_color = fragment(v_pos, v_level.x, v_level.y, dir);
}
)";

// A shell |x - E| = lambda: the pixel's ray from the eye crosses it at t = lambda; fragments outside the
// box (inclusive) or, with camera near/far, outside near <= (x - E) . f <= far are discarded.
const char* kShellMain = R"(
noperspective in vec3 v_ray;
uniform float u_lambda, u_level_spacing;
uniform vec3 u_box_lo, u_box_hi;
uniform int u_clip_depth;
uniform float u_near, u_far;
void main() {
    vec3 dir = normalize(v_ray);
    vec3 x = u_eye + u_lambda * dir;
    if (any(lessThan(x, u_box_lo)) || any(greaterThan(x, u_box_hi))) discard;
    if (u_clip_depth == 1) {
        float depth = u_lambda * dot(dir, u_f);
        if (depth < u_near || depth > u_far) discard;
    }
    o_color = fragment(x, 0.0, u_level_spacing, dir);
}
)";

// ---------------------------------------------------------------------------------------------------------
int run(int argc, char** argv) {
    std::vector<std::string> overrides, positional;
    std::set<std::string> defines;
    std::string require_renderer;
    bool egl_device = false;
    int dump_x = -1, dump_y = -1;
    std::vector<std::pair<std::string, json>> local;  // --set under render.profile / camera.near / camera.far
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--set" && i + 1 < argc) {
            const std::string kv = argv[++i];
            const std::size_t eq = kv.find('=');
            if (eq == std::string::npos) refuse("--set " + kv + ": expected PATH=VALUE");
            const std::string path = kv.substr(0, eq);
            if (path == "render.profile" || path.rfind("render.profile.", 0) == 0 || path == "camera.near" || path == "camera.far")
                local.emplace_back(path, override_value(kv.substr(eq + 1)));
            else
                overrides.push_back(kv);
        } else if (a == "--define" && i + 1 < argc) {
            defines.insert(argv[++i]);
        } else if (a == "--require-renderer" && i + 1 < argc) {
            require_renderer = argv[++i];
        } else if (a == "--egl-device") {
            egl_device = true;
        } else if (a == "--fragments" && i + 1 < argc) {
            if (std::sscanf(argv[++i], "%d,%d", &dump_x, &dump_y) != 2 || dump_x < 0 || dump_y < 0) refuse("--fragments: expected X,Y");
        } else {
            positional.push_back(a);
        }
    }
    if (positional.size() != 2)
        refuse("usage: gl_slicer SCENE.json OUT.exr [--set key=value]... [--define VARIANT]... [--require-renderer S] [--egl-device]");
    static const std::set<std::string> variants = {"SLICER_CORRECTED", "SLICER_HALF", "SLICER_FLOAT_FB", "SLICER_LINEAR_TABLE",
                                                   "SLICER_DATA_WINDOW", "SLICER_NO_NEAR_FAR"};
    for (const std::string& d : defines)
        if (!variants.contains(d)) refuse("--define " + d + ": not a variant (SLICER_CORRECTED, SLICER_HALF, SLICER_FLOAT_FB, "
                                          "SLICER_LINEAR_TABLE, SLICER_DATA_WINDOW, SLICER_NO_NEAR_FAR)");

    // The scene: render.profile and camera.near / far read here, the rest by volref's loader.
    const std::filesystem::path scene_path = positional[0];
    std::ifstream in(scene_path);
    if (!in) gl_fail(2, "cannot read " + scene_path.string());
    std::stringstream text;
    text << in.rdbuf();
    json doc;
    try {
        doc = json::parse(text.str());
    } catch (const json::parse_error& e) {
        refuse(scene_path.string() + ": " + e.what());
    }
    for (const auto& [path, value] : local) set_path(doc, path, value);
    if (!doc.contains("render") || !doc["render"].contains("profile")) refuse("render.profile: required (placement \"slices\")");
    const json profile_json = doc["render"]["profile"];
    doc["render"].erase("profile");
    View view;
    if (doc.contains("camera") && doc["camera"].is_object()) {
        json& cam = doc["camera"];
        for (const char* key : {"near", "far"})
            if (cam.contains(key)) {
                if (!cam[key].is_number()) refuse(std::string("camera.") + key + ": expected a number");
                (std::string(key) == "near" ? view.near : view.far) = cam[key].get<double>();
                cam.erase(key);
            }
    }
    if (view.near.has_value() != view.far.has_value()) refuse("camera.near / camera.far: give both");
    if (view.near && !(*view.near > 0 && *view.far > *view.near)) refuse("camera.near / camera.far: expected 0 < near < far");
    if (!doc.contains("volume") || !doc["volume"].contains("transfer") || !doc["volume"]["transfer"].contains("color") ||
        !doc["volume"]["transfer"].contains("opacity"))
        refuse("volume.transfer: gl_slicer needs its color and opacity rows");

    Slicing sl = read_profile(profile_json);
    if (defines.contains("SLICER_CORRECTED")) sl.correction_exact = true;
    if (defines.contains("SLICER_HALF")) sl.first_half = true;
    if (defines.contains("SLICER_FLOAT_FB") && sl.framebuffer == Slicing::Framebuffer::Rgba8) sl.framebuffer = Slicing::Framebuffer::Rgba32f;
    if (defines.contains("SLICER_LINEAR_TABLE") && sl.table_lookup == Slicing::Lookup::Nearest) sl.table_lookup = Slicing::Lookup::Linear;
    if (defines.contains("SLICER_DATA_WINDOW") && sl.window == Slicing::Window::Rows) sl.window = Slicing::Window::DataRange;
    const bool clip_depth = view.near.has_value() && !defines.contains("SLICER_NO_NEAR_FAR");

    using namespace volref;
    const Scene scene = parse_scene(doc.dump(), scene_path.parent_path(), scene_path.filename().string(), overrides);
    if (scene.volumes.size() != 1) refuse("one volume only");
    const VolumeSpec& vs = scene.volume();
    if (vs.bounds.type != BoundsSpec::Type::Box) refuse("volume.bounds: a box only");
    if (vs.transform || !vs.clip_planes.empty() || vs.crop) refuse("no transform, clip planes or crop");
    if (vs.classification || vs.transfer.domain != TransferSpec::Domain::Data || !vs.transfer.gradient_opacity.empty())
        refuse("volume.transfer: rows in the data domain, no gradient opacity");
    if (vs.transfer.color.size() > std::size_t(kMaxRows) || vs.transfer.opacity.size() > std::size_t(kMaxRows))
        refuse("volume.transfer: at most 64 rows each");
    if (vs.interpolation != Interpolation::Trilinear || vs.classify != VolumeSpec::Classify::Post || vs.shading)
        refuse("volume: trilinear, volume.classify post, unshaded");
    const bool mip = scene.render.projection == Projection::Mip;
    if (scene.render.projection != Projection::Composite && !mip) refuse("render.projection: composite or mip");
    if (mip != (sl.blend == Slicing::Blend::Max)) refuse("render.profile.blend: \"max\" with the mip projection, and only there");
    const CameraSpec& cam = scene.camera;
    if (cam.type != CameraSpec::Type::Perspective && cam.type != CameraSpec::Type::Orthographic)
        refuse("camera: perspective or orthographic");
    const int W = scene.image.width, H = scene.image.height;
    view.ortho = cam.type == CameraSpec::Type::Orthographic;
    view.eye = cam.eye;
    view.f = glm::normalize(cam.target - cam.eye);
    view.r = glm::normalize(glm::cross(view.f, cam.up));
    view.u = glm::cross(view.r, view.f);
    view.tan_half = std::tan(cam.fov_y * std::numbers::pi / 180.0 / 2.0);
    view.aspect = double(W) / double(H);
    view.half_height = cam.height / 2.0;
    if (sl.orientation == Slicing::Orientation::Spherical && view.ortho) refuse("render.profile.slices.orientation: \"spherical\" needs a perspective camera");
    if (sl.range == Slicing::Range::ViewVolume && !view.near) refuse("render.profile.slices.range: \"view_volume\" needs camera.near and camera.far");

    const Volume vol = load_volume(vs);
    const double h = world_step(scene.render, vol);
    const double unit = h / scene.render.step;  // world units per render.step_units unit
    const double spacing_world = sl.spacing_given ? sl.spacing * unit : h;
    // The geometry: the range's box is volume.bounds' box (the domain by default); polygons are clipped to
    // it AND the domain, where the rays' intervals are.
    const Box domain{vol.domain_min(), vol.domain_max()};
    const Box range_box{vs.bounds.min.value_or(domain.lo), vs.bounds.max.value_or(domain.hi)};
    const Box clip_box{glm::max(domain.lo, range_box.lo), glm::min(domain.hi, range_box.hi)};

    // The transfer function and the texture window.
    Transfer tf;
    tf.color = vs.transfer.color;
    tf.opacity = vs.transfer.opacity;
    if (sl.window == Slicing::Window::Rows) {
        tf.lo = std::min(tf.color.front()[0], tf.opacity.front()[0]);
        tf.hi = std::max(tf.color.back()[0], tf.opacity.back()[0]);
    } else if (sl.window == Slicing::Window::DataRange) {
        const auto [vmin, vmax] = vol.value_range();
        tf.lo = vmin, tf.hi = vmax;
    } else {
        tf.lo = sl.window_lo, tf.hi = sl.window_hi;
    }
    if (!(tf.hi > tf.lo)) refuse("render.profile.texture_window: an empty window [" + std::to_string(tf.lo) + ", " + std::to_string(tf.hi) + "]");

    // --- The surfaces, the range and the levels ---------------------------------------------------------
    // lambda(x): viewport (x - E) . f; axis +-x_a; spherical |x - E|.
    int axis = 0;
    double axis_sign = 1;
    const glm::dvec3 G = 1.0 / vol.spacing;  // diag(1 / spacing): world -> voxel units
    if (sl.orientation == Slicing::Orientation::Axis) {
        dvec3 w = view.f;
        // perspective: the unit vector from E to the centre of the geometry's bounding box (volume.bounds'
        // box, the domain by default) for both ranges (object and view_volume)
        if (!view.ortho) w = glm::normalize(0.5 * (range_box.lo + range_box.hi) - view.eye);
        for (int a = 1; a < 3; ++a)
            if (std::fabs(w[a]) > std::fabs(w[axis])) axis = a;
        axis_sign = w[axis] > 0 ? 1.0 : -1.0;
    }
    auto lambda = [&](const dvec3& x) {
        switch (sl.orientation) {
        case Slicing::Orientation::Viewport: return glm::dot(x - view.eye, view.f);
        case Slicing::Orientation::Axis: return axis_sign * x[axis];
        default: return glm::length(x - view.eye);
        }
    };
    double b_near = 0, b_far = 0;
    if (sl.range == Slicing::Range::Object) {
        const auto corners = range_box.corners();
        b_near = b_far = lambda(corners[0]);
        for (const dvec3& c : corners) b_near = std::min(b_near, lambda(c)), b_far = std::max(b_far, lambda(c));
        if (sl.orientation == Slicing::Orientation::Spherical) {
            const dvec3 q = glm::clamp(view.eye, range_box.lo, range_box.hi);  // the box's point nearest to E
            b_near = glm::length(view.eye - q);
        }
    } else if (sl.orientation == Slicing::Orientation::Axis) {
        const auto corners = view.frustum_corners();
        b_near = b_far = lambda(corners[0]);
        for (const dvec3& c : corners) b_near = std::min(b_near, lambda(c)), b_far = std::max(b_far, lambda(c));
    } else {
        b_near = *view.near, b_far = *view.far;
        if (sl.orientation == Slicing::Orientation::Spherical)  // far / cos(theta_c), theta_c the corner's half-angle
            b_far = *view.far * std::sqrt(1.0 + view.tan_half * view.tan_half * (1.0 + view.aspect * view.aspect));
    }
    // period: the range's extent E and the period D along the surfaces' normal, in voxels
    double extent_voxels = 0, period_voxels = 1;
    if (sl.orientation == Slicing::Orientation::Axis) {
        extent_voxels = (b_far - b_near) / vol.spacing[axis];
        period_voxels = sl.period[axis];
    } else {
        const dvec3 gf = G * view.f;
        const dvec3 wp = gf / glm::length(gf);
        extent_voxels = (b_far - b_near) * glm::length(gf);
        period_voxels = 1.0 / glm::length(wp / sl.period);
    }
    Levels lv;
    if (sl.texture_2d) {
        // every data layer x_a = o_a + i s_a, far to near (lambda = axis_sign x_a grows away from the eye)
        const int n = int(vol.dims[std::size_t(axis)]);
        for (int k = 0; k < n; ++k) {
            const int i = axis_sign > 0 ? n - 1 - k : k;
            lv.lambda.push_back(axis_sign * (vol.origin[axis] + double(i) * vol.spacing[axis]));
            lv.layer.push_back(i);
        }
        lv.spacing = vol.spacing[axis];
    } else {
        lv = place_levels(sl, b_near, b_far, spacing_world, extent_voxels, period_voxels);
    }
    std::fprintf(stderr, "gl_slicer: %zu levels in [%.17g, %.17g], level spacing %.17g%s\n", lv.lambda.size(), b_near, b_far, lv.spacing,
                 sl.orientation == Slicing::Orientation::Axis ? (std::string(", axis ") + "xyz"[axis] + (axis_sign > 0 ? " +" : " -")).c_str() : "");

    // --- GL ------------------------------------------------------------------------------------------
    gl_headless::make_context("gl_slicer", require_renderer, egl_device);

    // The texels s_i = clamp((v - lo) / (hi - lo), 0, 1), stored per texture_format (unorm: round(q s) / q);
    // pre-unweighted: each voxel's (c, a) looked up from its stored s, as RGBA32F.
    const std::size_t nvox = std::size_t(vol.dims[0] * vol.dims[1] * vol.dims[2]);
    std::vector<double> s_stored(nvox);
    for (std::size_t i = 0; i < nvox; ++i) {
        const double s = std::clamp((vol.values[i] - tf.lo) / (tf.hi - tf.lo), 0.0, 1.0);
        s_stored[i] = sl.texture_format == Slicing::Format::Unorm8    ? quantise(s, 255.0)
                      : sl.texture_format == Slicing::Format::Unorm16 ? quantise(s, 65535.0)
                                                                        : double(float(s));
    }
    std::vector<std::array<double, 4>> table;
    if (sl.table > 0) table = make_table(tf, sl.table, sl.table_unorm8);

    // Upload in the texture's layout: 3D as stored (i fastest); 2D: layers along `axis`, each layer with its
    // two other axes (first, second) in increasing order.
    int ax0 = 0, ax1 = 1;
    if (sl.texture_2d) ax0 = axis == 0 ? 1 : 0, ax1 = axis == 2 ? 1 : 2;
    const std::array<std::int64_t, 3> d = vol.dims;
    auto layout_index = [&](std::int64_t i, std::int64_t j, std::int64_t k) -> std::size_t {
        if (!sl.texture_2d) return std::size_t(i + d[0] * (j + d[1] * k));
        const std::int64_t c[3] = {i, j, k};
        return std::size_t(c[ax0] + d[std::size_t(ax0)] * (c[ax1] + d[std::size_t(ax1)] * c[axis]));
    };
    const GLsizei tw = GLsizei(sl.texture_2d ? d[std::size_t(ax0)] : d[0]), th = GLsizei(sl.texture_2d ? d[std::size_t(ax1)] : d[1]),
                  td = GLsizei(sl.texture_2d ? d[std::size_t(axis)] : d[2]);
    const GLenum target = sl.texture_2d ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_3D;
    GLuint vtex = 0;
    glGenTextures(1, &vtex);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(target, vtex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (sl.classify_pre) {
        std::vector<float> rgba(nvox * 4);
        for (std::int64_t k = 0; k < d[2]; ++k)
            for (std::int64_t j = 0; j < d[1]; ++j)
                for (std::int64_t i = 0; i < d[0]; ++i) {
                    const double s = s_stored[std::size_t(i + d[0] * (j + d[1] * k))];
                    const auto e = sl.table > 0 ? table_read(table, s, sl.table_lookup) : tf.at_s(s);
                    for (int c = 0; c < 4; ++c) rgba[layout_index(i, j, k) * 4 + std::size_t(c)] = float(e[std::size_t(c)]);
                }
        glTexImage3D(target, 0, GL_RGBA32F, tw, th, td, 0, GL_RGBA, GL_FLOAT, rgba.data());
    } else if (sl.texture_format == Slicing::Format::Unorm8) {
        std::vector<std::uint8_t> t(nvox);
        for (std::int64_t k = 0; k < d[2]; ++k)
            for (std::int64_t j = 0; j < d[1]; ++j)
                for (std::int64_t i = 0; i < d[0]; ++i)
                    t[layout_index(i, j, k)] = std::uint8_t(std::lround(s_stored[std::size_t(i + d[0] * (j + d[1] * k))] * 255.0));
        glTexImage3D(target, 0, GL_R8, tw, th, td, 0, GL_RED, GL_UNSIGNED_BYTE, t.data());
    } else if (sl.texture_format == Slicing::Format::Unorm16) {
        std::vector<std::uint16_t> t(nvox);
        for (std::int64_t k = 0; k < d[2]; ++k)
            for (std::int64_t j = 0; j < d[1]; ++j)
                for (std::int64_t i = 0; i < d[0]; ++i)
                    t[layout_index(i, j, k)] = std::uint16_t(std::lround(s_stored[std::size_t(i + d[0] * (j + d[1] * k))] * 65535.0));
        glTexImage3D(target, 0, GL_R16, tw, th, td, 0, GL_RED, GL_UNSIGNED_SHORT, t.data());
    } else {
        std::vector<float> t(nvox);
        for (std::int64_t k = 0; k < d[2]; ++k)
            for (std::int64_t j = 0; j < d[1]; ++j)
                for (std::int64_t i = 0; i < d[0]; ++i)
                    t[layout_index(i, j, k)] = float(s_stored[std::size_t(i + d[0] * (j + d[1] * k))]);
        glTexImage3D(target, 0, GL_R32F, tw, th, td, 0, GL_RED, GL_FLOAT, t.data());
    }
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTexParameteri(target, w, GL_CLAMP_TO_EDGE);
    check_gl("volume texture");

    // The table: a 1D texture of N entries, GL_RGBA8 (codes) or GL_RGBA32F, GL_LINEAR (read with texelFetch
    // for nearest), clamped to the edge.
    GLuint ttex = 0;
    glGenTextures(1, &ttex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_1D, ttex);
    if (sl.table > 0 && !sl.classify_pre) {
        GLint max_size = 0;
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
        if (sl.table > max_size) refuse("render.profile.table: " + std::to_string(sl.table) + " entries, GL_MAX_TEXTURE_SIZE is " + std::to_string(max_size));
        if (sl.table_unorm8) {
            std::vector<std::uint8_t> t(table.size() * 4);
            for (std::size_t j = 0; j < table.size(); ++j)
                for (int c = 0; c < 4; ++c) t[j * 4 + std::size_t(c)] = std::uint8_t(std::lround(table[j][std::size_t(c)] * 255.0));
            glTexImage1D(GL_TEXTURE_1D, 0, GL_RGBA8, sl.table, 0, GL_RGBA, GL_UNSIGNED_BYTE, t.data());
        } else {
            std::vector<float> t(table.size() * 4);
            for (std::size_t j = 0; j < table.size(); ++j)
                for (int c = 0; c < 4; ++c) t[j * 4 + std::size_t(c)] = float(table[j][std::size_t(c)]);
            glTexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, sl.table, 0, GL_RGBA, GL_FLOAT, t.data());
        }
    } else {
        const float zero[4] = {0, 0, 0, 0};
        glTexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, 1, 0, GL_RGBA, GL_FLOAT, zero);
    }
    glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    check_gl("table texture");

    // The frame buffer, cleared to (0, 0, 0, 0).
    const GLenum fb_format = sl.framebuffer == Slicing::Framebuffer::Rgba8     ? GL_RGBA8
                             : sl.framebuffer == Slicing::Framebuffer::Rgba16f ? GL_RGBA16F
                                                                               : GL_RGBA32F;
    gl_headless::make_framebuffer(fb_format, W, H);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);

    // The program.
    const bool shells = sl.orientation == Slicing::Orientation::Spherical;
    std::string header = "#version 330 core\n";
    header += std::string("#define TEXTURE_2D ") + (sl.texture_2d ? "1" : "0") + "\n";
    header += std::string("#define CLASSIFY_PRE ") + (sl.classify_pre ? "1" : "0") + "\n";
    header += "#define LOOKUP " + std::to_string(int(sl.table_lookup)) + "\n";
    header += std::string("#define CORRECTION_EXACT ") + (sl.correction_exact ? "1" : "0") + "\n";
    header += std::string("#define SHELLS ") + (shells ? "1" : "0") + "\n";
    header += std::string("#define PREMULTIPLIED ") + (sl.blend == Slicing::Blend::Premultiplied ? "1" : "0") + "\n";
    const GLuint prog = gl_headless::link_program(shells ? kShellVs : kPlaneVs, header + kFragment + (shells ? kShellMain : kPlaneMain));
    glUseProgram(prog);
    auto loc = [&](const char* name) { return glGetUniformLocation(prog, name); };
    auto v3 = [&](const char* name, const dvec3& v) { glUniform3f(loc(name), float(v.x), float(v.y), float(v.z)); };
    glUniform1i(loc("u_volume"), 0);
    glUniform1i(loc("u_table"), 1);
    v3("u_origin", vol.origin);
    v3("u_spacing", vol.spacing);
    v3("u_dims", dvec3(double(d[0]), double(d[1]), double(d[2])));
    v3("u_eye", view.eye);
    v3("u_f", view.f);
    glUniform1i(loc("u_ortho"), view.ortho ? 1 : 0);
    dvec3 normal = view.f;
    if (sl.orientation == Slicing::Orientation::Axis) normal = dvec3(0.0), normal[axis] = 1.0;
    v3("u_normal", normal);
    glUniform1f(loc("u_l"), float(vs.transfer.opacity_unit_distance));
    glUniform1i(loc("u_table_n"), sl.classify_pre ? 0 : sl.table);
    glUniform1f(loc("u_lo"), float(tf.lo));
    glUniform1f(loc("u_hi"), float(tf.hi));
    {
        std::vector<float> c, a;
        for (const auto& r : tf.color) c.insert(c.end(), {float(r[0]), float(r[1]), float(r[2]), float(r[3])});
        for (const auto& r : tf.opacity) a.insert(a.end(), {float(r[0]), float(r[1])});
        glUniform1i(loc("u_ncolor"), GLint(tf.color.size()));
        glUniform1i(loc("u_nopacity"), GLint(tf.opacity.size()));
        glUniform4fv(loc("u_color"), GLsizei(tf.color.size()), c.data());
        glUniform2fv(loc("u_opacity"), GLsizei(tf.opacity.size()), a.data());
    }
    glUniform2i(loc("u_layer_axes"), ax0, ax1);
    check_gl("uniforms");

    // The blend.
    glEnable(GL_BLEND);
    if (sl.blend == Slicing::Blend::Max) {
        glBlendEquation(GL_MAX);
    } else {
        glBlendEquation(GL_FUNC_ADD);
        if (sl.front_to_back) glBlendFunc(GL_ONE_MINUS_DST_ALPHA, GL_ONE);  // under: C += (1 - A) (a c), A += (1 - A) a
        else if (sl.blend == Slicing::Blend::Premultiplied) glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        else if (sl.blend_alpha_one) glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        else glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    }

    // The order the levels are drawn in: k ascending (far first) or descending.
    std::vector<std::size_t> order(lv.lambda.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = sl.front_to_back ? order.size() - 1 - k : k;

    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    std::vector<std::pair<GLint, GLsizei>> level_ranges;  // planes: each level's triangles in the buffer
    if (shells) {
        v3("u_r", view.r);
        v3("u_u", view.u);
        glUniform1f(loc("u_tan_half"), float(view.tan_half));
        glUniform1f(loc("u_aspect"), float(view.aspect));
        v3("u_box_lo", clip_box.lo);
        v3("u_box_hi", clip_box.hi);
        glUniform1i(loc("u_clip_depth"), clip_depth ? 1 : 0);
        glUniform1f(loc("u_near"), float(view.near.value_or(0.0)));
        glUniform1f(loc("u_far"), float(view.far.value_or(0.0)));
        glUniform1f(loc("u_level_spacing"), float(lv.spacing));
        for (const std::size_t k : order) {
            glUniform1f(loc("u_lambda"), float(lv.lambda[k]));
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
    } else {
        // Each level's polygon (plane n . x = c inside the clip box), fanned into triangles, in drawing
        // order in one buffer: GL blends primitives in order.
        std::vector<float> verts;  // x, y, z, layer, level spacing
        dvec3 n(0.0);
        level_ranges.assign(lv.lambda.size(), {0, 0});
        if (sl.orientation == Slicing::Orientation::Viewport) n = view.f;
        else n[axis] = 1.0;
        for (const std::size_t k : order) {
            // viewport: (x - E) . f = lambda  <=>  f . x = lambda + f . E; axis: x_a = sign lambda
            const double c = sl.orientation == Slicing::Orientation::Viewport ? lv.lambda[k] + glm::dot(view.f, view.eye) : axis_sign * lv.lambda[k];
            const auto poly = clip_plane_to_box(n, c, clip_box);
            const float layer = lv.layer.empty() ? 0.0f : float(lv.layer[k]);
            level_ranges[k] = {GLint(verts.size() / 5), GLsizei(poly.size() < 3 ? 0 : 3 * (poly.size() - 2))};
            for (std::size_t t = 1; t + 1 < poly.size(); ++t)
                for (const dvec3& p : {poly[0], poly[t], poly[t + 1]})
                    verts.insert(verts.end(), {float(p.x), float(p.y), float(p.z), layer, float(lv.spacing)});
        }
        // The projection's near and far: camera.near / far widened by kClipWiden; otherwise planes that
        // enclose the box (perspective: a near plane at a small fraction of the box's farthest depth, as
        // volref's rays start at t = 0; orthographic: the eye's plane).
        double zfar_box = 0;
        for (const dvec3& c : clip_box.corners()) zfar_box = std::max(zfar_box, glm::dot(c - view.eye, view.f));
        double zn = 0, zf = 0;
        if (clip_depth) {
            zn = *view.near * (1.0 - kClipWiden), zf = *view.far * (1.0 + kClipWiden);
        } else {
            zf = zfar_box * (1.0 + 1e-3) + 1.0;
            zn = view.ortho ? 0.0 : zf * 1e-6;
        }
        const glm::dmat4 mvp = projection_matrix(view, zn, zf) * view_matrix(view);
        float m[16];
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row) m[col * 4 + row] = float(mvp[col][row]);
        glUniformMatrix4fv(loc("u_mvp"), 1, GL_FALSE, m);
        GLuint vbo = 0;
        glGenBuffers(1, &vbo);
        glBindBuffer(GL_ARRAY_BUFFER, vbo);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(verts.size() * sizeof(float)), verts.data(), GL_STATIC_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 5 * sizeof(float), nullptr);
        glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 5 * sizeof(float), reinterpret_cast<const void*>(3 * sizeof(float)));
        glEnableVertexAttribArray(0);
        glEnableVertexAttribArray(1);
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(verts.size() / 5));
        std::fprintf(stderr, "gl_slicer: %zu triangles, GL near %.9g far %.9g\n", verts.size() / 15, zn, zf);
    }
    glFinish();
    check_gl("draw");

    // Read back (GL row 0 is the bottom, volref's the top) and write the frame buffer as it holds it:
    // rgba8 as codes / 255, float buffers as stored.
    Image img(W, H, {"R", "G", "B", "A"});
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    if (sl.framebuffer == Slicing::Framebuffer::Rgba8) {
        std::vector<std::uint8_t> px(std::size_t(W) * std::size_t(H) * 4);
        glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                for (int c = 0; c < 4; ++c)
                    img.at(x, y, std::size_t(c)) = px[(std::size_t(H - 1 - y) * std::size_t(W) + std::size_t(x)) * 4 + std::size_t(c)] / 255.0;
    } else {
        std::vector<float> px(std::size_t(W) * std::size_t(H) * 4);
        glReadPixels(0, 0, W, H, GL_RGBA, GL_FLOAT, px.data());
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                for (int c = 0; c < 4; ++c)
                    img.at(x, y, std::size_t(c)) = px[(std::size_t(H - 1 - y) * std::size_t(W) + std::size_t(x)) * 4 + std::size_t(c)];
    }
    check_gl("read");
    write_image(img, positional[1], scene.image.background);

    // --fragments X,Y: each level's fragment at pixel (x, y) (row 0 at the top) alone, unblended, in
    // RGBA32F, far first: the shader's output (src-alpha and max: (c, a); premultiplied: (a c, a)).
    if (dump_x >= 0) {
        gl_headless::make_framebuffer(GL_RGBA32F, W, H);
        glDisable(GL_BLEND);
        for (std::size_t k = 0; k < lv.lambda.size(); ++k) {
            glClearColor(0, 0, 0, -1);  // alpha -1: no fragment
            glClear(GL_COLOR_BUFFER_BIT);
            if (shells) {
                glUniform1f(loc("u_lambda"), float(lv.lambda[k]));
                glDrawArrays(GL_TRIANGLES, 0, 3);
            } else if (level_ranges[k].second > 0) {
                glDrawArrays(GL_TRIANGLES, level_ranges[k].first, level_ranges[k].second);
            }
            float f[4];
            glReadPixels(dump_x, H - 1 - dump_y, 1, 1, GL_RGBA, GL_FLOAT, f);
            if (f[3] >= 0)
                std::printf("level %zu lambda %.17g fragment %.9g %.9g %.9g %.9g (x 255: %.6f %.6f %.6f %.6f)\n", k, lv.lambda[k],
                            f[0], f[1], f[2], f[3], 255.0 * f[0], 255.0 * f[1], 255.0 * f[2], 255.0 * f[3]);
        }
        check_gl("fragments");
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const gl_headless::GlFail& f) {
        std::fprintf(stderr, "gl_slicer: %s\n", f.what.c_str());
        return f.code;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gl_slicer: %s\n", e.what());
        return 2;
    }
}
