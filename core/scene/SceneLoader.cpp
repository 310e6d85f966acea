// Scene loading: JSON text -> --set overrides -> strict validation -> Scene (docs/scene-format.md).
//
// Every problem is a volref::Error "<file>: <json path>: <problem>". Keys of the format that later work
// implements (transforms, clip planes, cropping, meshes and shells, ...) are recognised and rejected as
// "not implemented yet" rather than reported as unknown or silently ignored.
#include "core/scene/SceneLoader.h"

#include <algorithm>
#include <iostream>
#include <charconv>
#include <cmath>
#include <iterator>
#include <system_error>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <nlohmann/json.hpp>

#include "core/Angles.h"
#include "core/Conventions.h"
#include "core/Error.h"
#include "core/InputFile.h"
#include "core/scene/JsonReader.h"
#include "core/scene/ProfileRuleTable.h"
#include "core/scene/SceneNames.h"

namespace volref {

namespace {

namespace fs = std::filesystem;
namespace names = scene_names;
using json_reader::Choice;
using json_reader::Context;
using json_reader::Json;
using json_reader::ObjectReader;
using json_reader::Range;
using json_reader::child_path;
using json_reader::describe;
using json_reader::element;
using json_reader::format_number;
using json_reader::index_path;
using json_reader::read_array_size;
using json_reader::read_integer;
using json_reader::read_number;
using json_reader::read_numbers;
using json_reader::read_string;
using json_reader::read_vec3;

// Limits.
constexpr std::int64_t kMaxFieldVoxels = std::int64_t{1} << 31;  // procedural fields: at most 2^31 voxels
constexpr std::int64_t kMaxImageSide = 32768;                    // image width and height: [1, 32768]
constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 28;  // width * height <= 2^28

// ------------------------------------------------------------------------------------------------
// --set PATH=VALUE overrides
// ------------------------------------------------------------------------------------------------

// One step of an override path: a key, or an [index] into an array.
struct PathStep {
    bool is_index = false;
    std::string key;
    std::size_t index = 0;
};

bool is_key_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

// PATH: keys ([A-Za-z0-9_-]+) separated by '.', each optionally followed by [index] suffixes,
// e.g. `volume.transfer.opacity[2][1]`.
std::vector<PathStep> parse_override_path(const std::string& path, const Context& ctx) {
    const auto malformed = [&](std::size_t at, const std::string& what) {
        ctx.fail_plain("malformed path \"" + path + "\": " + what + " at character " + std::to_string(at + 1));
    };
    std::vector<PathStep> steps;
    std::size_t i = 0;
    const std::size_t n = path.size();
    while (true) {
        const std::size_t start = i;
        while (i < n && is_key_char(path[i])) ++i;
        if (i == start) malformed(i, "expected a key");
        steps.push_back({false, path.substr(start, i - start), 0});
        while (i < n && path[i] == '[') {
            const std::size_t digits = ++i;
            while (i < n && path[i] >= '0' && path[i] <= '9') ++i;
            if (i == digits || i == n || path[i] != ']') malformed(i, "expected [index]");
            std::size_t index = 0;
            const auto r = std::from_chars(path.data() + digits, path.data() + i, index);
            if (r.ec != std::errc()) malformed(digits, "index too large");
            steps.push_back({true, {}, index});
            ++i;
        }
        if (i == n) return steps;
        if (path[i] != '.') malformed(i, std::string("unexpected '") + path[i] + "'");
        ++i;
    }
}

// Applies `text` ("PATH=VALUE") to `root`. Missing intermediate objects are created; an index must
// name an existing element. VALUE is JSON when it parses as JSON, otherwise a string.
void apply_override(Json& root, const std::string& text, Context& scene_ctx) {
    const Context ctx("--set " + text);
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos) ctx.fail_plain("missing '='");
    const std::vector<PathStep> steps = parse_override_path(text.substr(0, eq), ctx);

    Json* at = &root;
    std::string path;
    for (const PathStep& step : steps) {
        if (!step.is_index) {
            if (at->is_null()) *at = Json::object();  // a missing intermediate object
            // a rule set over a preset given by name: "vtk-gpu" becomes {"base": "vtk-gpu"}
            if (path == "render.profile" && at->is_string()) *at = Json{{"base", *at}};
            if (!at->is_object())
                ctx.fail(path, "expected an object to set \"" + step.key + "\" in, got " + describe(*at));
            at = &(*at)[step.key];
            path = child_path(path, step.key);
        } else {
            if (!at->is_array())
                ctx.fail(path, at->is_null() ? std::string("no such array") : "expected an array, got " + describe(*at));
            if (step.index >= at->size())
                ctx.fail(index_path(path, step.index),
                         "index past the end (the array has " + std::to_string(at->size()) + " elements)");
            at = &(*at)[step.index];
            path = index_path(path, step.index);
        }
    }
    const std::string value = text.substr(eq + 1);
    std::optional<Json> parsed = json_reader::try_parse_json(value, ctx.name(), path);
    *at = parsed ? std::move(*parsed) : Json(value);
    scene_ctx.add_override(path, text);
}

// ------------------------------------------------------------------------------------------------
// Small readers
// ------------------------------------------------------------------------------------------------

double max_abs(const glm::dvec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }

bool all_finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Relative paths are relative to the scene file's folder; stored absolute and lexically normal, a symbolic
// link kept as written (its name gives the format, and messages name what the scene names).
fs::path resolve_file(const Json& v, const std::string& path, const Context& ctx, const fs::path& base_dir) {
    const std::string s = read_string(v, path, ctx);
    if (s.empty()) ctx.fail(path, "expected a file path, got \"\"");
    fs::path p(s);
    if (p.is_relative()) p = base_dir / p;
    std::error_code ec;
    const fs::path absolute = fs::absolute(p, ec);
    return (ec ? p : absolute).lexically_normal();
}

// A non-zero direction, normalised (scaled first, so that tiny or huge components do not under- or
// overflow).
glm::dvec3 read_direction(ObjectReader& r, std::string_view key) {
    const glm::dvec3 d = read_vec3(r.required(key), r.path(key), r.context());
    const double m = max_abs(d);
    if (m == 0.0) r.fail(key, "expected a non-zero direction, got [0, 0, 0]");
    return glm::normalize(d / m);
}

// Rows [key, x1, ..., x(N-1)] sorted by key (non-decreasing), at least one; x in `range`, the key in
// `key_range`. `key_name` names the key in messages ("value", "|grad f|").
template <std::size_t N>
std::vector<std::array<double, N>> read_rows(const Json& v, const std::string& path, const Context& ctx,
                                             std::string_view shape, const Range& range,
                                             const Range& key_range = {}, std::string_view key_name = "value") {
    const std::size_t n = read_array_size(v, path, ctx);
    if (n == 0) ctx.fail(path, "expected at least one row " + std::string(shape));
    std::vector<std::array<double, N>> rows;
    rows.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Json& row = element(v, i);
        const std::string row_path = index_path(path, i);
        if (!row.is_array() || row.size() != N)
            ctx.fail(row_path, "expected a row " + std::string(shape) + " of " + std::to_string(N) +
                                   " numbers, got " + describe(row));
        std::array<double, N> out{};
        out[0] = read_number(row[0], index_path(row_path, 0), ctx, key_range);
        for (std::size_t k = 1; k < N; ++k) out[k] = read_number(row[k], index_path(row_path, k), ctx, range);
        if (i > 0 && out[0] < rows.back()[0])
            ctx.fail(row_path, "rows must be sorted by " + std::string(key_name) + " (non-decreasing): " +
                                   format_number(out[0]) +
                                   " follows " + format_number(rows.back()[0]));
        rows.push_back(out);
    }
    return rows;
}

// ------------------------------------------------------------------------------------------------
// volume
// ------------------------------------------------------------------------------------------------

