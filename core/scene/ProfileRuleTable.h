// ProfileRuleTable: render.profile's rules, one entry each (docs/scene-format.md, "render.profile";
// docs/conventions.md section 9, "Profiles as data"). An entry holds everything about its rule that is
// not the renderer reading it: its key, how the scene's object reads it (with the one-line messages
// naming render.profile.KEY) and writes it back, how it sets a resolved profile's value
// (ProfileRuleValues, which Profile extends) and reads it back, which placements and scenes read it, the
// values the convention search tries, and the `volref explain composite` option that takes it. The
// loops over it: SceneLoader (read_profile_rules), SceneWriter (profile_rules_object), Profile.cpp
// (resolve_profile, profile_rules_json, resolved_profile_json), ConventionSearch (candidate_rules,
// with_rules, describe) and ExplainArguments (composite --framebuffer). A new rule is its enumeration
// and value in Scene.h (ProfileRules, ProfileRuleValues), its names in SceneNames.h, one entry in
// ProfileRuleTable.cpp and the renderer's code that reads it.
//
// The table lives in core/scene, beside the loader and writer that loop over it, because core/scene
// includes nothing of the layers above it (docs/architecture.md): the resolved values an entry sets are
// ProfileRuleValues, a scene type, so an entry needs nothing of core/integrate. The one rule whose
// resolved form is not a scene type is "termination" (Profile::termination is the accumulators'
// Termination): its entry reads, writes and searches it; Profile.cpp sets and reads back the Termination.
#pragma once
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene/Scene.h"

namespace volref {

namespace json_reader {
class ObjectReader;  // core/scene/JsonReader.h (internal: not installed)
}

// The placements that read a rule, a bit (1 << Placement) for each.
using PlacementMask = unsigned;
constexpr PlacementMask placement_bit(ProfileRuleTypes::Placement p) { return 1u << unsigned(p); }
inline constexpr PlacementMask kEveryPlacement = 0xFu;
inline constexpr PlacementMask kRayCasterPlacements =
    placement_bit(ProfileRuleTypes::Placement::Midpoints) | placement_bit(ProfileRuleTypes::Placement::FromEntry) |
    placement_bit(ProfileRuleTypes::Placement::FromExit);
inline constexpr PlacementMask kSlicesOnly = placement_bit(ProfileRuleTypes::Placement::Slices);

// The scenes whose ray casters read a rule: every scene, composite projections, or shaded composites
// (the compositing and shading rules; a slicer reads its own rules in every scene it renders).
enum class ReadIn { EveryScene, Composite, ShadedComposite };

struct ProfileRule {
    using Json = nlohmann::json;
    using Dimensions = std::vector<std::vector<Json>>;  // the search's values, by dimension

    std::string_view key;

    // --- when it is read ----------------------------------------------------------------------------
    // The placements whose renderers read the rule: profile_rules_json writes it for those only (a
    // from-entry first sample, a slicer's frame buffer), and a search candidate that changes the
    // placement drops the rules it carries that the new placement does not read.
    PlacementMask placements = kEveryPlacement;
    ReadIn read_in = ReadIn::EveryScene;

    // --- the scene's form ---------------------------------------------------------------------------
    // Reads the key from render.profile's object into the scene's rules, when present (absent: the
    // rule stays unset); every problem is a one-line message naming render.profile.KEY.
    std::function<void(json_reader::ObjectReader& object, ProfileRules& rules)> read;
    // Whether the scene's rules set it, and its value as render.profile's object writes it.
    std::function<bool(const ProfileRules& rules)> is_set;
    std::function<void(const ProfileRules& rules, Json& object)> write;
    // A rule with one accepted value (jitter "off": volref never jitters): not recorded as set, and
    // written with that value in every resolved profile. Null for the others.
    const char* only_value = nullptr;

    // --- the resolved profile -----------------------------------------------------------------------
    // The scene's value set over the preset's (resolve_profile), and the resolved value as a set rule
    // (profile_rules_json). Null for the rules a Profile does not hold (texture_unit and arithmetic are
    // render.profile_options, jitter has one value, termination is Profile.cpp's).
    std::function<void(const ProfileRules& rules, ProfileRuleValues& values)> apply;
    std::function<void(const ProfileRuleValues& values, ProfileRules& rules)> capture;

    // --- a render.profile_options key the rule also is ------------------------------------------------
    // (texture_unit, kernel): set in one place only; the rule's value becomes the option's.
    std::string_view option;
    std::function<void(const ProfileRules& rules, ProfileOptions& options)> to_options;

    // --- the convention search (core/compare/ConventionSearch.h) --------------------------------------
    struct Search {
        // Where the search tries this rule among the others (the order of its singles, pairs and list
        // of tried sets); -1: not tried.
        int rank = -1;
        // The values tried on `scene` (slicer: its placement is "slices"), one list per dimension; a
        // ray caster's rule is tried only in the scenes that read it (read_in).
        std::function<Dimensions(const Scene& scene, bool slicer)> dimensions;
        // Keys its candidates set with it (placement: first, step_count): swapped out with it, and
        // dropped from the scene's rules when the new value does not read them.
        std::vector<std::string_view> carried;
        // Keys counted and described as one rule with it (placement "from-entry" and its first sample).
        std::vector<std::string_view> joined;
        // A candidate "KEY.PART" sets PART of the rule's object (slices.orientation), over the scene's.
        std::function<void(Json& object, const std::string& part, const Json& value)> set_part;
    } search;

    // --- `volref explain composite` -----------------------------------------------------------------
    struct Explain {
        std::string_view option;  // "--blend"; empty: not an option
        int rank = -1;            // the order the options are read in (the first bad one is the message)
    } explain;
    // An enumerated rule by one of its names: false when `name` is not one; and its names for a message
    // ("a, b or c"). Null for the rules whose value is not a name.
    std::function<bool(std::string_view name, ProfileRules& rules)> set_by_name;
    std::function<std::string()> names;

    bool read_under(ProfileRuleTypes::Placement p) const { return (placements & placement_bit(p)) != 0; }
};

// Every rule, in the order render.profile's object is read (its keys recorded in that order, the first
// bad rule the message) and its unknown-key message lists them.
std::span<const ProfileRule> profile_rule_table();

// The entry of `key`, or null.
const ProfileRule* find_profile_rule(std::string_view key);

// Whether `scene`'s ray casters read `rule` (ReadIn).
bool read_in_scene(const ProfileRule& rule, const Scene& scene);

// Whether a rule that is also render.profile_options.`option` is set in `rules` (the option is then
// the rule's).
bool option_set_as_rule(const ProfileRules& rules, std::string_view option);

}  // namespace volref
