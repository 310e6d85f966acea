// Profiles as data (issue 29): render.profile as an object of rules over a preset
// (core/integrate/profiles/Profile.h, core/scene/SceneLoader.cpp), each rule against a hand calculation on
// a constant box, the rules a path cannot honour refused by name, and the convention search
// (core/compare/ConventionSearch.h) finding rules volref itself was told to use.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "ComparedRender.h"
#include "TestScenes.h"
#include "core/Error.h"
#include "core/compare/ConventionSearch.h"
#include "core/integrate/profiles/Profile.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;
using nlohmann::json;

namespace {

// A box [0, 4]^3 of value 0.5 (opacity a per unit distance 1), one pixel looking along -z through its
// centre: the domain's chord is 4 long; step 0.5 (world units).
Scene box_scene(double opacity) {
    Scene s = field_scene(constant_field(0.5, {5, 5, 5}));
    s.volume().transfer.color = {{0, 0.2, 0.4, 0.6}, {1, 0.2, 0.4, 0.6}};
    s.volume().transfer.opacity = {{0, opacity}, {1, opacity}};
    s.volume().transfer.opacity_unit_distance = 1.0;
    s.camera = ortho_down_z(2.0, 2.0, 15.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    return s;
}

Scene with(Scene s, const json& rules) {
    s.render.profile_rules = parse_profile_rules(rules, s.render.profile, "test");
    return s;
}

double alpha(const Scene& s) { return rgba(render_scene(s, {1, false}), 0, 0).a; }

std::string error_of(const Scene& s) {
    try {
        render_scene(s, {1, false});
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

std::string parse_error(const std::string& profile) {
    try {
        parse_scene(R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]}}, "render": {"profile": )" + profile + "}}",
                    ".", "scene");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// Chord 4 (8 steps of 0.5), a = 0.1: each rule's sample count and alpha by hand.
//   from-entry, first 0, through-exit: n = floor(4 / 0.5 + 1) = 9 samples of 1 - 0.9^0.5: A = 1 - 0.9^4.5;
//   before-exit: n = ceil(8) = 8: A = 1 - 0.9^4; first 0.5: through-exit floor(8.5) = 8, before-exit ceil(7.5) = 8;
//   ray_box texel: the chord is 5 (the domain + half a spacing each side): 10 segments, A = 1 - 0.9^5;
//   a given box z in [-1, 5]: chord 6, reads clamped to the domain (a constant): A = 1 - 0.9^6;
//   correction none: 8 midpoints of alpha 0.1: A = 1 - 0.9^8; extinction, density 2: A = 1 - exp(-8 * 0.1 * 0.5 * 2).
TEST(ProfileRules, EachRuleByHand) {
    const Scene s = box_scene(0.1);
    EXPECT_NEAR(alpha(with(s, {{"placement", "from-entry"}, {"first", 0}})), 1.0 - std::pow(0.9, 4.5), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"placement", "from-entry"}, {"first", 0}, {"step_count", "before-exit"}})), 1.0 - std::pow(0.9, 4), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"placement", "from-entry"}, {"first", 0.5}})), 1.0 - std::pow(0.9, 4), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"placement", "from-entry"}, {"first", 0.5}, {"step_count", "before-exit"}})), 1.0 - std::pow(0.9, 4), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"ray_box", "texel"}})), 1.0 - std::pow(0.9, 5), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"ray_box", {{"min", {-3, -3, -1}}, {"max", {7, 7, 5}}}}})), 1.0 - std::pow(0.9, 6), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"correction", "none"}})), 1.0 - std::pow(0.9, 8), 1e-12);
    EXPECT_NEAR(alpha(with(s, {{"correction", "extinction"}, {"density_scale", 2}})), 1.0 - std::exp(-0.8), 1e-12);
    // The three front-to-back compositing rules are one formula: the reference's value.
    for (const char* c : {"optical-depth", "product", "opacity-sum"})
        EXPECT_NEAR(alpha(with(s, {{"compositing", c}})), 1.0 - std::pow(0.9, 4), 1e-12) << c;
}