// dims: 3 integers >= 1 (default [2, 2, 2]), at most 2^31 voxels in all.
std::array<std::int64_t, 3> read_dims(ObjectReader& r) {
    std::array<std::int64_t, 3> dims{2, 2, 2};
    const Json* v = r.find("dims");
    if (!v) return dims;
    const std::string path = r.path("dims");
    if (!v->is_array() || v->size() != 3)
        r.fail("dims", "expected an array of 3 integers >= 1, got " + describe(*v));
    for (std::size_t i = 0; i < 3; ++i)
        dims[i] = read_integer(element(*v, i), index_path(path, i), r.context(), Range::at_least(1));
    // Each factor is >= 1, so checking the partial products in order never overflows.
    const bool too_many = dims[0] > kMaxFieldVoxels || dims[1] > kMaxFieldVoxels || dims[2] > kMaxFieldVoxels ||
                          dims[0] * dims[1] > kMaxFieldVoxels || dims[0] * dims[1] * dims[2] > kMaxFieldVoxels;
    if (too_many)
        r.fail("dims", std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " + std::to_string(dims[2]) +
                           " voxels exceed the limit of 2^31 (2147483648) voxels for procedural fields");
    return dims;
}

// cells: `values`, exactly nx*ny*nz numbers, i fastest.
std::vector<double> read_cell_values(ObjectReader& r, const std::array<std::int64_t, 3>& dims) {
    const Json& v = r.required("values");
    const std::string path = r.path("values");
    const auto count = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
    const std::size_t n = read_array_size(v, path, r.context());
    if (n != count)
        r.fail("values", "expected " + std::to_string(count) + " values (dims " + std::to_string(dims[0]) + " x " +
                             std::to_string(dims[1]) + " x " + std::to_string(dims[2]) + "), got " + std::to_string(n));
    std::vector<double> values;
    values.reserve(n);
    for (std::size_t i = 0; i < n; ++i) values.push_back(read_number(element(v, i), index_path(path, i), r.context()));
    return values;
}

// {"field": NAME, "dims": [nx, ny, nz], ...}: each field takes only its own parameters.
FieldSpec read_field(ObjectReader& r) {
    using K = FieldSpec::Kind;
    FieldSpec f;
    f.kind = r.required_choice<K>("field", names::kFields);
    const std::string what = "for field \"" + r.string("field", "") + "\"";
    switch (f.kind) {
        case K::Constant: r.allow({"field", "dims", "value"}, what); break;
        case K::Linear: r.allow({"field", "dims", "coefficients"}, what); break;
        case K::Radial: r.allow({"field", "dims", "center"}, what); break;
        case K::MarschnerLobb: r.allow({"field", "dims", "fm", "alpha"}, what); break;
        case K::Gaussian: r.allow({"field", "dims", "center", "sigma", "amplitude"}, what); break;
        case K::Cells: r.allow({"field", "dims", "values"}, what); break;
    }
    f.dims = read_dims(r);
    switch (f.kind) {
        case K::Constant: f.value = r.number("value", 0.0); break;
        case K::Linear:
            if (const Json* c = r.find("coefficients")) {
                const std::vector<double> a = read_numbers(*c, r.path("coefficients"), r.context(), 4);
                std::copy(a.begin(), a.end(), f.coefficients.begin());
            }
            break;
        case K::Radial: f.center = r.vec3("center", glm::dvec3(0.0)); break;
        case K::MarschnerLobb:
            f.fm = r.number("fm", 6.0, Range::non_negative());
            f.alpha = r.number("alpha", 0.25, Range::non_negative());
            break;
        case K::Gaussian:
            f.center = r.vec3("center", glm::dvec3(0.0));
            f.sigma = r.number("sigma", 1.0, Range::positive());
            f.amplitude = r.number("amplitude", 1.0);
            break;
        case K::Cells: f.values = read_cell_values(r, f.dims); break;
    }
    return f;
}

// A file path (format from the extension), {"file": PATH, "format": "nrrd" | "raw" | "nifti" | "metaimage" |
// "vtk" | "vti" | "den"} or a field.
VolumeSourceSpec read_source(const Json& v, const std::string& path, const Context& ctx, const fs::path& base_dir) {
    VolumeSourceSpec s;
    if (v.is_string()) {
        s.file = resolve_file(v, path, ctx, base_dir);
        return s;
    }
    if (!v.is_object())
        ctx.fail(path, "expected a file path or an object with \"file\" or \"field\", got " + describe(v));
    ObjectReader r(v, path, ctx);
    const bool has_file = r.has("file"), has_field = r.has("field");
    if (has_file && has_field) r.fail_here("give either \"file\" or \"field\", not both");
    if (!has_file && !has_field) {
        r.allow({"file", "format", "field"});
        r.fail_here("expected an object with \"file\" or \"field\"");
    }
    if (has_field) {
        s.field = read_field(r);
        return s;
    }
    r.allow({"file", "format"}, "for a file source");
    s.file = resolve_file(r.required("file"), r.path("file"), ctx, base_dir);
    s.format = std::string(r.choice<std::string_view>("format", "", {{"nrrd", "nrrd"}, {"raw", "raw"}, {"nifti", "nifti"}, {"metaimage", "metaimage"},
                                                         {"vtk", "vtk"}, {"vti", "vti"}, {"den", "den"}}));
    return s;
}

// {"type": "box", "min": [3], "max": [3]}: min < max on every axis when both are given.
// [lo, hi] with lo < hi, each in `range`.
std::array<double, 2> read_range(ObjectReader& r, std::string_view key, std::array<double, 2> fallback,
                                 const Range& range = {}) {
    const Json* j = r.find(key);
    if (!j) return fallback;
    const std::vector<double> x = read_numbers(*j, r.path(key), r.context(), 2, range);
    if (!(x[0] < x[1])) r.fail(key, "expected [lo, hi] with lo < hi, got " + describe(*j));
    return {x[0], x[1]};
}

// Angles [a0, a1] in degrees with a0 < a1 <= a0 + 360 (a full turn when a1 - a0 = 360).
std::array<double, 2> read_angle_range(ObjectReader& r, std::string_view key) {
    const std::array<double, 2> a = read_range(r, key, {0.0, 360.0});
    if (a[1] - a[0] > 360.0) r.fail(key, "expected a range of at most 360 degrees");
    return a;
}

