// The rule table (core/scene/ProfileRuleTable.h): every entry against the loader, the writer, the
// resolved profile and the convention search that loop over it. Each rule's example value below is
// read, written back and read again; each bad value is a one-line error naming render.profile.KEY; a
// preset's written rules are exactly those its placement reads; every search candidate parses.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/compare/ConventionSearch.h"
#include "core/explain/ExplainArguments.h"
#include "core/integrate/profiles/Profile.h"
#include "core/scene/ProfileRuleTable.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneWriter.h"

namespace volref {
namespace {

using nlohmann::json;

// One value each rule accepts, over a base it applies to (a rule missing here fails EveryRuleHasAnExample).
const std::map<std::string, std::pair<std::string, json>>& examples() {
    static const std::map<std::string, std::pair<std::string, json>> e{
        {"placement", {"reference", "from-entry"}},
        {"first", {"reference", 0.5}},
        {"step_count", {"reference", "before-exit"}},
        {"ray_box", {"reference", {{"min", {0.0, 0.0, 0.0}}, {"max", {1.0, 2.0, 3.0}}}}},
        {"step_voxel", {"reference", "extent-over-samples"}},
        {"correction", {"reference", "extinction"}},
        {"correction_floor", {"reference", 0.25}},
        {"density_scale", {"reference", 2.0}},
        {"compositing", {"reference", "product"}},
        {"termination", {"reference", {{"transmittance_at_most", 0.01}}}},
        {"table", {"reference", 256}},
        {"table_coordinate", {"reference", "data-range-times-transfer-scale"}},
        {"texture_unit", {"reference", "h100"}},
        {"arithmetic", {"cuda-curvilinear", "double"}},
        {"normal", {"reference", "+gradient"}},
        {"gradient", {"reference", "forward"}},
        {"gradient_offset", {"reference", 0.5}},
        {"gradient_offset_texture", {"reference", 0.1}},
        {"clamp_shaded", {"reference", true}},
        {"jitter", {"reference", "off"}},
        {"slices", {"volumizer", {{"orientation", "axis"}, {"range", "object"}, {"count", 128}, {"first", "half"}, {"order", "back-to-front"}}}},
        {"texture", {"volumizer", "2d"}},
        {"texture_format", {"volumizer", "unorm16"}},
        {"texture_window", {"volumizer", {0.25, 0.75}}},
        {"table_lookup", {"volumizer", "linear"}},
        {"table_format", {"volumizer", "float"}},
        {"classify", {"volumizer", "pre-unweighted"}},
        {"framebuffer", {"volumizer", "rgba16f"}},
        {"framebuffer_rounding", {"volumizer", "truncate"}},
        {"blend_products", {"volumizer", "llvmpipe"}},
        {"blend", {"volumizer", "premultiplied"}},
        {"blend_alpha", {"volumizer", "one"}},
        {"texture_filter", {"volumizer", "fixed8"}},
    };
    return e;
}

Scene scene_with(const json& profile) {
    const json j = {{"volume", {{"source", {{"field", "constant"}, {"value", 1}, {"dims", {4, 4, 4}}}}}},
                    {"render", {{"profile", profile}}}};
    return parse_scene(j.dump(), ".", "scene");
}

std::string load_error(const json& profile) {
    try {
        scene_with(profile);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(ProfileRuleTable, KeysAreUniqueAndEveryRuleHasAnExample) {
    std::set<std::string> keys;
    for (const ProfileRule& rule : profile_rule_table()) {
        EXPECT_TRUE(keys.insert(std::string(rule.key)).second) << rule.key;
        EXPECT_TRUE(examples().count(std::string(rule.key))) << rule.key << ": no example value in this test";
        EXPECT_TRUE(rule.read && rule.is_set && rule.write) << rule.key;
        EXPECT_EQ(bool(rule.apply), bool(rule.capture)) << rule.key;
        EXPECT_EQ(rule.option.empty(), !rule.to_options) << rule.key;
        EXPECT_EQ(find_profile_rule(rule.key), &rule);
    }
    EXPECT_EQ(keys.size(), examples().size());
    EXPECT_EQ(find_profile_rule("colour"), nullptr);
}

// The search's and explain's orders are total: no two rules share a rank.
TEST(ProfileRuleTable, RanksAreDistinct) {
    std::set<int> search, explain;
    for (const ProfileRule& rule : profile_rule_table()) {
        EXPECT_EQ(rule.search.rank >= 0, bool(rule.search.dimensions)) << rule.key;
        if (rule.search.dimensions) EXPECT_TRUE(search.insert(rule.search.rank).second) << rule.key;
        EXPECT_EQ(rule.explain.rank >= 0, !rule.explain.option.empty()) << rule.key;
        if (!rule.explain.option.empty()) {
            EXPECT_TRUE(explain.insert(rule.explain.rank).second) << rule.key;
            EXPECT_TRUE(rule.set_by_name && rule.names) << rule.key;
        }
    }
}

// Each example: read (recorded as set unless it has one value), written back as given, and read again
// to the same rules; the resolved profile then writes it where its placement reads it.
TEST(ProfileRuleTable, EveryKeyRoundTripsThroughTheLoaderAndTheWriter) {
    for (const ProfileRule& rule : profile_rule_table()) {
        const auto& [base, value] = examples().at(std::string(rule.key));
        const json profile = {{"base", base}, {std::string(rule.key), value}};
        SCOPED_TRACE(profile.dump());
        const Scene s = scene_with(profile);
        const ProfileRules& r = s.render.profile_rules;
        if (rule.only_value) {
            EXPECT_TRUE(r.empty());
            EXPECT_EQ(profile_rules_object(r), json::object());
            EXPECT_EQ(profile_rules_json(resolve_profile(s.render)).at(std::string(rule.key)), rule.only_value);
            continue;
        }
        EXPECT_EQ(r.keys, std::vector<std::string>{std::string(rule.key)});
        EXPECT_TRUE(rule.is_set(r));
        const json written = profile_rules_object(r);
        EXPECT_EQ(written, json({{std::string(rule.key), value}}));
        // The whole scene written and read back: the same render.profile.
        const Scene back = parse_scene(scene_json(s).dump(), ".", "back");
        EXPECT_EQ(profile_rules_object(back.render.profile_rules), written);
        EXPECT_EQ(back.render.profile_rules.keys, r.keys);
        // The resolved profile holds the value and writes it back (the rules a Profile holds, where its
        // placement reads them).
        const Profile p = resolve_profile(s.render);
        const json resolved = resolved_profile_json(s.render);
        if (rule.apply && rule.read_under(p.placement)) EXPECT_EQ(resolved.at(std::string(rule.key)), value);
        if (!rule.option.empty()) EXPECT_EQ(resolved.at(std::string(rule.key)), value);
    }
}

// A bad value of any rule is one line naming render.profile.KEY.
TEST(ProfileRuleTable, EveryBadValueIsRefusedNamingItsKey) {
    for (const ProfileRule& rule : profile_rule_table()) {
        const std::string& base = examples().at(std::string(rule.key)).first;
        for (const json& bad : {json("no-such-value"), json::array(), json(-1)}) {
            const json profile = {{"base", base}, {std::string(rule.key), bad}};
            const std::string e = load_error(profile);
            SCOPED_TRACE(profile.dump());
            if (e.empty()) {  // -1 is a value of no rule here but a number's; "no-such-value" and [] of none
                ADD_FAILURE() << "accepted";
                continue;
            }
            EXPECT_NE(e.find("render.profile." + std::string(rule.key)), std::string::npos) << e;
            EXPECT_EQ(e.find('\n'), std::string::npos) << e;
        }
    }
}

// Messages the loop over the table keeps byte for byte.
TEST(ProfileRuleTable, MessagesAsBefore) {
    EXPECT_EQ(load_error({{"base", "reference"}, {"colour", 1}}),
              "scene: render.profile.colour: unknown key (expected one of: base, placement, first, step_count, ray_box, step_voxel, "
              "correction, correction_floor, density_scale, compositing, termination, table, table_coordinate, texture_unit, "
              "arithmetic, normal, gradient, gradient_offset, gradient_offset_texture, clamp_shaded, jitter, slices, texture, "
              "texture_format, texture_window, table_lookup, table_format, classify, framebuffer, framebuffer_rounding, "
              "blend_products, blend, blend_alpha, texture_filter)");
    EXPECT_EQ(load_error({{"base", "vtk-js"}, {"jitter", "off"}, {"table", 3}}),
              "scene: render.profile.table: the \"vtk-js\" profile is its own renderer, not a set of rules (use "
              "render.profile_options, or base \"reference\")");
    EXPECT_EQ(load_error({{"base", "reference"}, {"table", 1}}),
              "scene: render.profile.table: expected 0 (the transfer function read exactly) or at least 2 entries");
    EXPECT_EQ(load_error({{"base", "reference"}, {"gradient_offset", 1}, {"gradient_offset_texture", 0.1}}),
              "scene: render.profile.gradient_offset_texture: also set as gradient_offset (voxels): set one");
    EXPECT_EQ(load_error({{"base", "reference"}, {"texture_unit", "hardware"}}),
              "scene: render.profile.texture_unit: expected one of \"exact\", \"h100\", got \"hardware\"");
    // The first bad rule in the table's order is the message.
    EXPECT_EQ(load_error({{"base", "reference"}, {"texture_filter", "x"}, {"framebuffer", "y"}}),
              "scene: render.profile.framebuffer: expected one of \"double\", \"rgba32f\", \"rgba16f\", \"rgba8\", got \"y\"");
    // The rules that are render.profile_options too.
    try {
        parse_scene(R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]}},
                        "render": {"profile": {"base": "cuda-curvilinear", "arithmetic": "double"}, "profile_options": {"kernel": "double"}}})",
                    ".", "scene");
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "scene: render.profile.arithmetic: also set by render.profile_options.kernel (set it in one place)");
    }
}