// Termination after the sample that passes the test: A_k = 1 - 0.9^(k / 2).
//   alpha_at_least 0.2: 0.9^(k/2) <= 0.8 first at k = 5 (k/2 >= 2.118): A = 1 - 0.9^2.5;
//   transmittance_at_most 0.7: 0.9^(k/2) <= 0.7 first at k = 7 (k/2 >= 3.385): A = 1 - 0.9^3.5, under
//   every compositing rule.
TEST(ProfileRules, TerminationByHand) {
    const Scene s = box_scene(0.1);
    EXPECT_NEAR(alpha(with(s, {{"termination", {{"alpha_at_least", 0.2}}}})), 1.0 - std::pow(0.9, 2.5), 1e-12);
    for (const char* c : {"optical-depth", "product", "opacity-sum"})
        EXPECT_NEAR(alpha(with(s, {{"termination", {{"transmittance_at_most", 0.7}}}, {"compositing", c}})), 1.0 - std::pow(0.9, 3.5), 1e-12) << c;
    EXPECT_NEAR(alpha(with(s, {{"termination", {{"alpha_above", 0.2}}}})), 1.0 - std::pow(0.9, 2.5), 1e-12);
}

// A preset's rules written out (profile_rules_json) and read back give the same profile.
TEST(ProfileRules, PresetsRoundTrip) {
    for (ProfileId id : preset_ids()) {
        RenderSpec r;
        r.profile = id;
        const json j = profile_rules_json(resolve_profile(r));
        json rules = j;
        rules.erase("base");
        RenderSpec back;
        back.profile = id;
        if (rules.empty()) continue;  // vtk-cpu, vtk-js, fast: renderers of their own
        back.profile_rules = parse_profile_rules(rules, id, "test");
        EXPECT_EQ(profile_rules_json(resolve_profile(back)), j) << j.dump();
        EXPECT_NE(resolve_profile(back).name.find("custom (base "), std::string::npos);
    }
    RenderSpec vtk;
    vtk.profile = ProfileId::VtkGpu;
    const json v = profile_rules_json(resolve_profile(vtk));
    EXPECT_EQ(v["placement"], "from-entry");
    EXPECT_EQ(v["first"], 1.0);
    EXPECT_EQ(v["table"], 1024);
    EXPECT_EQ(v["termination"]["alpha_above"], 1.0 - 1.0 / 255.0);
    EXPECT_EQ(v["normal"], "+gradient");
}

// Bad rules are one-line errors naming the key.
TEST(ProfileRules, BadRulesNameTheKey) {
    EXPECT_NE(parse_error(R"({"base": "reference", "placement": "random"})").find("render.profile.placement"), std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "reference", "jitter": "on"})").find("render.profile.jitter"), std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "reference", "table": 1})").find("render.profile.table"), std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "reference", "colour": 1})").find("colour"), std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "vtk-js", "placement": "midpoints"})").find("its own renderer"), std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "reference", "termination": {"alpha_above": 0.9, "alpha_at_least": 0.9}})").find("render.profile.termination"),
              std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "reference", "ray_box": {"min": [0, 0, 0], "max": [1, 0, 1]}})").find("render.profile.ray_box.max"),
              std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "reference", "gradient_offset": 1, "gradient_offset_texture": 0.1})").find("gradient_offset_texture"),
              std::string::npos);
    EXPECT_NE(parse_error(R"({"base": "cuda-curvilinear", "texture_unit": "h100"}, "profile_options": {"texture_unit": "exact"})")
                  .find("render.profile.texture_unit"),
              std::string::npos);
}

