#include "core/explain/PixelTrace.h"

#include "core/integrate/profiles/Profile.h"

#include <algorithm>
#include <charconv>
#include <functional>
#include <cmath>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/scene/JsonReader.h"
#include "core/explain/NumberFormat.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneNames.h"

namespace volref::explain {

namespace {

GridLocation locate(const PreparedScene& scene, const glm::dvec3& world) {
    GridLocation g;
    const PreparedVolume& volume = scene.volume();
    const glm::dvec3 position = volume.transform ? volume.transform->to_local(world) : world;
    if (volume.model.cartesian) {
        const VolumeSampler& s = *volume.model.cartesian;
        g.index = s.continuous_index(position);
        s.locate(g.index, g.cell, g.local);
    } else if (volume.model.shell_grid) {
        const ShellGrid& grid = *volume.model.shell_grid;
        g.index = grid.continuous_index(position);
        // The cell and fraction of ShellSampler's trilinear reconstruction (docs/shells.md section 3):
        // non-periodic axes clamp u to [0, n - 1] and take i = min(floor(u), n - 2) (0 when n = 1);
        // periodic axes take i = floor(u) in [0, n - 1] (the cell [n - 1, n) wraps to sample 0).
        for (int a = 0; a < 3; ++a) {
            const std::int64_t n = grid.dims()[std::size_t(a)];
            double u = std::isfinite(g.index[a]) ? g.index[a] : 0.0;
            std::int64_t i = 0;
            if (grid.axis(a).periodic) {
                i = std::clamp<std::int64_t>(std::int64_t(std::floor(u)), 0, n - 1);
            } else if (n > 1) {
                u = std::clamp(u, 0.0, double(n - 1));
                i = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 2);
            }
            g.cell[std::size_t(a)] = i;
            g.local[a] = n == 1 && !grid.axis(a).periodic ? 0.0 : u - double(i);
        }
    }
    return g;
}

struct Collector final : SampleRecorder {
    const PreparedScene& scene;
    std::vector<TracedSample>& out;
    Collector(const PreparedScene& s, std::vector<TracedSample>& o) : scene(s), out(o) {}
    void record(const SampleRecord& r) override { out.push_back({r, locate(scene, r.sample.position)}); }
};

bool composite(const PixelTrace& t) { return is_composite(t.projection); }
bool line_integral(const PixelTrace& t) { return is_line_integral(t.projection); }

}  // namespace

const char* projection_name(Projection p) { return scene_names::name_of(scene_names::kProjections, p); }

std::array<int, 2> parse_pixel(const std::string& text, int width, int height) {
    std::array<long long, 2> v{};
    std::size_t pos = 0;
    for (int i = 0; i < 2; ++i) {
        const char* b = text.data() + pos;
        const char* e = text.data() + text.size();
        const auto r = std::from_chars(b, e, v[std::size_t(i)]);
        if (r.ec != std::errc() || (i == 0 && (r.ptr == e || *r.ptr != ',')) || (i == 1 && r.ptr != e))
            throw Error("--pixel: expected X,Y (two integers), got \"" + text + "\"");
        pos = std::size_t(r.ptr - text.data()) + 1;
    }
    if (v[0] < 0 || v[0] >= width || v[1] < 0 || v[1] >= height)
        throw Error("--pixel: (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ") is outside the " +
                    std::to_string(width) + " x " + std::to_string(height) + " image");
    return {int(v[0]), int(v[1])};
}