// The keys of a cylindrical or spherical shell (b.type already read): the one reader of a shell, for
// a scene's volume.bounds and for parse_shell (volref resample --shell). radius is required, and height
// for a cylinder (a shell places the samples: no unit default); ranges are [lo, hi] with lo < hi,
// radius >= 0, angle and longitude spans at most 360, latitude in [-90, 90]; tessellate >= 3.
void read_shell(ObjectReader& r, BoundsSpec& b) {
    using T = BoundsSpec::Type;
    const Range radius = Range::non_negative();
    if (b.type == T::Cylindrical) {
        r.allow({"type", "center", "radius", "angle", "height", "tessellate"}, "for bounds type \"cylindrical\"");
        CylindricalShell& c = b.cylinder;
        c.center = r.vec3("center", glm::dvec3(0.0));
        r.required("radius");
        const auto rr = read_range(r, "radius", {0.0, 1.0}, radius);
        const auto a = read_angle_range(r, "angle");
        r.required("height");
        const auto h = read_range(r, "height", {0.0, 1.0});
        c.r0 = rr[0];
        c.r1 = rr[1];
        c.a0 = a[0];
        c.a1 = a[1];
        c.h0 = h[0];
        c.h1 = h[1];
    } else {
        r.allow({"type", "center", "radius", "longitude", "latitude", "axes", "tessellate"},
                "for bounds type \"spherical\"");
        SphericalShell& s = b.sphere;
        s.center = r.vec3("center", glm::dvec3(0.0));
        r.required("radius");
        const auto rr = read_range(r, "radius", {0.0, 1.0}, radius);
        const auto lon = read_angle_range(r, "longitude");
        const auto lat = read_range(r, "latitude", {-90.0, 90.0}, Range::closed(-90.0, 90.0));
        s.r0 = rr[0];
        s.r1 = rr[1];
        s.lon0 = lon[0];
        s.lon1 = lon[1];
        s.lat0 = lat[0];
        s.lat1 = lat[1];
        if (const Json* ax = r.find("axes")) {
            const std::string p = r.path("axes");
            const Context& ctx = r.context();
            if (!ax->is_array() || ax->size() != 3)
                ctx.fail(p, "expected 3 names, a permutation of \"longitude\", \"latitude\", \"radius\"");
            std::array<bool, 3> used{false, false, false};
            for (std::size_t i = 0; i < 3; ++i) {
                const Json& e = (*ax)[i];
                const std::string ep = p + "[" + std::to_string(i) + "]";
                const std::string name = e.is_string() ? e.get<std::string>() : "";
                int k = -1;
                for (const auto& axis : names::kSphericalAxes)
                    if (axis.name == name) k = axis.value;
                if (k < 0) ctx.fail(ep, "expected \"longitude\", \"latitude\" or \"radius\", got " + describe(e));
                if (used[std::size_t(k)]) ctx.fail(ep, "\"" + name + "\" is given twice");
                used[std::size_t(k)] = true;
                s.axes[i] = k;
            }
        }
    }
    b.tessellate = int(r.integer("tessellate", 0, Range::at_least(3)));
}

BoundsSpec read_bounds(const Json& v, const std::string& path, const Context& ctx, const fs::path& base_dir) {
    using T = BoundsSpec::Type;
    ObjectReader r(v, path, ctx);
    BoundsSpec b;
    b.type = r.choice<T>("type", T::Box, names::kBounds);
    switch (b.type) {
        case T::Box: break;
        case T::Mesh:
            r.allow({"type", "file"}, "for bounds type \"mesh\"");
            b.mesh = resolve_file(r.required("file"), r.path("file"), ctx, base_dir);
            return b;
        case T::Tetrahedra:
            r.allow({"type", "file", "overlap"}, "for bounds type \"tetrahedra\"");
            b.mesh = resolve_file(r.required("file"), r.path("file"), ctx, base_dir);
            b.overlap = r.choice<BoundsSpec::Overlap>("overlap", BoundsSpec::Overlap::Union, names::kOverlaps);
            return b;
        case T::Cylindrical:
        case T::Spherical:
            read_shell(r, b);
            return b;
    }
    r.allow({"type", "min", "max"}, "for bounds type \"box\"");
    b.min = r.optional_vec3("min");
    b.max = r.optional_vec3("max");
    if (b.min && b.max && !(b.min->x < b.max->x && b.min->y < b.max->y && b.min->z < b.max->z))
        r.fail("max", "expected max > min on every axis, got min " + describe(*r.find("min")) + " and max " +
                          describe(*r.find("max")));
    return b;
}

// Piecewise-linear colour and opacity; absent rows stay empty (the renderer fills its defaults).
TransferSpec read_transfer(const Json& v, const std::string& path, const Context& ctx) {
    using D = TransferSpec::Domain;
    ObjectReader r(v, path, ctx);
    r.allow({"domain", "window", "color", "opacity", "gradient_opacity", "opacity_unit_distance"});
    TransferSpec t;
    t.domain = r.choice<D>("domain", D::Data, names::kTransferDomains);
    if (const Json* w = r.find("window")) {
        if (t.domain != D::Normalized)
            r.fail("window", "a window applies only to \"domain\": \"normalized\" (the data domain uses values as they are)");
        const std::vector<double> x = read_numbers(*w, r.path("window"), ctx, 2);
        if (!(x[0] < x[1])) r.fail("window", "expected [lo, hi] with lo < hi, got " + describe(*w));
        t.window = std::array<double, 2>{x[0], x[1]};
    }
    if (const Json* c = r.find("color")) t.color = read_rows<4>(*c, r.path("color"), ctx, "[value, r, g, b]", Range::non_negative());
    if (const Json* o = r.find("opacity")) t.opacity = read_rows<2>(*o, r.path("opacity"), ctx, "[value, a]", Range::closed(0, 1));
    t.opacity_unit_distance = r.number("opacity_unit_distance", 1.0, Range::positive());
    if (const Json* g = r.find("gradient_opacity"))
        t.gradient_opacity = read_rows<2>(*g, r.path("gradient_opacity"), ctx, "[|grad f|, factor]",
                                          Range::non_negative(), Range::non_negative(), "|grad f|");
    return t;
}

// One element of classification.isovalues: {"value" (required), "opacity", "thickness", "color"}.
IsovalueContour read_isovalue(const Json& v, const std::string& path, const Context& ctx) {
    ObjectReader r(v, path, ctx);
    r.allow({"value", "opacity", "thickness", "color"}, "for an isovalue contour");
    IsovalueContour c;
    c.value = read_number(r.required("value"), r.path("value"), ctx);
    c.opacity = r.number("opacity", 1.0, Range::closed(0, 1));
    c.thickness = r.number("thickness", 1.0, Range::positive());
    c.color = r.vec3("color", glm::dvec3(1.0), Range::non_negative());
    return c;
}

// One element of classification.regions: {"value" (required), "opacity", "color"}.
BoundaryRegion read_region(const Json& v, const std::string& path, const Context& ctx) {
    ObjectReader r(v, path, ctx);
    r.allow({"value", "opacity", "color"}, "for a boundary region");
    BoundaryRegion b;
    b.value = read_number(r.required("value"), r.path("value"), ctx);
    b.opacity = r.number("opacity", 1.0, Range::closed(0, 1));
    b.color = r.vec3("color", glm::dvec3(1.0), Range::non_negative());
    return b;
}

// Levoy's classification (conventions section 7): {"type": "isovalue", "isovalues": [...]} or
// {"type": "boundary", "regions": [...]}, each with "opacity_unit_distance".
ClassificationSpec read_classification(const Json& v, const std::string& path, const Context& ctx) {
    using T = ClassificationSpec::Type;
    ObjectReader r(v, path, ctx);
    // Without "type", a misspelt key is reported before "type: required".
    if (!r.has("type")) r.allow({"type", "isovalues", "regions", "opacity_unit_distance"});
    ClassificationSpec c;
    c.type = r.required_choice<T>("type", names::kClassifications);
    if (c.type == T::Isovalue) {
        r.allow({"type", "isovalues", "opacity_unit_distance"}, "for classification type \"isovalue\"");
        const Json& list = r.required("isovalues");
        const std::string list_path = r.path("isovalues");
        const std::size_t n = read_array_size(list, list_path, ctx);
        if (n == 0) r.fail("isovalues", "expected at least one isovalue contour, got []");
        for (std::size_t i = 0; i < n; ++i)
            c.isovalues.push_back(read_isovalue(element(list, i), index_path(list_path, i), ctx));
    } else {
        r.allow({"type", "regions", "opacity_unit_distance"}, "for classification type \"boundary\"");
        const Json& list = r.required("regions");
        const std::string list_path = r.path("regions");
        const std::size_t n = read_array_size(list, list_path, ctx);
        if (n < 2) r.fail("regions", "expected at least two regions, got " + std::to_string(n));
        for (std::size_t i = 0; i < n; ++i) {
            const std::string region_path = index_path(list_path, i);
            c.regions.push_back(read_region(element(list, i), region_path, ctx));
            if (i > 0 && !(c.regions[i].value > c.regions[i - 1].value))
                ctx.fail(child_path(region_path, "value"),
                         "region values must be strictly increasing: " + format_number(c.regions[i].value) +
                             " follows " + format_number(c.regions[i - 1].value));
        }
    }
    c.opacity_unit_distance = r.number("opacity_unit_distance", 1.0, Range::positive());
    return c;
}