// A rule the path cannot honour is refused, naming it (never silently ignored).
TEST(ProfileRules, RulesThePathCannotHonourAreRefused) {
    const Scene s = box_scene(0.1);
    EXPECT_NE(error_of(with(s, {{"first", 1}})).find("render.profile.first"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"step_count", "before-exit"}})).find("render.profile.step_count"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"arithmetic", "float32"}})).find("render.profile.arithmetic"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"compositing", "lerp"}, {"termination", {{"alpha_above", 0.5}}}})).find("render.profile.termination"),
              std::string::npos);
    EXPECT_NE(error_of(with(s, {{"placement", "from-exit"}})).find("render.profile.placement"), std::string::npos);
    EXPECT_NE(error_of(with(s, {{"compositing", "lerp"}, {"correction", "none"}})).find("render.profile.correction"), std::string::npos);
    Scene vtk = s;
    vtk.render.profile = ProfileId::VtkGpu;  // its termination would be dropped by lerp
    EXPECT_NE(error_of(with(vtk, {{"compositing", "lerp"}})).find("render.profile.compositing"), std::string::npos);
    EXPECT_EQ(error_of(with(vtk, {{"compositing", "lerp"}, {"termination", "none"}})), "");
    Scene bounded = with(s, {{"ray_box", "texel"}});
    bounded.volume().bounds.min = glm::dvec3(1.0);
    EXPECT_NE(error_of(bounded).find("render.profile.ray_box"), std::string::npos);
    // Only the reference without rules renders transformed volumes and several volumes.
    Scene two = with(s, {{"correction", "none"}});
    two.volumes.push_back(two.volumes.front());
    EXPECT_NE(error_of(two).find("render.profile"), std::string::npos);
}

// volume.bounds past the domain: rays are clipped to the domain, and the render says so.
TEST(ProfileRules, BoundsPastTheDomainWarn) {
    Scene s = box_scene(0.1);
    s.volume().bounds.min = glm::dvec3(-1.0);
    RenderStats stats;
    const Image im = render_scene(s, {1, false}, &stats);
    ASSERT_EQ(stats.warnings.size(), 1u);
    EXPECT_NE(stats.warnings[0].find("volume.bounds"), std::string::npos);
    EXPECT_NEAR(rgba(im, 0, 0).a, 1.0 - std::pow(0.9, 4), 1e-12);  // the chord stays the domain's
    s.volume().bounds.min.reset();
    render_scene(s, {1, false}, &stats);
    EXPECT_TRUE(stats.warnings.empty());
}

// The image models on one pixel (r, g, b, a) = (0.2, 0.1, 0.05, 0.5), premultiplied.
TEST(ConventionSearch, ImageModelsByHand) {
    Image im(1, 2, {"R", "G", "B", "A"});
    const double px[8] = {0.2, 0.1, 0.05, 0.5, 0, 0, 0, 0};
    std::copy(px, px + 8, im.pixels.begin());
    using compare::apply_image_model;
    EXPECT_EQ(apply_image_model("vertical flip", im)[7], 0.5);
    EXPECT_EQ(apply_image_model("vertical flip", im)[3], 0.0);
    EXPECT_NEAR(apply_image_model("unpremultiplied", im)[0], 0.4, 1e-15);
    EXPECT_NEAR(apply_image_model("double-premultiplied", im)[1], 0.05, 1e-15);
    EXPECT_EQ(apply_image_model("BGRA", im)[0], 0.05);
    EXPECT_EQ(apply_image_model("BGRA", im)[2], 0.2);
    EXPECT_NEAR(apply_image_model("sRGB-encoded", im)[0], 1.055 * std::pow(0.2, 1 / 2.4) - 0.055, 1e-15);
    EXPECT_EQ(apply_image_model("identity", im)[3], 0.5);
}

