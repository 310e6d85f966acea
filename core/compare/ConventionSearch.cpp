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
#include "core/scene/ProfileRuleTable.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneNames.h"
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

// Whether `key` is counted and described as part of another rule (ProfileRule::Search::joined:
// placement "from-entry" and its first sample are one rule).
bool joined_to_another(const std::string& key) {
    for (const ProfileRule& rule : profile_rule_table())
        for (std::string_view j : rule.search.joined)
            if (j == key) return true;
    return false;
}

// The number of rules a candidate changes, counting a non-identity image model as one.
int rule_count(const SearchCandidate& c) {
    int n = int(c.rules.size());
    for (auto it = c.rules.begin(); it != c.rules.end(); ++it)
        if (joined_to_another(it.key())) --n;
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

// The rule a candidate object changes: its first key in the rule table's order ("placement" for
// {"placement", "first"}; "slices.orientation" for itself).
std::string dimension(const json& rules) {
    for (const ProfileRule& rule : profile_rule_table())
        for (auto it = rules.begin(); it != rules.end(); ++it)
            if (it.key() == rule.key || it.key().rfind(std::string(rule.key) + ".", 0) == 0) return it.key();
    return rules.begin().key();
}

// The table's rules the search tries, in its order (ProfileRule::Search::rank).
std::vector<const ProfileRule*> searched_rules() {
    std::vector<const ProfileRule*> rules;
    for (const ProfileRule& rule : profile_rule_table())
        if (rule.search.dimensions) rules.push_back(&rule);
    std::sort(rules.begin(), rules.end(), [](const ProfileRule* a, const ProfileRule* b) { return a->search.rank < b->search.rank; });
    return rules;
}

}  // namespace

std::string SearchCandidate::describe() const {
    std::string s;
    auto add = [&](const std::string& key, const json& value) {
        if (!s.empty()) s += ", ";
        s += key + " " + (value.is_string() ? value.get<std::string>() : value.is_number() ? number_text(value.get<double>()) : value.dump());
    };
    // A rule with joined keys first, then those keys (placement, then its first sample), then the others.
    std::vector<std::string> done;
    for (const ProfileRule& rule : profile_rule_table()) {
        if (rule.search.joined.empty()) continue;
        done.emplace_back(rule.key);
        for (std::string_view k : rule.search.joined) done.emplace_back(k);
    }
    for (const std::string& k : done)
        if (rules.contains(k)) add(k, rules[k]);
    for (auto it = rules.begin(); it != rules.end(); ++it)
        if (std::find(done.begin(), done.end(), it.key()) == done.end()) add(it.key(), it.value());
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
    // A slicer (placement "slices") tries its surfaces, fragments and frame buffer; a ray caster the
    // rules its scene reads.
    const bool slicer = !r.reference_integrators() && r.profile != ProfileId::Fast &&
                        resolve_profile(r).placement == Profile::Placement::Slices;
    std::vector<std::vector<json>> d;
    for (const ProfileRule* rule : searched_rules()) {
        if (!slicer && !read_in_scene(*rule, scene)) continue;
        for (std::vector<json>& values : rule->search.dimensions(scene, slicer)) d.push_back(std::move(values));
    }
    return d;
}

Scene with_rules(const Scene& scene, const json& rules) {
    json merged = profile_rules_object(scene.render.profile_rules);
    for (auto it = rules.begin(); it != rules.end(); ++it) {
        // "KEY.PART": one part of a rule's object (slices.orientation), over the scene's resolved object.
        const std::size_t dot = it.key().find('.');
        const ProfileRule* whole = dot == std::string::npos ? nullptr : find_profile_rule(std::string_view(it.key()).substr(0, dot));
        if (whole && whole->search.set_part) {
            const std::string key(whole->key);
            if (!merged.contains(key)) merged[key] = profile_rules_json(resolve_profile(scene.render)).at(key);
            whole->search.set_part(merged[key], it.key().substr(dot + 1), it.value());
            continue;
        }
        merged[it.key()] = it.value();
    }
    // A candidate that sets a rule drops the rules it carries that the new placement does not read
    // (other than from-entry: no first sample's offset; midpoints: no step count).
    const auto placement = merged.contains("placement") && merged["placement"].is_string()
                               ? scene_names::value_of(scene_names::kPlacements, merged["placement"].get<std::string>())
                               : std::nullopt;
    for (const ProfileRule& rule : profile_rule_table()) {
        if (!rules.contains(std::string(rule.key)) || !placement) continue;
        for (std::string_view k : rule.search.carried)
            if (const ProfileRule* carried = find_profile_rule(k); carried && !carried->read_under(*placement)) merged.erase(std::string(k));
    }
    Scene s = scene;
    s.render.profile_rules = parse_profile_rules(merged, scene.render.profile, "--fit");
    // The rules that are render.profile_options too (SceneLoader's read_render does the same).
    for (const ProfileRule& rule : profile_rule_table())
        if (!rule.option.empty() && rule.is_set(s.render.profile_rules)) rule.to_options(s.render.profile_rules, s.render.profile_options);
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
                if (const ProfileRule* rule = find_profile_rule(dim))  // with the keys its candidates carry
                    for (std::string_view k : rule->search.carried) rules.erase(std::string(k));
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