// Gradient shading (conventions section 8). Nodal shading has no specular term: "ks" and "n" are
// errors with it, and ks is stored as 0.
ShadingSpec read_shading(const Json& v, const std::string& path, const Context& ctx) {
    using M = ShadingSpec::Model;
    ObjectReader r(v, path, ctx);
    r.allow({"model", "ka", "kd", "ks", "n", "kc", "kl", "two_sided"});
    ShadingSpec s;
    s.model = r.choice<M>("model", M::BlinnPhong, names::kShadingModels);
    if (s.model == M::Nodal) {
        r.reject("ks", "the nodal model has no specular term");
        r.reject("n", "the nodal model has no specular term (n is its exponent)");
    }
    s.ka = r.number("ka", 0.1, Range::non_negative());
    s.kd = r.number("kd", 0.7, Range::non_negative());
    s.ks = s.model == M::Nodal ? 0.0 : r.number("ks", 0.2, Range::non_negative());
    s.n = r.number("n", 10.0, Range::positive());
    s.kc = r.number("kc", 1.0, Range::non_negative());
    s.kl = r.number("kl", 0.0, Range::non_negative());
    if (s.kc == 0.0 && s.kl == 0.0)
        r.fail("kc", "kc and kl are both 0, so the depth cueing 1 / (kc + kl d) divides by 0 (give kc > 0 or kl > 0)");
    s.two_sided = r.boolean("two_sided", false);
    return s;
}

// {"scheme": "central" | "forward" | "analytic", "cache": bool | "auto"} (an extension of the format).
GradientSpec read_gradient(const Json& v, const std::string& path, const Context& ctx, Interpolation interpolation) {
    using S = GradientSpec::Scheme;
    ObjectReader r(v, path, ctx);
    r.allow({"scheme", "cache"});
    GradientSpec g;
    g.scheme = r.choice<S>("scheme", S::Default, names::kGradientSchemes);
    const bool tricubic =
        interpolation == Interpolation::TricubicBSpline || interpolation == Interpolation::TricubicCatmullRom;
    if (g.scheme == S::Analytic && !tricubic)
        r.fail("scheme", "analytic gradients need a tricubic interpolation (\"tricubic-bspline\" or "
                         "\"tricubic-catmull-rom\"); use \"central\" or \"forward\" with \"" +
                             std::string(interpolation == Interpolation::Nearest ? "nearest" : "trilinear") + "\"");
    if (const Json* c = r.find("cache"); c && c->is_string()) {
        if (c->get<std::string>() != "auto")
            r.fail("cache", "expected true, false or \"auto\", got \"" + c->get<std::string>() + "\"");
        g.cache_auto = true;
    } else {
        g.cache = r.boolean("cache", false);
    }
    return g;
}

// An invertible affine matrix whose entries and inverse are finite; `path` names it in messages.
void check_affine(const glm::dmat4& m, const std::string& path, const Context& ctx) {
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row)
            if (!std::isfinite(m[col][row])) ctx.fail(path, "the matrix has a non-finite entry");
    if (!(m[0][3] == 0.0 && m[1][3] == 0.0 && m[2][3] == 0.0 && m[3][3] == 1.0))
        ctx.fail(path, "expected an affine matrix (last row 0 0 0 1), got last row " + format_number(m[0][3]) + " " +
                           format_number(m[1][3]) + " " + format_number(m[2][3]) + " " + format_number(m[3][3]));
    const double det = glm::determinant(glm::dmat3(m));
    if (!(std::fabs(det) > 1e-300) || !std::isfinite(det))
        ctx.fail(path, "the matrix is not invertible (determinant " + format_number(det) + ")");
    const glm::dmat4 inverse = glm::inverse(m);
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row)
            if (!std::isfinite(inverse[col][row])) ctx.fail(path, "the matrix is not invertible (its inverse overflows)");
}

// "transform": 16 numbers, a ROW-major 4x4 affine matrix (as written on paper: the first four numbers
// are the first row), or {"scale": [3], "rotate": {"axis": [3], "degrees": d}, "translate": [3]}
// applied in that order (M = T R S); each part optional.
glm::dmat4 read_transform(const Json& v, const std::string& path, const Context& ctx) {
    glm::dmat4 m(1.0);
    if (v.is_array()) {
        const std::vector<double> a = read_numbers(v, path, ctx, 16);
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) m[col][row] = a[static_cast<std::size_t>(4 * row + col)];
    } else {
        ObjectReader r(v, path, ctx);
        r.allow({"scale", "rotate", "translate"});
        const glm::dvec3 scale = r.vec3("scale", glm::dvec3(1.0));
        for (int a = 0; a < 3; ++a)
            if (scale[a] == 0.0) r.fail("scale", "expected non-zero scale factors, got " + format_number(scale[a]));
        glm::dmat3 rotation(1.0);
        if (const Json* rot = r.find("rotate")) {
            ObjectReader rr(*rot, r.path("rotate"), ctx);
            rr.allow({"axis", "degrees"});
            const glm::dvec3 axis = read_direction(rr, "axis");
            const double degrees = rr.number("degrees", 0.0);
            rotation = rotation_matrix(axis, degrees);
        }
        const glm::dvec3 translate = r.vec3("translate", glm::dvec3(0.0));
        const glm::dmat3 linear = rotation * glm::dmat3(glm::dvec3(scale.x, 0, 0), glm::dvec3(0, scale.y, 0),
                                                        glm::dvec3(0, 0, scale.z));
        m = glm::dmat4(linear);
        m[3] = glm::dvec4(translate, 1.0);
    }
    check_affine(m, path, ctx);
    return m;
}

// [{"point": [3], "normal": [3] non-zero}, ...]
std::vector<ClipPlaneSpec> read_clip_planes(const Json& v, const std::string& path, const Context& ctx) {
    const std::size_t n = read_array_size(v, path, ctx);
    std::vector<ClipPlaneSpec> planes;
    for (std::size_t i = 0; i < n; ++i) {
        ObjectReader r(element(v, i), index_path(path, i), ctx);
        r.allow({"point", "normal"});
        ClipPlaneSpec p;
        p.point = read_vec3(r.required("point"), r.path("point"), ctx);
        p.normal = read_direction(r, "normal");
        planes.push_back(p);
    }
    return planes;
}

// {"planes": [x0, x1, y0, y1, z0, z1], "regions": "subvolume" | "fence" | "inverted-fence" | "cross" |
// "inverted-cross" | a 27-bit integer}; VTK's constants VTK_CROP_SUBVOLUME .. VTK_CROP_INVERTED_CROSS.
CropSpec read_crop(const Json& v, const std::string& path, const Context& ctx) {
    ObjectReader r(v, path, ctx);
    r.allow({"planes", "regions"});
    CropSpec c;
    const std::vector<double> planes = read_numbers(r.required("planes"), r.path("planes"), ctx, 6);
    for (int a = 0; a < 3; ++a) {
        c.planes[std::size_t(2 * a)] = planes[std::size_t(2 * a)];
        c.planes[std::size_t(2 * a + 1)] = planes[std::size_t(2 * a + 1)];
        if (!(planes[std::size_t(2 * a)] <= planes[std::size_t(2 * a + 1)]))
            ctx.fail(index_path(r.path("planes"), std::size_t(2 * a + 1)),
                     std::string("the ") + "xyz"[a] + " planes must not decrease: " + format_number(planes[std::size_t(2 * a + 1)]) +
                         " < " + format_number(planes[std::size_t(2 * a)]));
    }
    if (const Json* f = r.find("regions"); f && f->is_number()) {
        c.regions = std::uint32_t(read_integer(*f, r.path("regions"), ctx, Range::closed(0, double((1u << 27) - 1))));
    } else {
        enum class P : std::uint32_t {
            SubVolume = 0x0002000, Fence = 0x2ebfeba, InvertedFence = 0x5140145, Cross = 0x0417410, InvertedCross = 0x7be8bef
        };
        c.regions = std::uint32_t(r.choice<P>("regions", P::SubVolume,
                                              {{"subvolume", P::SubVolume},
                                               {"fence", P::Fence},
                                               {"inverted-fence", P::InvertedFence},
                                               {"cross", P::Cross},
                                               {"inverted-cross", P::InvertedCross}}));
    }
    return c;
}