// volref told to use rules (placement from the entry, the texel box; then a flipped image) is the
// "other renderer": the search names those rules; a planted change no rule makes (the transfer
// function's opacity scaled on one half of the image) stays unexplained.
TEST(ConventionSearch, FindsTheRulesItWasGiven) {
    Scene s = field_scene(linear_field({0.0, 0.3, 0.2, 0.1}, {9, 8, 7}));
    s.volume().transfer.color = {{0, 0.9, 0.2, 0.1}, {1, 0.1, 0.5, 0.9}};
    s.volume().transfer.opacity = {{0, 0.02}, {3, 0.4}};
    s.camera.type = CameraSpec::Type::Perspective;
    s.camera.eye = glm::dvec3(14, 11, 20);
    s.camera.target = glm::dvec3(4, 3.5, 3);
    s.camera.up = glm::dvec3(0, 1, 0);
    s.camera.fov_y = 40.0;
    s.image.width = 24;
    s.image.height = 20;
    auto other = [&](const json& rules) { return compared_image(render_scene(with(s, rules), {0, false})); };
    const compare::SearchResult r = compare::search_conventions(other({{"placement", "from-entry"}, {"first", 0}, {"ray_box", "texel"}}), s);
    EXPECT_TRUE(r.explained) << r.verdict;
    EXPECT_EQ(r.best.rules["placement"], "from-entry");
    EXPECT_EQ(r.best.rules["first"], 0.0);
    EXPECT_EQ(r.best.rules["ray_box"], "texel");
    EXPECT_EQ(r.best.image_model, "identity");
    EXPECT_EQ(r.to_json()["rules"], r.best.rules);

    compare::ComparedImage flipped = other({{"correction", "none"}});
    const std::vector<double> f = compare::apply_image_model("vertical flip", flipped.rgba);
    std::copy(f.begin(), f.end(), flipped.rgba.pixels.begin());
    const compare::SearchResult rf = compare::search_conventions(flipped, s);
    EXPECT_TRUE(rf.explained) << rf.verdict;
    EXPECT_EQ(rf.best.rules, json({{"correction", "none"}}));
    EXPECT_EQ(rf.best.image_model, "vertical flip");

    compare::ComparedImage bug = other(json::object());
    for (int y = 0; y < bug.rgba.height / 2; ++y)  // the top half's colour doubled: a planted bug
        for (int x = 0; x < bug.rgba.width; ++x)
            for (std::size_t c = 0; c < 3; ++c) bug.rgba.at(x, y, c) *= 2.0;
    const compare::SearchResult rb = compare::search_conventions(bug, s);
    EXPECT_FALSE(rb.explained) << rb.verdict;
    EXPECT_TRUE(rb.to_json()["rules"].empty());
    EXPECT_GT(rb.best.unexplained_pixels, 0);
    EXPECT_TRUE(rb.alpha_agrees) << rb.verdict;  // only colour was changed
    EXPECT_NE(rb.verdict.find("alpha agrees, colour differs (under the scene's own profile)"), std::string::npos);
}

// --set render.profile.RULE=VALUE sets a rule over the preset the scene names (a name becomes {"base": name}).
TEST(ProfileRules, OverridesSetRulesOverANamedPreset) {
    const std::string scene = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]}}, "render": {"profile": "vtk-gpu"}})";
    const Scene s = parse_scene(scene, ".", "scene", {"render.profile.ray_box=texel", "render.profile.first=0"});
    EXPECT_EQ(s.render.profile, ProfileId::VtkGpu);
    EXPECT_EQ(s.render.profile_rules.ray_box, ProfileRules::RayBox::Texel);
    EXPECT_EQ(s.render.profile_rules.first, 0.0);
    EXPECT_EQ(s.render.profile_rules.keys, (std::vector<std::string>{"first", "ray_box"}));
    const Scene d = parse_scene(R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]}}})", ".", "scene",
                                {"render.profile.correction=none"});
    EXPECT_EQ(d.render.profile, ProfileId::Reference);
    EXPECT_EQ(d.render.profile_rules.correction, ProfileRules::Correction::None);
    EXPECT_FALSE(d.render.reference_integrators());
}

// Every preset's rules, as volref.profiles() gives them, render as the preset (cuda-curvilinear's lerp
// with its own correction "none" included): the same image bit for bit.
TEST(ProfileRules, PresetRulesRenderAsThePreset) {
    Scene s = field_scene(linear_field({0.0, 0.3, 0.2, 0.1}, {9, 8, 7}));
    s.volume().transfer.opacity = {{0, 0.02}, {3, 0.4}};
    s.camera = ortho_down_z(4.0, 3.5, 20.0, 9.0);
    s.image.width = 8;
    s.image.height = 6;
    for (ProfileId id : {ProfileId::VtkGpu, ProfileId::GlslBasic, ProfileId::Ospray, ProfileId::CudaCurvilinear}) {
        s.render.profile = id;
        s.render.profile_rules = {};
        const Image by_name = render_scene(s, {1, false});
        RenderSpec r;
        r.profile = id;
        json rules = profile_rules_json(resolve_profile(r));
        rules.erase("base");
        const Image by_rules = render_scene(with(s, rules), {1, false});
        EXPECT_EQ(by_name.pixels, by_rules.pixels) << rules.dump();
    }
}
