// Parsing `volref explain TOPIC OPTIONS` (docs/explain.md): options are "--name VALUE ...", a name
// followed by the tokens up to the next "--name" (negative numbers are values: they start with a
// single '-'); lists of numbers are comma-separated without spaces. Every bad value is a one-line
// volref::Error naming its option.
#include "core/explain/ExplainArguments.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <map>
#include <set>

#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/InputFile.h"
#include "core/explain/Explain.h"
#include "core/explain/PixelTrace.h"
#include "core/grid/Volume.h"
#include "core/io/VolumeReader.h"
#include "core/render/PreparedScene.h"
#include "core/scene/ProfileRuleTable.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneNames.h"

namespace volref::explain {

const char* topics() {
    return "trilinear, composite, opacity-correction, classify-isovalue, classify-boundary, shade, coords, intersect, ray, "
           "texture-fetch, volpack-warp, volpack-voxel, volpack-scene";
}

namespace {

class Options {
public:
    Options(const std::string& topic, const std::vector<std::string>& tokens, const std::set<std::string>& allowed)
        : topic_(topic) {
        std::string current;
        for (const std::string& t : tokens) {
            if (t.rfind("--", 0) == 0 && t.size() > 2) {
                current = t;
                if (!allowed.count(current)) {
                    std::string list;
                    for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
                    throw Error(current + ": not an option of explain " + topic + " (allowed: " + list + ")");
                }
                if (values_.count(current) && current != "--set" && current != "--samples" &&
                    current != "--contour" && current != "--region" && current != "--light")
                    throw Error(current + ": given twice");
                values_[current];
                continue;
            }
            if (current.empty()) throw Error("explain " + topic + ": unexpected argument \"" + t + "\" (expected an option --NAME)");
            values_[current].push_back(t);
        }
    }
    bool has(const std::string& name) const { return values_.count(name) != 0; }
    // The one value of `name` (required unless a default is given).
    std::string one(const std::string& name) const {
        auto it = values_.find(name);
        if (it == values_.end()) throw Error(name + ": required by explain " + topic_);
        if (it->second.size() != 1)
            throw Error(name + ": expected one value, got " + std::to_string(it->second.size()));
        return it->second[0];
    }
    const std::vector<std::string>& all(const std::string& name) const {
        static const std::vector<std::string> none;
        auto it = values_.find(name);
        return it == values_.end() ? none : it->second;
    }
    void flag(const std::string& name) const {
        if (has(name) && !all(name).empty()) throw Error(name + ": takes no value");
    }

private:
    std::string topic_;
    std::map<std::string, std::vector<std::string>> values_;
};

double parse_number(const std::string& option, const std::string& text) {
    double v = 0.0;
    const char* b = text.data();
    const char* e = b + text.size();
    if (!text.empty() && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    if (r.ec != std::errc() || r.ptr != e || !std::isfinite(v))
        throw Error(option + ": expected a finite number, got \"" + text + "\"");
    return v;
}

// "a,b,c" -> numbers; `count` > 0: exactly that many; `min`..`max` otherwise.
std::vector<double> parse_list(const std::string& option, const std::string& text, std::size_t min, std::size_t max,
                               const std::string& what) {
    std::vector<double> out;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        double v = 0.0;
        const char* b = item.data();
        const char* e = b + item.size();
        if (!item.empty() && *b == '+') ++b;
        const auto r = std::from_chars(b, e, v);
        if (item.empty() || r.ec != std::errc() || r.ptr != e || !std::isfinite(v))
            throw Error(option + ": expected " + what + " (finite numbers separated by commas), got \"" + text + "\"");
        out.push_back(v);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (out.size() < min || out.size() > max)
        throw Error(option + ": expected " + what + ", got " + std::to_string(out.size()) + " numbers in \"" + text + "\"");
    return out;
}

glm::dvec3 vec3(const std::string& option, const std::string& text) {
    const auto v = parse_list(option, text, 3, 3, "3 numbers X,Y,Z");
    return {v[0], v[1], v[2]};
}

glm::dvec3 vec3_or(const Options& o, const std::string& name, glm::dvec3 fallback) {
    return o.has(name) ? vec3(name, o.one(name)) : fallback;
}

double number_or(const Options& o, const std::string& name, double fallback) {
    return o.has(name) ? parse_number(name, o.one(name)) : fallback;
}

std::array<double, 2> pair(const Options& o, const std::string& name, std::array<double, 2> fallback) {
    if (!o.has(name)) return fallback;
    const auto v = parse_list(name, o.one(name), 2, 2, "2 numbers LO,HI");
    return {v[0], v[1]};
}

glm::dvec3 unit(const std::string& option, const glm::dvec3& v) {
    const double n = glm::length(v);
    if (!(n > 0.0) || !std::isfinite(n)) throw Error(option + ": must be a non-zero finite vector");
    return v / n;
}

Scene scene_of(const Options& o) {
    return load_scene(o.one("--scene"), o.all("--set"));
}

}  // namespace

// --points FILE: a header line, then "x,y,z" per line (blank lines skipped).
std::vector<glm::dvec3> read_points(const std::string& file) {
    io::check_whole_file(file, "--points: " + file);
    std::ifstream in(file);
    if (!in) throw Error("--points: " + file + ": cannot be read");
    std::vector<glm::dvec3> out;
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
        ++n;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (n == 1 || line.find_first_not_of(" \t") == std::string::npos) continue;
        const std::string where = "--points: " + file + " line " + std::to_string(n);
        std::vector<double> v;
        try {
            v = parse_list(where, line, 3, 3, "3 numbers x,y,z");
        } catch (const Error&) {
            throw Error(where + ": expected x,y,z (3 finite numbers), got \"" + line.substr(0, 80) + "\"");
        }
        out.emplace_back(v[0], v[1], v[2]);
    }
    if (out.empty()) throw Error("--points: " + file + ": no points (a header line, then x,y,z per line)");
    return out;
}

Explanation from_arguments(const std::string& t, const std::vector<std::string>& args) {
    if (t == "trilinear") {
        const Options o(t, args, {"--corners", "--point", "--scene", "--at", "--set"});
        if (o.has("--scene")) {
            if (o.has("--corners") || o.has("--point")) throw Error("--scene: give either --scene and --at or --corners and --point");
            const glm::dvec3 at = vec3("--at", o.one("--at"));
            const Scene scene = scene_of(o);
            VolumeModel model;
            build_volume_model(scene.volume(), model);
            if (!model.cartesian) throw Error("--scene: explain trilinear --at needs a Cartesian grid (box or mesh bounds)");
            return trilinear_at(*model.cartesian, at);
        }
        const auto f = parse_list("--corners", o.one("--corners"), 8, 8, "8 numbers f1,...,f8");
        std::array<double, 8> c{};
        std::copy(f.begin(), f.end(), c.begin());
        return trilinear(c, vec3("--point", o.one("--point")));
    }
    if (t == "composite") {
        // The frame buffer's rules are options too (ProfileRule::explain: --framebuffer, --blend, ...).
        std::vector<const ProfileRule*> fb_rules;
        for (const ProfileRule& rule : profile_rule_table())
            if (!rule.explain.option.empty()) fb_rules.push_back(&rule);
        std::sort(fb_rules.begin(), fb_rules.end(), [](const ProfileRule* a, const ProfileRule* b) { return a->explain.rank < b->explain.rank; });
        std::set<std::string> allowed{"--samples", "--order", "--unit-distance", "--step"};
        for (const ProfileRule* rule : fb_rules) allowed.emplace(rule->explain.option);
        const Options o(t, args, allowed);
        std::vector<CompositeSample> samples;
        for (const std::string& s : o.all("--samples")) {
            const auto v = parse_list("--samples", s, 4, 4, "samples r,g,b,a");
            samples.push_back({{v[0], v[1], v[2]}, v[3]});
        }
        if (!o.has("--samples")) throw Error("--samples: required by explain composite");
        CompositeOrder order = CompositeOrder::FrontToBack;
        if (o.has("--order")) {
            const std::string s = o.one("--order");
            const auto named = scene_names::value_of(scene_names::kOrders, s);
            if (!named) throw Error("--order: expected " + scene_names::listing(scene_names::kOrders) + ", got \"" + s + "\"");
            order = *named;
        }
        if (o.has("--framebuffer")) {  // a slicer's blends, each stored in the frame buffer's format
            ProfileRules given;
            for (const ProfileRule* rule : fb_rules) {
                const std::string option(rule->explain.option);
                if (!o.has(option)) continue;
                const std::string v = o.one(option);
                if (!rule->set_by_name(v, given)) throw Error(option + ": expected " + rule->names() + ", got \"" + v + "\"");
            }
            ProfileRuleValues fb;  // the rules not given: a frame buffer's defaults
            for (const ProfileRule* rule : fb_rules) rule->apply(given, fb);
            const FrameBufferRules f{fb.framebuffer, fb.framebuffer_rounding, fb.blend_products, fb.blend, fb.blend_alpha};
            if (!o.has("--order")) order = CompositeOrder::BackToFront;
            if (o.has("--unit-distance") || o.has("--step")) throw Error("--framebuffer: the samples' alphas are blended as given (no --unit-distance or --step)");
            return composite_framebuffer(samples, order, f);
        }
        for (const ProfileRule* rule : fb_rules)
            if (o.has(std::string(rule->explain.option))) throw Error(std::string(rule->explain.option) + ": applies with --framebuffer");
        return composite(samples, order, number_or(o, "--unit-distance", 1.0), number_or(o, "--step", 1.0));
    }
    if (t == "opacity-correction") {
        const Options o(t, args, {"--opacity", "--unit-distance", "--length"});
        return opacity_correction(parse_number("--opacity", o.one("--opacity")), number_or(o, "--unit-distance", 1.0),
                                  parse_number("--length", o.one("--length")));
    }
    if (t == "classify-isovalue") {
        const Options o(t, args, {"--value", "--gradient", "--contour"});
        std::vector<IsovalueContour> contours;
        for (const std::string& s : o.all("--contour")) {
            const auto v = parse_list("--contour", s, 3, 6, "a contour fv,av,r or fv,av,r,R,G,B");
            if (v.size() != 3 && v.size() != 6) throw Error("--contour: expected fv,av,r or fv,av,r,R,G,B, got \"" + s + "\"");
            if (!(v[1] >= 0.0 && v[1] <= 1.0)) throw Error("--contour: av must be in [0, 1], got \"" + s + "\"");
            if (!(v[2] > 0.0)) throw Error("--contour: r must be > 0, got \"" + s + "\"");
            IsovalueContour c;
            c.value = v[0];
            c.opacity = v[1];
            c.thickness = v[2];
            if (v.size() == 6) c.color = {v[3], v[4], v[5]};
            contours.push_back(c);
        }
        return classify_isovalue(parse_number("--value", o.one("--value")), parse_number("--gradient", o.one("--gradient")),
                                 contours);
    }
    if (t == "classify-boundary") {
        const Options o(t, args, {"--value", "--gradient", "--region"});
        std::vector<BoundaryRegion> regions;
        for (const std::string& s : o.all("--region")) {
            const auto v = parse_list("--region", s, 2, 5, "a region fv,av or fv,av,R,G,B");
            if (v.size() != 2 && v.size() != 5) throw Error("--region: expected fv,av or fv,av,R,G,B, got \"" + s + "\"");
            if (!(v[1] >= 0.0 && v[1] <= 1.0)) throw Error("--region: av must be in [0, 1], got \"" + s + "\"");
            BoundaryRegion r;
            r.value = v[0];
            r.opacity = v[1];
            if (v.size() == 5) r.color = {v[2], v[3], v[4]};
            regions.push_back(r);
        }
        return classify_boundary(parse_number("--value", o.one("--value")), parse_number("--gradient", o.one("--gradient")),
                                 regions);
    }
    if (t == "shade") {
        const Options o(t, args, {"--gradient", "--normal", "--view", "--material", "--light", "--model", "--ka", "--kd",
                                    "--ks", "--n", "--kc", "--kl", "--depth", "--two-sided"});
        o.flag("--two-sided");
        ShadeInput in;
        if (o.has("--gradient") == o.has("--normal")) throw Error("--gradient: give either --gradient or --normal");
        in.gradient = o.has("--gradient") ? vec3("--gradient", o.one("--gradient"))
                                          : -unit("--normal", vec3("--normal", o.one("--normal")));
        in.view = unit("--view", vec3_or(o, "--view", {0.0, 0.0, 1.0}));
        in.material = vec3_or(o, "--material", glm::dvec3(1.0));
        in.depth = number_or(o, "--depth", 0.0);
        ShadingSpec& k = in.spec;
        if (o.has("--model")) {
            const std::string m = o.one("--model");
            const auto named = scene_names::value_of(scene_names::kShadingModels, m);
            if (!named) throw Error("--model: expected " + scene_names::listing(scene_names::kShadingModels) + ", got \"" + m + "\"");
            k.model = *named;
        }
        if (k.model == ShadingSpec::Model::Nodal && (o.has("--ks") || o.has("--n")))
            throw Error("--ks: the nodal model has no specular term (no --ks or --n)");
        k.ka = number_or(o, "--ka", k.ka);
        k.kd = number_or(o, "--kd", k.kd);
        k.ks = number_or(o, "--ks", k.ks);
        k.n = number_or(o, "--n", k.n);
        k.kc = number_or(o, "--kc", k.kc);
        k.kl = number_or(o, "--kl", k.kl);
        k.two_sided = o.has("--two-sided");
        if (o.has("--light")) {
            in.lights.clear();
            for (const std::string& s : o.all("--light")) {
                LightSpec l;
                const std::size_t colon = s.find(':');
                const std::string dir = s.substr(0, colon);
                if (dir == "headlight") {
                    l.type = LightSpec::Type::Headlight;
                } else {
                    l.type = LightSpec::Type::Directional;
                    l.direction = unit("--light", vec3("--light", dir));
                }
                if (colon != std::string::npos) l.color = vec3("--light", s.substr(colon + 1));
                in.lights.push_back(l);
            }
        }
        return shade(in);
    }
    if (t == "coords") {
        const Options o(t, args, {"--cartesian", "--cylindrical", "--spherical", "--center"});
        const int given = int(o.has("--cartesian")) + int(o.has("--cylindrical")) + int(o.has("--spherical"));
        if (given != 1) throw Error("--cartesian: give exactly one of --cartesian, --cylindrical, --spherical");
        const glm::dvec3 c = vec3_or(o, "--center", glm::dvec3(0.0));
        if (o.has("--cartesian")) return coords(CoordinateSystem::Cartesian, vec3("--cartesian", o.one("--cartesian")), c);
        if (o.has("--cylindrical"))
            return coords(CoordinateSystem::Cylindrical, vec3("--cylindrical", o.one("--cylindrical")), c);
        return coords(CoordinateSystem::Spherical, vec3("--spherical", o.one("--spherical")), c);
    }
    if (t == "intersect") {
        const Options o(t, args, {"--origin", "--direction", "--box", "--cylinder", "--sphere", "--center", "--radius",
                                    "--angle", "--height", "--longitude", "--latitude"});
        o.flag("--cylinder");
        o.flag("--sphere");
        Ray ray;
        ray.origin = vec3("--origin", o.one("--origin"));
        ray.direction = unit("--direction", vec3("--direction", o.one("--direction")));
        const int shapes = int(o.has("--box")) + int(o.has("--cylinder")) + int(o.has("--sphere"));
        if (shapes != 1) throw Error("--box: give exactly one of --box, --cylinder, --sphere");
        if (o.has("--box")) {
            const auto v = parse_list("--box", o.one("--box"), 6, 6, "6 numbers MINX,MINY,MINZ,MAXX,MAXY,MAXZ");
            return intersect_box(ray, {v[0], v[1], v[2]}, {v[3], v[4], v[5]});
        }
        if (o.has("--cylinder")) {
            CylindricalShell s;
            s.center = vec3_or(o, "--center", glm::dvec3(0.0));
            const auto r = pair(o, "--radius", {s.r0, s.r1});
            const auto an = pair(o, "--angle", {s.a0, s.a1});
            const auto h = pair(o, "--height", {s.h0, s.h1});
            s.r0 = r[0], s.r1 = r[1], s.a0 = an[0], s.a1 = an[1], s.h0 = h[0], s.h1 = h[1];
            if (o.has("--longitude") || o.has("--latitude")) throw Error("--longitude: only for --sphere");
            return intersect_cylinder(ray, s);
        }
        SphericalShell s;
        s.center = vec3_or(o, "--center", glm::dvec3(0.0));
        const auto r = pair(o, "--radius", {s.r0, s.r1});
        const auto lon = pair(o, "--longitude", {s.lon0, s.lon1});
        const auto lat = pair(o, "--latitude", {s.lat0, s.lat1});
        s.r0 = r[0], s.r1 = r[1], s.lon0 = lon[0], s.lon1 = lon[1], s.lat0 = lat[0], s.lat1 = lat[1];
        if (o.has("--angle") || o.has("--height")) throw Error("--angle: only for --cylinder");
        return intersect_sphere(ray, s);
    }
    if (t == "ray") {
        const Options o(t, args, {"--scene", "--pixel", "--set", "--no-skipping"});
        o.flag("--no-skipping");
        const Scene scene = scene_of(o);
        const auto p = parse_pixel(o.one("--pixel"), scene.image.width, scene.image.height);
        if (is_first_hit(scene.render.projection)) throw Error("trace: first-hit is not supported yet");
        if (scene.render.profile == ProfileId::VolPack)
            throw Error("--scene: a volpack pixel is VolPack's warp of its intermediate image, not a ray: explain volpack-warp works it");
        RenderOptions options;
        options.empty_space_skipping = !o.has("--no-skipping");
        const PreparedScene prepared(scene, options);
        return ray(prepared, p[0], p[1]);
    }
    if (t == "volpack-warp" || t == "volpack-voxel" || t == "volpack-scene") {
        const Options o(t, args, t == "volpack-warp"    ? std::set<std::string>{"--scene", "--pixel", "--set"}
                                 : t == "volpack-voxel" ? std::set<std::string>{"--scene", "--voxel", "--set"}
                                                        : std::set<std::string>{"--scene", "--step", "--set"});
        const Scene scene = scene_of(o);
        if (scene.render.profile != ProfileId::VolPack) throw Error("--scene: not a render.profile \"volpack\" scene");
        const PreparedScene prepared(scene, RenderOptions{});
        if (t == "volpack-warp") {
            const auto p = parse_pixel(o.one("--pixel"), scene.image.width, scene.image.height);
            return volpack_warp(prepared, p[0], p[1]);
        }
        if (t == "volpack-voxel") {
            const auto v = parse_list("--voxel", o.one("--voxel"), 3, 3, "3 integers X,Y,Z");
            for (double c : v)
                if (c != std::floor(c)) throw Error("--voxel: expected 3 integers X,Y,Z, got \"" + o.one("--voxel") + "\"");
            return volpack_voxel(prepared, std::int64_t(v[0]), std::int64_t(v[1]), std::int64_t(v[2]));
        }
        const double step = number_or(o, "--step", 0.125);
        if (!(step > 0.0)) throw Error("--step: must be > 0 (voxels)");
        return volpack_scene(prepared, step);
    }
    if (t == "texture-fetch") {
        const Options o(t, args, {"--unit", "--volume", "--normalized", "--at", "--points"});
        o.flag("--normalized");
        const std::string unit = o.has("--unit") ? o.one("--unit") : "h100";
        if (unit != "h100" && unit != "exact") throw Error("--unit: expected h100 or exact, got \"" + unit + "\"");
        if (o.has("--at") == o.has("--points")) throw Error("--at: give either --at X,Y,Z or --points POINTS.csv");
        const std::string file = o.one("--volume");
        const Volume v = read_volume(file);
        if (o.has("--at")) return texture_fetch(v, vec3("--at", o.one("--at")), unit == "h100", o.has("--normalized"));
        return texture_fetch_points(v, read_points(o.one("--points")), unit == "h100", o.has("--normalized"));
    }
    throw Error("explain: unknown topic \"" + t + "\" (topics: " + topics() + ")");
}


}  // namespace volref::explain