VolumeSpec read_volume(const Json& v, const std::string& path, const Context& ctx, const fs::path& base_dir) {
    ObjectReader r(v, path, ctx);
    r.allow({"source", "origin", "spacing", "interpolation", "bounds", "classify", "transfer", "classification",
             "shading", "gradient", "transform", "clip_planes", "crop"});

    VolumeSpec spec;
    spec.source = read_source(r.required("source"), r.path("source"), ctx, base_dir);
    spec.origin = r.optional_vec3("origin");
    spec.spacing = r.optional_vec3("spacing", Range::positive());
    spec.interpolation = r.choice<Interpolation>("interpolation", Interpolation::Trilinear, names::kInterpolations);
    using C = VolumeSpec::Classify;
    spec.classify = r.choice<C>("classify", C::Post, names::kClassify);
    if (const Json* b = r.find("bounds")) spec.bounds = read_bounds(*b, r.path("bounds"), ctx, base_dir);
    const Json* transfer = r.find("transfer");
    const Json* classification = r.find("classification");
    if (transfer && classification)
        r.fail("classification", "give either \"transfer\" or \"classification\", not both");
    if (transfer) spec.transfer = read_transfer(*transfer, r.path("transfer"), ctx);
    if (classification) spec.classification = read_classification(*classification, r.path("classification"), ctx);
    if (const Json* s = r.find("shading")) spec.shading = read_shading(*s, r.path("shading"), ctx);
    if (const Json* g = r.find("gradient"))
        spec.gradient = read_gradient(*g, r.path("gradient"), ctx, spec.interpolation);
    if (const Json* t = r.find("transform")) spec.transform = read_transform(*t, r.path("transform"), ctx);
    if (const Json* c = r.find("clip_planes")) spec.clip_planes = read_clip_planes(*c, r.path("clip_planes"), ctx);
    if (const Json* c = r.find("crop")) spec.crop = read_crop(*c, r.path("crop"), ctx);
    return spec;
}

// "volume": {...} (the shorthand for a list of one), or "volumes": [{...}, ...] (at least one).
std::vector<VolumeSpec> read_volumes_key(ObjectReader& r, const fs::path& base_dir) {
    const Json* one = r.find("volume");
    const Json* many = r.find("volumes");
    if (one && many) r.fail("volumes", "give either \"volume\" or \"volumes\", not both");
    std::vector<VolumeSpec> volumes;
    if (many) {
        const std::size_t n = read_array_size(*many, r.path("volumes"), r.context());
        if (n == 0) r.fail("volumes", "expected at least one volume, got an empty array");
        for (std::size_t i = 0; i < n; ++i)
            volumes.push_back(read_volume(element(*many, i), index_path(r.path("volumes"), i), r.context(), base_dir));
        return volumes;
    }
    if (!one) r.fail("volume", "required");
    volumes.push_back(read_volume(*one, r.path("volume"), r.context(), base_dir));
    return volumes;
}

// ------------------------------------------------------------------------------------------------
// lights, camera, image, render
// ------------------------------------------------------------------------------------------------

// {"type": "headlight" | "directional", "direction": [3] (directional only), "color": [3] >= 0}.
LightSpec read_light(const Json& v, const std::string& path, const Context& ctx) {
    using T = LightSpec::Type;
    ObjectReader r(v, path, ctx);
    LightSpec l;
    l.type = r.choice<T>("type", T::Headlight, names::kLights);
    if (l.type == T::Headlight) {
        r.allow({"type", "color"}, "for a headlight");
    } else {
        r.allow({"type", "direction", "color"}, "for a directional light");
        l.direction = read_direction(r, "direction");
    }
    l.color = r.vec3("color", glm::dvec3(1.0), Range::non_negative());
    return l;
}

// An array of lights; [] means no lights.
std::vector<LightSpec> read_lights(const Json& v, const std::string& path, const Context& ctx) {
    const std::size_t n = read_array_size(v, path, ctx);
    std::vector<LightSpec> lights;
    for (std::size_t i = 0; i < n; ++i) lights.push_back(read_light(element(v, i), index_path(path, i), ctx));
    return lights;
}

// eye, target, up: eye != target; up non-zero and not parallel to target - eye.
void read_look_at(ObjectReader& r, CameraSpec& c) {
    c.eye = r.vec3("eye", glm::dvec3(0.0, 0.0, 1.0));
    c.target = r.vec3("target", glm::dvec3(0.0));
    c.up = r.vec3("up", glm::dvec3(0.0, 1.0, 0.0));
    const glm::dvec3 forward = c.target - c.eye;
    if (max_abs(forward) == 0.0) r.fail("eye", "the eye is at the target (they must differ)");
    if (!all_finite(forward)) r.fail("target", "target - eye overflows a double");
    if (max_abs(c.up) == 0.0) r.fail("up", "expected a non-zero up vector, got [0, 0, 0]");
    // |up x f| > 1e-12 |up| |f|, on vectors scaled to a largest component of 1 (no under-/overflow).
    const glm::dvec3 u = c.up / max_abs(c.up), f = forward / max_abs(forward);
    if (!(glm::length(glm::cross(u, f)) > 1e-12 * glm::length(u) * glm::length(f)))
        r.fail("up", "the up vector is parallel to the view direction (target - eye)");
}

// 16 numbers, column-major as OpenGL stores them (m[col][row] = a[4 col + row]); invertible.
glm::dmat4 read_matrix(ObjectReader& r, std::string_view key) {
    const std::vector<double> a = read_numbers(r.required(key), r.path(key), r.context(), 16);
    glm::dmat4 m(1.0);
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) m[col][row] = a[static_cast<std::size_t>(4 * col + row)];
    const double det = glm::determinant(m);
    if (!(std::fabs(det) > 1e-300))
        r.fail(key, "the matrix is not invertible (determinant " + format_number(det) + ")");
    const glm::dmat4 inverse = glm::inverse(m);
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row)
            if (!std::isfinite(inverse[col][row])) r.fail(key, "the matrix is not invertible (its inverse overflows)");
    return m;
}

CameraSpec read_camera(const Json& v, const std::string& path, const Context& ctx) {
    using T = CameraSpec::Type;
    ObjectReader r(v, path, ctx);
    CameraSpec c;
    c.type = r.required_choice<T>("type", names::kCameras);
    switch (c.type) {
        case T::Perspective:
            r.allow({"type", "eye", "target", "up", "fov_y", "near", "far"}, "for camera type \"perspective\"");
            read_look_at(r, c);
            c.fov_y = r.number("fov_y", 30.0, Range::open(0, 180));
            break;
        case T::Orthographic:
            r.allow({"type", "eye", "target", "up", "height", "near", "far"}, "for camera type \"orthographic\"");
            read_look_at(r, c);
            c.height = r.number("height", 1.0, Range::positive());
            break;
        case T::Matrices:
            r.allow({"type", "view", "projection"}, "for camera type \"matrices\"");
            c.view = read_matrix(r, "view");
            c.projection = read_matrix(r, "projection");
            break;
        case T::Default: break;  // not a value of "type"
    }
    // Clipping depths (placement "slices" reads them): eye-space depths, 0 < near < far.
    c.near = r.optional_number("near", Range::positive());
    c.far = r.optional_number("far", Range::positive());
    if (c.near.has_value() != c.far.has_value()) r.fail(c.near ? "near" : "far", "near and far are set together");
    if (c.near && !(*c.near < *c.far)) r.fail("far", "must exceed near");
    return c;
}

