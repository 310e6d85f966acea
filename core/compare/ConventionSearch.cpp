#include "core/compare/ConventionSearch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/Error.h"
#include "core/compare/CompareConstants.h"
#include "core/compare/Tolerance.h"
#include "core/film/Background.h"
#include "core/integrate/profiles/Profile.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneWriter.h"

namespace volref::compare {

using nlohmann::json;

namespace {

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

// sRGB's encoding of a linear value in [0, 1] (IEC 61966-2-1).
double srgb_encode(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

// The number of rules a candidate changes, counting a non-identity image model as one.
int rule_count(const SearchCandidate& c) {
    int n = int(c.rules.size());
    if (c.rules.contains("first")) --n;  // placement "from-entry" and its first sample are one rule
    return n + (c.image_model == "identity" ? 0 : 1);
}

struct Evaluator {
    const ComparedImage& g;
    std::vector<double> tol;  // T + Q_G(p, c), interleaved
    long pixels = 0;
    std::optional<glm::dvec4> background;

    bool skipped(std::size_t p) const { return !g.fault.empty() && g.fault[p] != 0; }

    // The candidate's counts for one render under every image model; the best model kept in `out`.
    // out.residual receives the best model's per-pixel residual.
    void evaluate(const Image& r, SearchCandidate& out) const {
        std::size_t error_channel = r.channels.size();
        for (std::size_t c = 0; c < r.channels.size(); ++c)
            if (r.channels[c] == "error") error_channel = c;
        bool first = true;
        SearchCandidate best = out;
        for (const std::string& m : image_models()) {
            std::vector<double> v = apply_image_model(m, r);
            if (background)
                for (std::size_t i = 0; i + 3 < v.size(); i += 4) composite_over_background(&v[i], *background);
            SearchCandidate c = out;
            c.image_model = m;
            double sum2 = 0.0;
            long n = 0;
            long alpha_over = 0;
            std::vector<double> res(std::size_t(g.rgba.width) * std::size_t(g.rgba.height), 0.0);
            for (std::size_t p = 0; p < res.size(); ++p) {
                if (skipped(p)) continue;
                const double e = error_channel < r.channels.size() ? r.pixels[p * r.channels.size() + error_channel] : 0.0;
                bool over = false;
                for (std::size_t ch = 0; ch < 4; ++ch) {
                    const double d = std::fabs(v[p * 4 + ch] - g.rgba.pixels[p * 4 + ch]);
                    const double allowed = tol[p * 4 + ch] + (std::isfinite(e) ? e : 0.0);
                    if (!(d <= allowed)) {
                        over = true;
                        if (ch == 3) ++alpha_over;
                    }
                    if (std::isfinite(d)) {
                        res[p] = std::max(res[p], d);
                        sum2 += d * d;
                        ++n;
                    } else {
                        res[p] = std::numeric_limits<double>::infinity();
                    }
                }
                if (over) ++c.unexplained_pixels;
            }
            c.residual_max = 0.0;
            for (double x : res) c.residual_max = std::max(c.residual_max, x);
            c.residual_rms = n > 0 ? std::sqrt(sum2 / double(n)) : 0.0;
            c.alpha_unexplained = alpha_over;
            const bool better = first || c.unexplained_pixels < best.unexplained_pixels ||
                                (c.unexplained_pixels == best.unexplained_pixels && c.residual_rms < best.residual_rms);
            if (better) {
                best = c;
                best.residual = std::move(res);
            }
            first = false;
        }
        out = best;
    }
};

// a before b: explaining first (fewer rules, then the smaller RMS), then fewer unexplained pixels.
bool ranks_before(const SearchCandidate& a, const SearchCandidate& b, long allowed) {
    const bool ea = a.unexplained_pixels <= allowed, eb = b.unexplained_pixels <= allowed;
    if (ea != eb) return ea;
    if (ea) {
        if (rule_count(a) != rule_count(b)) return rule_count(a) < rule_count(b);
        return a.residual_rms < b.residual_rms;
    }
    if (a.unexplained_pixels != b.unexplained_pixels) return a.unexplained_pixels < b.unexplained_pixels;
    // RMS residuals that differ by rounding alone (a rule that changes nothing visible) count as equal.
    const double noise = 1e-12 + 1e-9 * std::max(a.residual_rms, b.residual_rms);
    if (std::fabs(a.residual_rms - b.residual_rms) > noise) return a.residual_rms < b.residual_rms;
    return rule_count(a) < rule_count(b);
}

// The rule a candidate object changes ("placement" for {"placement", "first"}).
std::string dimension(const json& rules) { return rules.contains("placement") ? "placement" : rules.begin().key(); }

}  // namespace

std::string SearchCandidate::describe() const {
    std::string s;
    auto add = [&](const std::string& key, const json& value) {
        if (!s.empty()) s += ", ";
        s += key + " " + (value.is_string() ? value.get<std::string>() : value.is_number() ? number_text(value.get<double>()) : value.dump());
    };
    if (rules.contains("placement")) add("placement", rules["placement"]);  // then its first sample
    if (rules.contains("first")) add("first", rules["first"]);
    for (auto it = rules.begin(); it != rules.end(); ++it)
        if (it.key() != "placement" && it.key() != "first") add(it.key(), it.value());
    if (image_model != "identity") s += (s.empty() ? "" : " with ") + std::string("image model ") + image_model;
    return s.empty() ? "the scene's own profile" : s;
}

json SearchResult::to_json() const {
    json j;
    j["explained"] = explained;
    j["rules"] = explained ? best.rules : json::object();
    j["image_model"] = explained ? json(best.image_model) : json(nullptr);
    j["unexplained_pixels"] = best.unexplained_pixels;
    j["residual_max"] = best.residual_max;
    j["residual_rms"] = best.residual_rms;
    j["pixels"] = pixels;
    j["explained_fraction"] = pixels > 0 ? 1.0 - double(best.unexplained_pixels) / double(pixels) : 1.0;
    j["unexplained_before"] = unexplained_before;
    j["tolerance"] = tolerance;
    j["closest"] = {{"rules", best.rules}, {"image_model", best.image_model}};
    j["alpha_agrees_colour_differs"] = alpha_agrees;
    if (alpha_agrees) j["alpha_explained_by"] = {{"rules", alpha_set.rules}, {"image_model", alpha_set.image_model}};
    j["verdict"] = verdict;
    j["tried"] = json::array();
    for (const SearchCandidate& c : tried)
        j["tried"].push_back({{"rules", c.rules},
                              {"image_model", c.image_model},
                              {"unexplained_pixels", c.unexplained_pixels},
                              {"residual_max", c.residual_max},
                              {"residual_rms", c.residual_rms}});
    return j;
}

const std::vector<std::string>& image_models() {
    static const std::vector<std::string> m{"identity", "vertical flip", "unpremultiplied", "double-premultiplied", "BGRA",
                                            "sRGB-encoded"};
    return m;
}

std::vector<double> apply_image_model(const std::string& model, const Image& r) {
    const std::size_t W = std::size_t(r.width), H = std::size_t(r.height), C = r.channels.size();
    std::vector<double> out(W * H * 4);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            const std::size_t sy = model == "vertical flip" ? H - 1 - y : y;
            const double* s = &r.pixels[(sy * W + x) * C];
            double* d = &out[(y * W + x) * 4];
            for (int c = 0; c < 4; ++c) d[c] = s[c];
            if (model == "unpremultiplied") {
                for (int c = 0; c < 3; ++c) d[c] = s[3] > 0.0 ? s[c] / s[3] : 0.0;
            } else if (model == "double-premultiplied") {
                for (int c = 0; c < 3; ++c) d[c] = s[c] * s[3];
            } else if (model == "BGRA") {
                std::swap(d[0], d[2]);
            } else if (model == "sRGB-encoded") {
                for (int c = 0; c < 3; ++c) d[c] = srgb_encode(s[c]);
            }
        }
    return out;
}

std::vector<std::vector<json>> candidate_rules(const Scene& scene) {
    const RenderSpec& r = scene.render;
    const bool composite = is_composite(r.projection);
    const bool shaded = composite && scene.volume().shading.has_value();
    const bool box = scene.volume().bounds.type == BoundsSpec::Type::Box && !scene.volume().bounds.min && !scene.volume().bounds.max;
    std::vector<std::vector<json>> d;
    // A slicer (placement "slices"): its surfaces, fragments and frame buffer; the rules of
    // "slices" are tried one key at a time ("slices.KEY", merged into the object by with_rules).
    if (!r.reference_integrators() && r.profile != ProfileId::Fast &&
        resolve_profile(r).placement == Profile::Placement::Slices) {
        const bool perspective = scene.camera.type != CameraSpec::Type::Orthographic;
        std::vector<json> orientation{{{"slices.orientation", "viewport"}}, {{"slices.orientation", "axis"}}};
        if (perspective) orientation.push_back({{"slices.orientation", "spherical"}});
        d.push_back(orientation);
        if (scene.camera.near) d.push_back({{{"slices.range", "object"}}, {{"slices.range", "view_volume"}}});
        d.push_back({{{"slices.first", "bound"}}, {{"slices.first", "half"}}});
        d.push_back({{{"slices.spacing", r.step / 2.0}}, {{"slices.spacing", r.step}}, {{"slices.spacing", 2.0 * r.step}},
                     {{"slices.count", 128}}, {{"slices.count", 256}}});
        d.push_back({{{"framebuffer", "rgba8"}}, {{"framebuffer", "rgba16f"}}, {{"framebuffer", "rgba32f"}}, {{"framebuffer", "double"}}});
        d.push_back({{{"correction", "none"}}, {{"correction", "exact"}}});
        d.push_back({{{"framebuffer_rounding", "nearest"}}, {{"framebuffer_rounding", "truncate"}}});
        d.push_back({{{"blend_products", "exact"}}, {{"blend_products", "rounded"}}});
        d.push_back({{{"blend_alpha", "src-alpha"}}, {{"blend_alpha", "one"}}});
        d.push_back({{{"table_lookup", "nearest"}}, {{"table_lookup", "linear"}}, {{"table_lookup", "texture"}}});
        d.push_back({{{"texture_format", "unorm8"}}, {{"texture_format", "unorm16"}}, {{"texture_format", "float"}}});
        d.push_back({{{"table_format", "unorm8"}}, {{"table_format", "float"}}});
        d.push_back({{{"classify", "post"}}, {{"classify", "pre-unweighted"}}});
        d.push_back({{{"texture", "3d"}}, {{"texture", "2d"}}});
        return d;
    }
    // (from-entry with each step count: step_count alone cannot be set over midpoints)
    d.push_back({{{"placement", "midpoints"}},
                 {{"placement", "from-entry"}, {"first", 0.0}},
                 {{"placement", "from-entry"}, {"first", 0.5}},
                 {{"placement", "from-entry"}, {"first", 1.0}},
                 {{"placement", "from-entry"}, {"first", 0.0}, {"step_count", "before-exit"}},
                 {{"placement", "from-entry"}, {"first", 0.5}, {"step_count", "before-exit"}},
                 {{"placement", "from-entry"}, {"first", 1.0}, {"step_count", "before-exit"}}});
    d.push_back({{{"step_count", "through-exit"}}, {{"step_count", "before-exit"}}});
    if (box) d.push_back({{{"ray_box", "domain"}}, {{"ray_box", "texel"}}});
    d.push_back({{{"table", 0}}, {{"table", 256}}, {{"table", 1024}}});
    if (r.step_units == StepUnits::Voxel) d.push_back({{{"step_voxel", "spacing"}}, {{"step_voxel", "extent-over-samples"}}});
    if (composite) {
        d.push_back({{{"correction", "pow"}}, {{"correction", "exact"}}, {{"correction", "none"}}, {{"correction", "extinction"}}});
        d.push_back({{{"termination", "none"}},
                     {{"termination", {{"alpha_above", 1.0 - 1.0 / 255.0}}}},
                     {{"termination", {{"alpha_at_least", 0.999}}}},
                     {{"termination", {{"alpha_above", 0.99}}}},
                     {{"termination", {{"alpha_above", 0.95}}}}});
    }
    if (shaded) {
        d.push_back({{{"normal", "-gradient"}}, {{"normal", "+gradient"}}});
        d.push_back({{{"gradient", "central"}}, {{"gradient", "forward"}}, {{"gradient", "central-in-domain"}}});
        d.push_back({{{"clamp_shaded", false}}, {{"clamp_shaded", true}}});
        d.push_back({{{"gradient_offset", 0.5}}, {{"gradient_offset", 1.0}}, {{"gradient_offset", 2.0}}});
        d.push_back({{{"gradient_offset_texture", 0.1}}});  // seed 002's +-0.1 of the domain's extent
    }
    return d;
}

Scene with_rules(const Scene& scene, const json& rules) {
    json merged = profile_rules_object(scene.render.profile_rules);
    for (auto it = rules.begin(); it != rules.end(); ++it) {
        if (it.key().rfind("slices.", 0) == 0) {  // one key of the slicer's "slices" object, over the scene's
            if (!merged.contains("slices")) merged["slices"] = profile_rules_json(resolve_profile(scene.render)).at("slices");
            const std::string key = it.key().substr(7);
            if (key == "spacing" || key == "count" || key == "period")
                for (const char* other : {"spacing", "count", "period"}) merged["slices"].erase(other);
            merged["slices"][key] = it.value();
            continue;
        }
        merged[it.key()] = it.value();
    }
    // A placement other than from-entry has no first sample's offset; midpoints no step count.
    if (rules.contains("placement")) {
        if (merged["placement"] != "from-entry") merged.erase("first");
        if (merged["placement"] == "midpoints") merged.erase("step_count");
    }
    Scene s = scene;
    s.render.profile_rules = parse_profile_rules(merged, scene.render.profile, "--fit");
    // The rules that are render.profile_options too (SceneLoader's read_render does the same).
    if (s.render.profile_rules.texture_unit) s.render.profile_options.texture_unit = *s.render.profile_rules.texture_unit;
    return s;
}

SearchResult search_conventions(const ComparedImage& g, const Scene& scene, const SearchOptions& options) {
    SearchResult out;
    out.width = g.rgba.width;
    out.height = g.rgba.height;
    if (scene.image.width != g.rgba.width || scene.image.height != g.rgba.height)
        throw Error("--scene: the scene renders " + std::to_string(scene.image.width) + "x" + std::to_string(scene.image.height) +
                    " but the image is " + std::to_string(g.rgba.width) + "x" + std::to_string(g.rgba.height));
    out.tolerance = options.tolerance >= 0.0 ? options.tolerance : kSearchTolerance;
    Evaluator ev{g, {}, 0, options.background};
    const std::size_t P = std::size_t(g.rgba.width) * std::size_t(g.rgba.height);
    ev.tol.resize(P * 4);
    for (std::size_t p = 0; p < P; ++p) {
        if (!ev.skipped(p)) ++ev.pixels;
        for (std::size_t c = 0; c < 4; ++c) ev.tol[p * 4 + c] = out.tolerance + quantisation_bound(g, p, c);
    }
    out.pixels = ev.pixels;
    const long allowed = long(std::floor(kSearchUnexplainedFraction * double(ev.pixels)));
    RenderOptions ro;
    ro.threads = options.threads;

    const json base_profile = profile_rules_json(resolve_profile(scene.render));
    // Renders `rules` over the scene's own; false when a rule does not apply or changes nothing.
    auto attempt = [&](const json& rules, SearchCandidate& c) {
        Scene s;
        try {
            s = with_rules(scene, rules);
            if (!rules.empty() && profile_rules_json(resolve_profile(s.render)) == base_profile) return false;
            c.rules = rules;
            ev.evaluate(render_scene(s, ro), c);
        } catch (const Error&) {
            return false;  // not applicable to this scene (a rule's own error)
        }
        out.tried.push_back(c);
        out.tried.back().residual.clear();  // (kept for the best set only: W x H doubles each)
        return true;
    };

    SearchCandidate base;
    ev.evaluate(options.base_render ? *options.base_render : render_scene(scene, ro), base);
    out.tried.push_back(base);
    out.tried.back().residual.clear();
    out.unexplained_before = base.unexplained_pixels;
    SearchCandidate best = base;
    auto consider = [&](const SearchCandidate& c) {
        if (ranks_before(c, best, allowed)) best = c;
    };

    // One rule at a time.
    std::vector<SearchCandidate> singles;
    if (best.unexplained_pixels > allowed || rule_count(best) > 0) {
        for (const std::vector<json>& values : candidate_rules(scene))
            for (const json& v : values) {
                SearchCandidate c;
                if (attempt(v, c)) {
                    consider(c);
                    c.residual.clear();
                    singles.push_back(c);
                }
            }
    }
    // Pairs of singles, then the best set grown one rule at a time while that helps.
    // (By the RMS residual: a rule that is half of the explanation may leave as many pixels over the
    // tolerance as before while bringing every one of them closer.)
    // Every pair when pairs x pixels is within kSearchAllPairsPixels (two rules can explain together what
    // each alone makes worse: from-entry and the texel box); else the kSearchPairsOf singles of smallest RMS.
    std::sort(singles.begin(), singles.end(), [](const SearchCandidate& a, const SearchCandidate& b) { return a.residual_rms < b.residual_rms; });
    std::vector<SearchCandidate> helpful;
    double pairs = 0.0;
    for (std::size_t i = 0; i < singles.size(); ++i)
        for (std::size_t j = i + 1; j < singles.size(); ++j)
            if (dimension(singles[i].rules) != dimension(singles[j].rules)) pairs += 1.0;
    const bool all_pairs = pairs * double(ev.pixels) <= kSearchAllPairsPixels;
    for (const SearchCandidate& c : singles)
        if (all_pairs || helpful.size() < std::size_t(kSearchPairsOf)) helpful.push_back(c);
    if (best.unexplained_pixels > allowed) {
        for (std::size_t i = 0; i < helpful.size(); ++i)
            for (std::size_t j = i + 1; j < helpful.size(); ++j) {
                if (dimension(helpful[i].rules) == dimension(helpful[j].rules)) continue;
                json rules = helpful[i].rules;
                rules.update(helpful[j].rules);
                SearchCandidate c;
                if (attempt(rules, c)) consider(c);
            }
    }
    while (best.unexplained_pixels > allowed && rule_count(best) < kSearchMaxRules) {
        SearchCandidate grown = best;
        for (const SearchCandidate& h : helpful) {
            if (best.rules.contains(dimension(h.rules))) continue;
            json rules = best.rules;
            rules.update(h.rules);
            SearchCandidate c;
            if (attempt(rules, c) && ranks_before(c, grown, allowed)) grown = c;
        }
        if (!ranks_before(grown, best, allowed)) break;
        best = grown;
    }

    // Each rule of the best set swapped for the other values of its rule while that helps (a pair found
    // with first 0 where the image has first 1, say).
    const std::vector<std::vector<json>> dims = candidate_rules(scene);
    for (bool improved = true; improved && best.unexplained_pixels > allowed && !best.rules.empty();) {
        improved = false;
        for (const std::vector<json>& values : dims) {
            const std::string dim = dimension(values.front());
            if (!best.rules.contains(dim)) continue;
            for (const json& v : values) {
                json rules = best.rules;
                rules.erase(dim);
                if (dim == "placement") rules.erase("first"), rules.erase("step_count");
                rules.update(v);
                if (rules == best.rules) continue;
                SearchCandidate c;
                if (attempt(rules, c) && ranks_before(c, best, allowed)) {
                    best = c;
                    improved = true;
                }
            }
        }
    }

    out.residual = std::move(best.residual);  // the heat map
    out.best = best;
    out.explained = best.unexplained_pixels <= allowed;
    const double fraction = ev.pixels > 0 ? 100.0 * (1.0 - double(best.unexplained_pixels) / double(ev.pixels)) : 100.0;
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.2f%%", fraction);
    if (out.explained) {
        out.verdict = (rule_count(best) == 0 ? std::string("the scene's own profile explains ") : best.describe() + " explain ") + pct +
                      " of pixels; " + std::to_string(best.unexplained_pixels) + " pixels unexplained";
    } else {
        out.verdict = "no set of rules or image model explains the image: the closest (" + best.describe() + ") leaves " +
                      std::to_string(best.unexplained_pixels) + " of " + std::to_string(ev.pixels) +
                      " pixels unexplained (residual max " + number_text(best.residual_max) +
                      "): a bug, or a convention volref does not model";
    }
    if (!out.explained) {  // the best-ranked set whose alpha is explained everywhere
        for (const SearchCandidate& c : out.tried)
            if (c.alpha_unexplained <= allowed && (!out.alpha_agrees || ranks_before(c, out.alpha_set, allowed))) {
                out.alpha_agrees = true;
                out.alpha_set = c;
            }
        if (out.alpha_agrees) out.verdict += "; alpha agrees, colour differs (under " + out.alpha_set.describe() + ")";
    }
    return out;
}

}  // namespace volref::compare