// profile_rules_json writes, of the rules a Profile holds, exactly those its placement reads (and the
// one-valued ones); what it writes reads back to the same profile.
TEST(ProfileRuleTable, APresetWritesTheRulesItsPlacementReads) {
    for (ProfileId id : preset_ids()) {
        RenderSpec r;
        r.profile = id;
        const Profile p = resolve_profile(r);
        const json j = profile_rules_json(p);
        if (j.size() == 1) continue;  // a renderer of its own: {"base": name}
        std::set<std::string> expected{"base"};
        for (const ProfileRule& rule : profile_rule_table())
            if ((rule.capture || rule.key == "termination") && rule.read_under(p.placement)) expected.insert(std::string(rule.key));
            else if (rule.only_value) expected.insert(std::string(rule.key));
        // The gradient's offset is one of two keys.
        expected.erase(p.gradient_offset_texture > 0.0 ? "gradient_offset" : "gradient_offset_texture");
        std::set<std::string> got;
        for (auto it = j.begin(); it != j.end(); ++it) got.insert(it.key());
        EXPECT_EQ(got, expected) << j.dump();
    }
}

// Every value the search tries on a ray caster and on a slicer parses over the scene's own rules.
TEST(ProfileRuleTable, EverySearchCandidateParses) {
    Scene caster = scene_with("vtk-gpu");
    caster.volume().shading = ShadingSpec{};
    Scene slicer = scene_with("volumizer");
    slicer.camera.type = CameraSpec::Type::Perspective;
    slicer.camera.near = 1.0;
    slicer.camera.far = 100.0;
    std::set<std::string> tried;
    for (const Scene* s : {&caster, &slicer})
        for (const std::vector<json>& values : compare::candidate_rules(*s))
            for (const json& v : values) {
                SCOPED_TRACE(v.dump());
                EXPECT_NO_THROW(compare::with_rules(*s, v));
                for (auto it = v.begin(); it != v.end(); ++it) tried.insert(it.key().substr(0, it.key().find('.')));
            }
    for (const ProfileRule& rule : profile_rule_table())
        if (rule.search.dimensions) EXPECT_TRUE(tried.count(std::string(rule.key))) << rule.key << ": never tried";
}

// explain composite's frame-buffer options are the table's, in its explain order.
TEST(ProfileRuleTable, ExplainTakesTheFrameBufferRules) {
    auto error_of = [](const std::vector<std::string>& args) {
        try {
            explain::from_arguments("composite", args);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(error_of({"--samples", "1,0,0,0.5", "--framebuffer", "rgba8", "--blend", "premultiplied", "--blend-alpha", "one",
                        "--rounding", "truncate", "--products", "llvmpipe"}),
              "");
    EXPECT_EQ(error_of({"--samples", "1,0,0,0.5", "--framebuffer", "rgba8", "--products", "z", "--blend-alpha", "x"}),
              "--blend-alpha: expected src-alpha or one, got \"x\"");
    EXPECT_EQ(error_of({"--samples", "1,0,0,0.5", "--products", "exact", "--rounding", "nearest"}), "--rounding: applies with --framebuffer");
}

}  // namespace
}  // namespace volref