ImageSpec read_image(const Json& v, const std::string& path, const Context& ctx) {
    ObjectReader r(v, path, ctx);
    r.allow({"width", "height", "background"});
    ImageSpec im;
    const std::int64_t w = r.integer("width", 256, Range::closed(1, kMaxImageSide));
    const std::int64_t h = r.integer("height", 256, Range::closed(1, kMaxImageSide));
    if (w * h > kMaxImagePixels)
        r.fail(r.has("height") ? "height" : "width", std::to_string(w) + " x " + std::to_string(h) + " = " +
                                                        std::to_string(w * h) +
                                                        " pixels exceed the limit of 2^28 (268435456) pixels");
    im.width = static_cast<int>(w);
    im.height = static_cast<int>(h);
    if (const Json* b = r.find("background")) {
        const std::vector<double> c = read_numbers(*b, r.path("background"), ctx, 4, Range::closed(0, 1));
        im.background = glm::dvec4(c[0], c[1], c[2], c[3]);
    }
    return im;
}

template <class Reader>
ProfileId read_profile_id(Reader& r, std::string_view key) {
    return r.template choice<ProfileId>(key, ProfileId::Reference, names::kProfiles);
}

// render.profile as an object: each rule of the rule table by its key (ProfileRuleTable.h,
// scene-format.md "render.profile"), read in the table's order; the renderers that are not rule-driven
// (vtk-cpu, vtk-js, fast, volpack) take none.
ProfileRules read_profile_rules(ObjectReader& r, ProfileId base) {
    r.find("base");  // the keys the object may have, in the order the unknown-key message lists them
    for (const ProfileRule& rule : profile_rule_table()) r.find(rule.key);
    r.finish();
    ProfileRules out;
    for (const ProfileRule& rule : profile_rule_table())
        if (!rule.only_value && r.has(rule.key)) out.keys.emplace_back(rule.key);  // jitter "off": nothing to apply
    if (!out.keys.empty() && (base == ProfileId::VtkCpu || base == ProfileId::VtkJs || base == ProfileId::Fast || base == ProfileId::VolPack))
        r.fail(out.keys.front(), std::string("the \"") + std::string(names::name_of(names::kProfiles, base)) +
                                     "\" profile is its own renderer, not a set of rules (use render.profile_options, or base \"reference\")");
    for (const ProfileRule& rule : profile_rule_table()) rule.read(r, out);
    return out;
}

// render.profile_options of "volpack": VolPack's inputs, each range VolPack's own (its
// vpSet*, vpRamp and vpWindow error codes) or what its tables hold. A table is 256 numbers in [0, 1]
// or {"ramp": [[x, y], ...]} filled as vpRamp fills it (x strictly increasing integers from 0 to the
// field's maximum, so that every entry is set).
VolPackTable read_volpack_table(const Json& v, const std::string& path, const Context& ctx, int max_index) {
    VolPackTable t;
    t.entries.assign(256, 0.0f);
    if (v.is_object()) {
        ObjectReader r(v, path, ctx);
        r.allow({"ramp"});
        const Json& ramp = r.required("ramp");
        const std::string rp = r.path("ramp");
        const std::size_t n = read_array_size(ramp, rp, ctx);
        if (n < 2) ctx.fail(rp, "expected at least 2 points [x, y]");
        for (std::size_t i = 0; i < n; ++i) {
            const std::string ip = index_path(rp, i);
            const Json& point = element(ramp, i);
            read_numbers(point, ip, ctx, 2);  // [x, y]: two numbers
            const std::int64_t x = read_integer(element(point, 0), index_path(ip, 0), ctx, Range::closed(0, max_index));
            const double y = read_number(element(point, 1), index_path(ip, 1), ctx, Range::closed(0.0, 1.0));
            if (i == 0 && x != 0) ctx.fail(index_path(ip, 0), "the first point's x must be 0 (vpRamp sets only the entries between its points)");
            if (i > 0 && x <= t.ramp.back().first) ctx.fail(index_path(ip, 0), "x must increase strictly (vpRamp returns VPERROR_BAD_VALUE)");
            t.ramp.emplace_back(int(x), float(y));
        }
        if (t.ramp.back().first != max_index)
            ctx.fail(index_path(rp, n - 1), "the last point's x must be " + std::to_string(max_index) +
                                                " (vpRamp sets only the entries between its points)");
        // vpRamp (vp_util.c): the points' values, and between them y += dydx in double from the left point.
        t.entries[std::size_t(t.ramp[0].first)] = t.ramp[0].second;
        for (std::size_t i = 1; i < t.ramp.size(); ++i) {
            const int lastx = t.ramp[i - 1].first, nextx = t.ramp[i].first;
            const double lasty = t.ramp[i - 1].second, nexty = t.ramp[i].second;
            const double dydx = (nexty - lasty) / double(nextx - lastx);
            int x = lastx + 1;
            for (double y = lasty + dydx; x < nextx; ++x, y += dydx) t.entries[std::size_t(x)] = float(y);
            t.entries[std::size_t(x)] = float(nexty);
        }
        return t;
    }
    const std::vector<double> e = read_numbers(v, path, ctx, 256, Range::closed(0.0, 1.0));
    for (std::size_t i = 0; i < 256; ++i) t.entries[i] = float(e[i]);
    return t;
}

glm::dvec3 read_volpack_rgb(ObjectReader& r, std::string_view key, const glm::dvec3& fallback) {
    const Json* v = r.find(key);
    if (!v) return fallback;
    if (v->is_number()) return glm::dvec3(read_number(*v, r.path(key), r.context(), Range::non_negative()));
    return read_vec3(*v, r.path(key), r.context(), Range::non_negative());
}