PixelTrace trace_pixel(const PreparedScene& scene, int x, int y) {
    const RenderSpec& r = scene.scene.render;
    if (is_first_hit(r.projection)) throw Error("trace: first-hit is not supported yet");
    if (r.integrator == IntegrationMethod::Adaptive)
        throw Error("trace: render.integrator \"adaptive\" is not supported yet (trace the fixed-step integrator)");
    if (x < 0 || x >= scene.scene.image.width || y < 0 || y >= scene.scene.image.height)
        throw Error("--pixel: (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                    std::to_string(scene.scene.image.width) + " x " + std::to_string(scene.scene.image.height) + " image");
    const PreparedVolume& v = scene.traced_volume();
    PixelTrace t;
    t.x = x;
    t.y = y;
    t.ray = scene.pixel_ray(x, y);
    t.projection = r.projection;
    t.order = r.order;
    if (!v.classifier) {
        // volpack: VolPack's own renderer has no ray of volref's: the rows are the warp's taps
        // (each an intermediate pixel, `alpha` its weight) and then the pixel (explain volpack-warp).
        Collector collector(scene, t.samples);
        t.pixel = scene.trace_pixel(x, y, collector);
        return t;
    }
    t.intervals = scene.intervals(t.ray);
    t.step = v.step;
    {  // every sample is kept (and printed): counted against the memory limit before the march
        double samples = 0.0;
        for (const Interval& i : t.intervals) samples += double(segment_count(i, t.step)) + 1.0;  // + the exit (profiles)
        const double bytes = samples * double(sizeof(TracedSample) + conventions::kTraceBytesPerSampleOutput);
        check_memory(bytes >= 0x1p62 ? std::size_t(1) << 62 : std::size_t(bytes),
                     "trace: " + std::to_string(std::llround(std::min(samples, 0x1p62))) + " samples of pixel (" +
                         std::to_string(x) + ", " + std::to_string(y) + ") at render.step " + json_reader::format_number(t.step));
    }
    t.unit_distance = v.classifier->unit_distance();
    t.has_gradient = v.gradient != nullptr;
    t.shaded = v.shader != nullptr && is_composite(t.projection);
    t.lights = t.shaded ? v.shader->lights().size() : 0;
    t.skipping = v.macrocells != nullptr && is_composite(t.projection);  // the traced mip / minip loop does not skip
    t.slices = !r.reference_integrators() && r.profile != ProfileId::Fast &&
               resolve_profile(r).placement == Profile::Placement::Slices;
    Collector collector(scene, t.samples);
    t.pixel = scene.trace_pixel(x, y, collector);
    for (TracedSample& s : t.samples) {  // the rows' interval and step from its entry
        for (std::size_t i = 0; i < t.intervals.size(); ++i)
            if (t.intervals[i].t0 <= s.record.t) s.interval = std::int64_t(i);
        if (s.interval >= 0 && t.step > 0.0)
            s.segment = std::int64_t(std::floor((s.record.t - t.intervals[std::size_t(s.interval)].t0) / t.step + conventions::kSegmentSlack));  // the segments' own slack
    }
    if (t.pixel.fault) t.fault = v.integrator->fault_reason(v.volume_ray(t.ray));
    return t;
}

// ---- CSV -------------------------------------------------------------------------------------

namespace {

// One column: its name and how a sample fills it ("" = not computed for this sample).
struct Column {
    std::string name;
    std::function<std::string(const TracedSample&)> cell;
};

std::vector<Column> columns(const PixelTrace& t) {
    std::vector<Column> c;
    auto num = [](double v) { return number(v); };
    auto add = [&](std::string name, std::function<std::string(const TracedSample&)> f) {
        c.push_back({std::move(name), std::move(f)});
    };
    add("sample", [](const TracedSample& s) { return std::to_string(s.record.index); });
    add("interval", [](const TracedSample& s) { return std::to_string(s.interval); });
    add("segment", [](const TracedSample& s) { return std::to_string(s.segment); });
    add("t0", [=](const TracedSample& s) { return num(s.record.t0); });
    add("t1", [=](const TracedSample& s) { return num(s.record.t1); });
    add("t", [=](const TracedSample& s) { return num(s.record.t); });
    add("length", [=](const TracedSample& s) { return num(s.record.length); });
    const char* xyz = "xyz";
    for (int a = 0; a < 3; ++a)
        add(std::string(1, xyz[a]), [=](const TracedSample& s) { return num(s.record.sample.position[a]); });
    for (int a = 0; a < 3; ++a)
        add("u" + std::to_string(a), [=](const TracedSample& s) { return num(s.grid.index[a]); });
    for (int a = 0; a < 3; ++a)
        add(std::string("cell_") + "ijk"[a], [=](const TracedSample& s) { return std::to_string(s.grid.cell[std::size_t(a)]); });
    for (int a = 0; a < 3; ++a)
        add(std::string("local_") + "pqr"[a], [=](const TracedSample& s) { return num(s.grid.local[a]); });
    add("value", [=](const TracedSample& s) { return num(s.record.sample.value); });
    if (t.has_gradient) {
        for (int a = 0; a < 3; ++a)
            add(std::string("grad_") + xyz[a], [=](const TracedSample& s) {
                return s.record.sample.has_gradient ? num(s.record.sample.gradient[a]) : std::string();
            });
    }
    if (line_integral(t)) {
        add("coordinate", [=](const TracedSample& s) { return num(s.record.coordinate); });
    } else {
        const char* rgb = "rgb";
        for (int a = 0; a < 3; ++a)
            add(std::string("class_") + rgb[a], [=](const TracedSample& s) { return num(s.record.sample.classified_color[a]); });
        add("opacity", [=](const TracedSample& s) { return num(s.record.sample.opacity); });
    }
    if (t.shaded) {
        auto shaded = [](const TracedSample& s) { return s.record.sample.shaded; };
        for (int a = 0; a < 3; ++a)
            add(std::string("normal_") + xyz[a], [=](const TracedSample& s) {
                return shaded(s) ? num(s.record.sample.shading.normal[a]) : std::string();
            });
        for (std::size_t l = 0; l < t.lights; ++l) {
            const std::string p = "light" + std::to_string(l) + "_";
            auto term = [=](const TracedSample& s, auto&& f) {
                if (!shaded(s) || s.record.sample.shading.lights.size() <= l) return std::string();
                return num(f(s.record.sample.shading.lights[l]));
            };
            add(p + "n_dot_l", [=](const TracedSample& s) { return term(s, [](const LightTerms& x) { return x.n_dot_l; }); });
            add(p + "specular_dot",
                [=](const TracedSample& s) { return term(s, [](const LightTerms& x) { return x.specular_dot; }); });
            add(p + "depth_cue", [=](const TracedSample& s) { return term(s, [](const LightTerms& x) { return x.depth_cue; }); });
            for (const char* part : {"ambient", "diffuse", "specular"})
                for (int a = 0; a < 3; ++a)
                    add(p + part + "_" + "rgb"[a], [=](const TracedSample& s) {
                        return term(s, [&](const LightTerms& x) {
                            const std::string q = part;
                            return (q == "ambient" ? x.ambient : q == "diffuse" ? x.diffuse : x.specular)[a];
                        });
                    });
        }
        for (int a = 0; a < 3; ++a)
            add(std::string("shaded_") + "rgb"[a], [=](const TracedSample& s) { return num(s.record.sample.color[a]); });
    }
    if (composite(t)) {
        add("tau", [=](const TracedSample& s) { return num(s.record.tau); });
        add("alpha", [=](const TracedSample& s) { return num(s.record.alpha); });
        add("transmittance_before", [=](const TracedSample& s) { return num(s.record.transmittance_before); });
        add("transmittance_after", [=](const TracedSample& s) { return num(s.record.transmittance_after); });
    } else {
        add("running", [=](const TracedSample& s) { return num(s.record.running); });
    }
    if (t.slices) {  // the surface each fragment lies on, and its blend before the frame buffer stored it
        add("surface", [](const TracedSample& s) { return std::to_string(s.record.surface); });
        for (int a = 0; a < 4; ++a)
            add(std::string("blend_") + "rgba"[a], [=](const TracedSample& s) { return num(s.record.blend_exact[a]); });
    }
    for (int a = 0; a < 4; ++a)
        add(std::string("acc_") + "rgba"[a], [=](const TracedSample& s) { return num(s.record.accumulated[a]); });
    return c;
}

nlohmann::json jnum(double v) {
    if (std::isfinite(v)) return v;
    return number(v);
}
nlohmann::json jvec(const glm::dvec3& v) { return {jnum(v.x), jnum(v.y), jnum(v.z)}; }
nlohmann::json jvec(const glm::dvec4& v) { return {jnum(v.x), jnum(v.y), jnum(v.z), jnum(v.w)}; }

}  // namespace

std::vector<std::string> trace_csv_header(const PixelTrace& trace) {
    std::vector<std::string> names;
    for (const Column& c : columns(trace)) names.push_back(c.name);
    return names;
}

void write_trace_csv(const PixelTrace& trace, std::ostream& out) {
    const std::vector<Column> cols = columns(trace);
    for (std::size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << cols[i].name;
    out << '\n';
    for (const TracedSample& s : trace.samples) {
        for (std::size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << cols[i].cell(s);
        out << '\n';
    }
}

std::string trace_json(const PixelTrace& t, int indent) {
    nlohmann::json j;
    j["pixel"] = {t.x, t.y};
    j["projection"] = projection_name(t.projection);
    if (composite(t)) j["order"] = scene_names::name_of(scene_names::kOrders, t.order);
    j["ray"] = {{"origin", jvec(t.ray.origin)}, {"direction", jvec(t.ray.direction)}};
    nlohmann::json iv = nlohmann::json::array();
    for (const Interval& i : t.intervals) iv.push_back({jnum(i.t0), jnum(i.t1)});
    j["intervals"] = iv;
    j["step"] = jnum(t.step);
    j["unit_distance"] = jnum(t.unit_distance);
    j["empty_space_skipping"] = t.skipping;
    nlohmann::json samples = nlohmann::json::array();
    for (const TracedSample& s : t.samples) {
        const SampleRecord& r = s.record;
        const SampleDetail& d = r.sample;
        nlohmann::json o;
        o["sample"] = r.index;
        o["interval"] = s.interval;
        o["segment"] = s.segment;
        o["t0"] = jnum(r.t0);
        o["t1"] = jnum(r.t1);
        o["t"] = jnum(r.t);
        o["length"] = jnum(r.length);
        o["position"] = jvec(d.position);
        o["grid"] = {{"index", jvec(s.grid.index)},
                     {"cell", {s.grid.cell[0], s.grid.cell[1], s.grid.cell[2]}},
                     {"local", jvec(s.grid.local)}};
        o["value"] = jnum(d.value);
        if (d.has_gradient) o["gradient"] = jvec(d.gradient);
        if (line_integral(t)) {
            o["coordinate"] = jnum(r.coordinate);
        } else {
            o["classified"] = {{"color", jvec(d.classified_color)}, {"opacity", jnum(d.opacity)}};
        }
        if (t.shaded && d.shaded) {
            nlohmann::json lights = nlohmann::json::array();
            for (const LightTerms& l : d.shading.lights)
                lights.push_back({{"L", jvec(l.L)},
                                  {"H", jvec(l.H)},
                                  {"n_dot_l", jnum(l.n_dot_l)},
                                  {"specular_dot", jnum(l.specular_dot)},
                                  {"depth_cue", jnum(l.depth_cue)},
                                  {"ambient", jvec(l.ambient)},
                                  {"diffuse", jvec(l.diffuse)},
                                  {"specular", jvec(l.specular)}});
            o["shading"] = {{"gradient_magnitude", jnum(d.shading.gradient_magnitude)},
                            {"zero_gradient", d.shading.zero_gradient},
                            {"normal", jvec(d.shading.normal)},
                            {"lights", lights},
                            {"color", jvec(d.color)}};
        }
        if (composite(t)) {
            o["tau"] = jnum(r.tau);
            o["alpha"] = jnum(r.alpha);
            o["transmittance_before"] = jnum(r.transmittance_before);
            o["transmittance_after"] = jnum(r.transmittance_after);
        } else {
            o["running"] = jnum(r.running);
        }
        if (t.slices) {
            o["surface"] = r.surface;
            o["blend"] = jvec(r.blend_exact);
        }
        o["accumulated"] = jvec(r.accumulated);
        samples.push_back(std::move(o));
    }
    j["samples"] = std::move(samples);
    j["pixel_value"] = jvec(t.pixel.rgba);
    if (t.pixel.fault) j["fault"] = t.fault;
    return j.dump(indent);
}

}  // namespace volref::explain