VolPackSpec read_volpack_options(ObjectReader& po) {
    using V = VolPackSpec;
    const Context& ctx = po.context();
    po.allow({"rotate", "concat", "window", "scalar_table", "gradient_table", "shading", "min_voxel_opacity",
              "max_ray_opacity", "depth_cue", "channels", "path", "axis", "warp_weights", "normal_code",
              "correction_order"});
    V s;
    static constexpr Choice<V::Axis> kAxes[] = {{"x", V::Axis::X}, {"y", V::Axis::Y}, {"z", V::Axis::Z}};
    if (const Json* rot = po.find("rotate")) {
        const std::string rp = po.path("rotate");
        const std::size_t n = read_array_size(*rot, rp, ctx);
        for (std::size_t i = 0; i < n; ++i) {
            const Json& e = element(*rot, i);
            const std::string ip = index_path(rp, i);
            if (!e.is_array() || e.size() != 2)
                ctx.fail(ip, "expected [axis, degrees] (axis \"x\", \"y\" or \"z\"), got " + describe(e));
            const std::string a = read_string(e[0], index_path(ip, 0), ctx);
            const V::Axis* axis = nullptr;
            for (const auto& c : kAxes)
                if (c.name == a) axis = &c.value;
            if (!axis) ctx.fail(index_path(ip, 0), "expected \"x\", \"y\" or \"z\", got \"" + a + "\"");
            s.rotate.emplace_back(*axis, read_number(e[1], index_path(ip, 1), ctx));
        }
    }
    s.concat_left = po.choice<bool>("concat", false, {{"right", false}, {"left", true}});
    if (const Json* w = po.find("window")) {
        const std::string wp = po.path("window");
        const std::vector<double> v = read_numbers(*w, wp, ctx, 6);
        for (std::size_t i = 0; i < 6; ++i) s.window[i] = v[i];
        // vpWindow: VPERROR_BAD_VALUE unless left < right, bottom < top, near < far.
        if (!(v[0] < v[1])) ctx.fail(index_path(wp, 1), "right must exceed left (vpWindow)");
        if (!(v[2] < v[3])) ctx.fail(index_path(wp, 3), "top must exceed bottom (vpWindow)");
        if (!(v[4] < v[5])) ctx.fail(index_path(wp, 5), "far must exceed near (vpWindow)");
    }
    s.scalar_table = read_volpack_table(po.required("scalar_table"), po.path("scalar_table"), ctx, 255);
    if (const Json* g = po.find("gradient_table")) s.gradient_table = read_volpack_table(*g, po.path("gradient_table"), ctx, 221);
    if (const Json* sh = po.find("shading")) {
        s.shaded = true;
        ObjectReader sr(*sh, po.path("shading"), ctx);
        sr.allow({"material", "lights", "two_sided"});
        if (const Json* m = sr.find("material")) {
            ObjectReader mr(*m, sr.path("material"), ctx);
            mr.allow({"ambient", "diffuse", "specular", "shininess"});
            s.ambient = read_volpack_rgb(mr, "ambient", s.ambient);
            s.diffuse = read_volpack_rgb(mr, "diffuse", s.diffuse);
            s.specular = read_volpack_rgb(mr, "specular", s.specular);
            s.shininess = mr.number("shininess", s.shininess);
        }
        if (const Json* l = sr.find("lights")) {
            const std::string lp = sr.path("lights");
            const std::size_t n = read_array_size(*l, lp, ctx);
            if (n > 6) ctx.fail(lp, "VolPack has 6 lights (VP_LIGHT0 .. VP_LIGHT5), got " + std::to_string(n));
            std::vector<VolPackLight> lights;
            for (std::size_t i = 0; i < n; ++i) {
                ObjectReader lr(element(*l, i), index_path(lp, i), ctx);
                lr.allow({"direction", "color"});
                VolPackLight light;
                light.direction = read_vec3(lr.required("direction"), lr.path("direction"), ctx);
                if (glm::dot(light.direction, light.direction) < 1e-11)
                    lr.fail("direction", "a zero vector (vpSetLight returns VPERROR_SINGULAR)");
                light.color = lr.vec3("color", glm::dvec3(1.0), Range::closed(0.0, 1.0));
                lights.push_back(light);
            }
            s.lights = std::move(lights);
        }
        s.two_sided = sr.boolean("two_sided", false);
    }
    // vpSetd: VP_MIN_VOXEL_OPACITY in [0, 1] or exactly -1 (every voxel kept), else VPERROR_BAD_VALUE.
    s.min_voxel_opacity = po.number("min_voxel_opacity", 0.0, Range::closed(-1.0, 1.0));
    if (s.min_voxel_opacity < 0.0 && s.min_voxel_opacity != -1.0)
        po.fail("min_voxel_opacity", "expected a number in [0, 1] or -1 (vpSetd returns VPERROR_BAD_VALUE), got " +
                                         format_number(s.min_voxel_opacity));
    s.max_ray_opacity = po.number("max_ray_opacity", 1.0, Range::left_open(0.0, 1.0));
    if (const Json* d = po.find("depth_cue")) {
        ObjectReader dr(*d, po.path("depth_cue"), ctx);
        dr.allow({"front", "density"});
        // vpSetDepthCueing: VPERROR_BAD_VALUE for front_factor <= 0.
        s.depth_cue = std::array<double, 2>{dr.number("front", 1.0, Range::positive()), dr.number("density", 1.0)};
    }
    s.channels = int(po.integer("channels", 1, Range::closed(1, 3)));
    if (s.channels == 2) po.fail("channels", "expected 1 (luminance) or 3 (RGB), got 2");
    s.path = po.choice<V::Path>("path", V::Path::Classified, {{"classified", V::Path::Classified}, {"raw", V::Path::Raw}});
    if (po.has("axis"))
        s.axis = po.choice<V::Axis>("axis", V::Axis::Z, std::span<const Choice<V::Axis>>(kAxes));
    s.warp_weights = po.choice<V::WarpWeights>("warp_weights", V::WarpWeights::Table,
                                               {{"table", V::WarpWeights::Table}, {"exact", V::WarpWeights::Exact}});
    s.normal_code = po.choice<V::NormalCode>("normal_code", V::NormalCode::Quantised,
                                             {{"quantised", V::NormalCode::Quantised}, {"exact", V::NormalCode::Exact}});
    s.correction_order = po.choice<V::CorrectionOrder>("correction_order", V::CorrectionOrder::Voxel,
                                                       {{"voxel", V::CorrectionOrder::Voxel}, {"sample", V::CorrectionOrder::Sample}});
    return s;
}

RenderSpec read_render(const Json& v, const std::string& path, const Context& ctx) {
    ObjectReader r(v, path, ctx);
    r.allow({"projection", "order", "step", "step_units", "isovalue", "early_termination", "integrator", "tolerance",
             "profile", "profile_options", "gain"});
    RenderSpec s;
    s.projection = r.choice<Projection>("projection", s.projection, names::kProjections);  // the default: RenderSpec's
    s.order = r.choice<CompositeOrder>("order", CompositeOrder::FrontToBack, names::kOrders);
    s.step = r.number("step", 0.5, Range::positive());
    s.step_units = r.choice<StepUnits>("step_units", StepUnits::Voxel, names::kStepUnits);
    s.isovalue = r.optional_number("isovalue");
    s.early_termination = r.optional_number("early_termination", Range::left_open(0, 1));
    s.integrator = r.choice<IntegrationMethod>("integrator", IntegrationMethod::Fixed, names::kIntegrators);
    s.tolerance = r.number("tolerance", conventions::kAdaptiveDefaultTolerance, Range::positive());
    // render.profile: a preset's name, or an object of rules over a preset (read_profile_rules).
    if (const Json* p = r.find("profile"); p && p->is_object()) {
        ObjectReader pr(*p, r.path("profile"), ctx);
        s.profile = read_profile_id(pr, "base");
        s.profile_rules = read_profile_rules(pr, s.profile);
    } else {
        s.profile = read_profile_id(r, "profile");
    }
    if (s.profile == ProfileId::VolPack) {  // VolPack's inputs; volref's own render keys do not apply
        const Json* o = r.find("profile_options");
        if (!o) r.fail("profile_options", "required by render.profile \"volpack\" (VolPack's inputs: scalar_table at least)");
        ObjectReader po(*o, r.path("profile_options"), ctx);
        s.profile_options.volpack = read_volpack_options(po);
        for (std::string_view k : {"projection", "order", "step", "step_units", "isovalue", "early_termination", "integrator", "tolerance", "gain"})
            if (r.has(k))
                r.fail(k, "not used by render.profile \"volpack\" (VolPack composites front to back on its voxel slices; "
                          "its thresholds are render.profile_options.min_voxel_opacity and max_ray_opacity)");
    } else if (const Json* o = r.find("profile_options"); o && s.profile == ProfileId::VtkJs) {
        ObjectReader po(*o, r.path("profile_options"), ctx);
        po.allow({"jitter", "fixed_normal", "flip_normal", "ray_box", "mip_correction", "subpixel_bits"});
        s.profile_options.jitter = po.number("jitter", 1.0, Range::closed(0.01, 1.0));
        s.profile_options.fixed_normal = po.boolean("fixed_normal", false);
        s.profile_options.flip_normal = po.boolean("flip_normal", false);
        s.profile_options.ray_box_domain = po.choice<bool>("ray_box", false, names::kVtkJsRayBoxes);
        s.profile_options.mip_correction = po.boolean("mip_correction", true);
        s.profile_options.subpixel_bits = int(po.integer("subpixel_bits", 4, Range::closed(0, 23)));
    } else if (const Json* o = r.find("profile_options"); o && s.profile == ProfileId::Fast) {
        ObjectReader po(*o, r.path("profile_options"), ctx);
        po.allow({"preintegration"});
        s.profile_options.preintegration =
            int(po.integer("preintegration", 0, Range::closed(2, conventions::kPreIntegrationMaxIntervals)));
    } else if (const Json* o = r.find("profile_options");
               o && (s.profile == ProfileId::Volumizer || s.profile_rules.placement == ProfileRules::Placement::Slices)) {
        ObjectReader po(*o, r.path("profile_options"), ctx);
        po.allow({"framebuffer_band"});
        s.profile_options.framebuffer_band = po.boolean("framebuffer_band", false);
    } else if (const Json* o = r.find("profile_options")) {
        if (s.profile != ProfileId::CudaCurvilinear && s.profile != ProfileId::GlslBasic && s.profile != ProfileId::VtkGpu)
            r.fail("profile_options", "only the cuda-curvilinear, glsl-basic, vtk-gpu, vtk-js, fast and volumizer profiles (and placement \"slices\") have options");
        ObjectReader po(*o, r.path("profile_options"), ctx);
        if (s.profile == ProfileId::GlslBasic) po.allow({"intensity", "texture_unit", "texture_band"});
        else if (s.profile == ProfileId::VtkGpu) po.allow({"texture_unit", "texture_band"});
        else po.allow({"density", "transfer_scale", "iso_threshold", "brightness", "texture_unit", "texture_band", "texture_format", "kernel", "tricubic"});
        // the texture unit's weights (TextureUnit.h) and the band in the "error" channel
        using TU = ProfileOptions::TextureUnit;
        s.profile_options.texture_unit = po.choice<TU>("texture_unit", TU::Exact, names::kTextureUnits);
        if (po.has("texture_unit") && po.string("texture_unit", "") == "hardware")
            std::cerr << "volref: notice: render.profile_options.texture_unit: \"hardware\" is a deprecated alias of \"h100\"\n";
        s.profile_options.texture_band = po.boolean("texture_band", false);
        s.profile_options.data_unorm16 = po.choice<bool>("texture_format", false, names::kTextureFormats);
        using K = ProfileOptions::Kernel;  // seed 001's kernel in float32, or the double profile
        s.profile_options.kernel = po.choice<K>("kernel", K::Float32, names::kKernels);
        s.profile_options.tricubic = po.boolean("tricubic", false);  // seed 001's --tricubic
        s.profile_options.intensity = po.number("intensity", 1.0, Range::non_negative());
        s.profile_options.density = po.number("density", 1.0, Range::non_negative());
        s.profile_options.transfer_scale = po.number("transfer_scale", 1.0, Range::non_negative());
        s.profile_options.iso_threshold = po.number("iso_threshold", 0.0);
        s.profile_options.brightness = po.number("brightness", 1.0, Range::non_negative());
    }
    // The rules that are render.profile_options too (texture_unit, arithmetic): set in one place only.
    const Json* po_json = r.find("profile_options");
    for (const ProfileRule& rule : profile_rule_table()) {
        if (rule.option.empty() || !rule.is_set(s.profile_rules)) continue;
        if (po_json && po_json->contains(std::string(rule.option)))
            r.fail("profile." + std::string(rule.key),
                   "also set by render.profile_options." + std::string(rule.option) + " (set it in one place)");
        rule.to_options(s.profile_rules, s.profile_options);
    }
    s.gain = r.number("gain", 1.0, Range::positive());
    if (is_first_hit(s.projection) && !s.isovalue) r.fail("isovalue", "required by projection first-hit");
    return s;
}

// ------------------------------------------------------------------------------------------------
// The scene
// ------------------------------------------------------------------------------------------------

Scene read_scene(const Json& root, const Context& ctx, const fs::path& base_dir) {
    ObjectReader r(root, "", ctx);
    r.allow({"description", "volume", "volumes", "lights", "camera", "image", "render"});
    r.optional_string("description");  // a note for humans; ignored
    Scene scene;
    scene.volumes = read_volumes_key(r, base_dir);
    if (const Json* v = r.find("lights")) scene.lights = read_lights(*v, r.path("lights"), ctx);
    if (const Json* v = r.find("camera")) scene.camera = read_camera(*v, r.path("camera"), ctx);
    if (const Json* v = r.find("image")) scene.image = read_image(*v, r.path("image"), ctx);
    if (const Json* v = r.find("render")) scene.render = read_render(*v, r.path("render"), ctx);
    if (scene.render.profile == ProfileId::VolPack) {  // the scene names VolPack's inputs only
        const char* why = "not used by render.profile \"volpack\" (VolPack's inputs are render.profile_options)";
        if (scene.volumes.size() != 1) r.fail("volumes", "render.profile \"volpack\" renders one volume");
        const Json* one = r.find("volume");
        const Json& vol = one ? *one : element(*r.find("volumes"), 0);
        for (const char* k : {"transfer", "classification", "shading", "gradient", "transform", "clip_planes", "crop",
                              "bounds", "classify", "interpolation", "origin", "spacing"})
            if (vol.contains(k)) ctx.fail(std::string(one ? "volume." : "volumes[0].") + k, why);
        if (r.find("camera")) ctx.fail("camera", std::string(why) + ": the view is rotate and window");
        if (r.find("lights")) ctx.fail("lights", std::string(why) + ": the lights are shading.lights");
        if (scene.image.background != glm::dvec4(0.0))
            ctx.fail("image.background", "VolPack has no background (its pixels are premultiplied over nothing): remove it");
    }
    return scene;
}

std::string read_text(const fs::path& path, const Context& ctx) {
    std::error_code ec;
    if (!fs::exists(path, ec)) ctx.fail_plain("cannot read the scene file: no such file");
    if (const std::string problem = io::input_file_problem(path); !problem.empty())
        ctx.fail_plain("cannot read the scene file: " + problem);  // a FIFO or a device: refused by type
    try {
        return io::read_file_bytes(path, "the scene file");
    } catch (const Error& e) {
        ctx.fail_plain(e.what());
    }
}

fs::path absolute_dir(const fs::path& dir) { return dir.empty() ? fs::current_path() : fs::absolute(dir); }

}  // namespace

BoundsSpec parse_shell(const std::string& json_text, const std::string& name) {
    using T = BoundsSpec::Type;
    const Context ctx(name);
    const Json json = json_reader::parse_json(json_text, name);
    ObjectReader r(json, "", ctx);
    BoundsSpec b;
    b.type = r.required_choice<T>("type", std::span<const json_reader::Choice<T>>(names::kBounds).subspan(2, 2));  // the shells
    read_shell(r, b);
    return b;
}

ProfileRules parse_profile_rules(const nlohmann::json& object, ProfileId base, const std::string& name) {
    const Context ctx(name);
    if (!object.is_object()) ctx.fail("render.profile", "expected an object, got " + describe(object));
    ObjectReader r(object, "render.profile", ctx);
    return read_profile_rules(r, base);
}

Scene parse_scene(const std::string& json_text, const std::filesystem::path& base_dir, const std::string& name,
                  const std::vector<std::string>& overrides) {
    Context ctx(name);
    Json root = json_reader::parse_json(json_text, name);
    if (!root.is_object()) ctx.fail("", "expected an object, got " + describe(root));
    for (const std::string& o : overrides) apply_override(root, o, ctx);
    Scene scene = read_scene(root, ctx, absolute_dir(base_dir));
    scene.file = name;
    return scene;
}

Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
    const std::string name = path.string();
    const std::string text = read_text(path, Context(name));
    Scene scene = parse_scene(text, fs::absolute(path).parent_path(), name, overrides);
    scene.file = path;
    return scene;
}

}  // namespace volref
