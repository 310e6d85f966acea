#include "core/scene/ProfileRuleTable.h"

#include <initializer_list>
#include <type_traits>

#include "core/scene/JsonReader.h"
#include "core/scene/SceneNames.h"

namespace volref {

namespace {

namespace names = scene_names;
using json_reader::Choice;
using json_reader::ObjectReader;
using json_reader::Range;
using json_reader::read_numbers;
using json_reader::read_vec3;
using Json = nlohmann::json;
using Dimensions = ProfileRule::Dimensions;
using P = ProfileRuleTypes;
template <class T>
using Exactly = std::type_identity_t<T>;  // a parameter that takes its type from the others

// One dimension of search candidates: {key: value} for each value.
std::vector<Json> values_of(std::string_view key, std::initializer_list<Json> values) {
    std::vector<Json> d;
    for (const Json& v : values) d.push_back(Json::object({{std::string(key), v}}));
    return d;
}

// An entry being built: the makers below give its scene form and resolved value; these members add when
// it is read, its search, its explain option and the option it also is.
struct Rule {
    ProfileRule r;

    Rule& read_by(PlacementMask placements, ReadIn read_in = ReadIn::EveryScene) {
        r.placements = placements;
        r.read_in = read_in;
        return *this;
    }
    // Tried at `rank` with the values `dimensions` gives.
    Rule& tried(int rank, std::function<Dimensions(const Scene&, bool slicer)> dimensions) {
        r.search.rank = rank;
        r.search.dimensions = std::move(dimensions);
        return *this;
    }
    // Tried on ray casters only (or slicers only), one dimension of `values`.
    Rule& tried_on_ray_casters(int rank, std::initializer_list<Json> values) {
        std::vector<Json> d = values_of(r.key, values);
        return tried(rank, [d](const Scene&, bool slicer) { return slicer ? Dimensions{} : Dimensions{d}; });
    }
    Rule& tried_on_slicers(int rank, std::initializer_list<Json> values) {
        std::vector<Json> d = values_of(r.key, values);
        return tried(rank, [d](const Scene&, bool slicer) { return slicer ? Dimensions{d} : Dimensions{}; });
    }
    Rule& explained_as(std::string_view option, int rank) {
        r.explain = {option, rank};
        return *this;
    }
    // A rule that is render.profile_options.`option` too.
    Rule& also_option(std::string_view option, std::function<void(const ProfileRules&, ProfileOptions&)> to_options) {
        r.option = option;
        r.to_options = std::move(to_options);
        return *this;
    }
};

// An enumerated rule, read and written by its names (SceneNames.h). `value`: the resolved profile's
// field (null: a rule a Profile does not hold).
template <class E>
Rule choice_rule(std::string_view key, std::optional<E> ProfileRules::*rule, Exactly<E> ProfileRuleValues::*value,
                 std::span<const Choice<Exactly<E>>> table) {
    ProfileRule r;
    r.key = key;
    r.read = [=](ObjectReader& o, ProfileRules& out) { out.*rule = o.optional_choice<E>(key, table); };
    r.is_set = [=](const ProfileRules& in) { return (in.*rule).has_value(); };
    r.write = [=](const ProfileRules& in, Json& j) {
        if (in.*rule) j[std::string(key)] = names::name_of(table, *(in.*rule));
    };
    if (value) {
        r.apply = [=](const ProfileRules& in, ProfileRuleValues& v) {
            if (in.*rule) v.*value = *(in.*rule);
        };
        r.capture = [=](const ProfileRuleValues& v, ProfileRules& out) { out.*rule = v.*value; };
    }
    r.set_by_name = [=](std::string_view name, ProfileRules& out) {
        const std::optional<E> v = names::value_of(table, name);
        if (v) out.*rule = *v;
        return v.has_value();
    };
    r.names = [=] { return names::listing(table); };
    return {r};
}
template <class E, std::size_t N>
Rule choice_rule(std::string_view key, std::optional<E> ProfileRules::*rule, Exactly<E> ProfileRuleValues::*value,
                 const Choice<Exactly<E>> (&table)[N]) {
    return choice_rule<E>(key, rule, value, std::span<const Choice<E>>(table));
}

// A number in `range`.
Rule number_rule(std::string_view key, std::optional<double> ProfileRules::*rule, double ProfileRuleValues::*value, Range range) {
    ProfileRule r;
    r.key = key;
    r.read = [=](ObjectReader& o, ProfileRules& out) { out.*rule = o.optional_number(key, range); };
    r.is_set = [=](const ProfileRules& in) { return (in.*rule).has_value(); };
    r.write = [=](const ProfileRules& in, Json& j) {
        if (in.*rule) j[std::string(key)] = *(in.*rule);
    };
    r.apply = [=](const ProfileRules& in, ProfileRuleValues& v) {
        if (in.*rule) v.*value = *(in.*rule);
    };
    r.capture = [=](const ProfileRuleValues& v, ProfileRules& out) { out.*rule = v.*value; };
    return {r};
}

// --- the rules whose value is not one name or one number -----------------------------------------------

// "domain", "texel", or a given box {"min": [x, y, z], "max": [x, y, z]}.
Rule ray_box_rule() {
    ProfileRule r;
    r.key = "ray_box";
    r.read = [](ObjectReader& o, ProfileRules& out) {
        const Json* b = o.find("ray_box");
        if (!b) return;
        if (b->is_object()) {
            ObjectReader br(*b, o.path("ray_box"), o.context());
            br.allow({"min", "max"});
            const glm::dvec3 lo = read_vec3(br.required("min"), br.path("min"), o.context());
            const glm::dvec3 hi = read_vec3(br.required("max"), br.path("max"), o.context());
            if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) br.fail("max", "must exceed min on every axis");
            out.ray_box = P::RayBox::Given;
            out.box = std::array<glm::dvec3, 2>{lo, hi};
        } else {
            out.ray_box = o.choice<P::RayBox>("ray_box", P::RayBox::Domain, names::kRayBoxes);
        }
    };
    r.is_set = [](const ProfileRules& in) { return in.ray_box.has_value(); };
    r.write = [](const ProfileRules& in, Json& j) {
        if (in.ray_box == P::RayBox::Given && in.box)
            j["ray_box"] = {{"min", {(*in.box)[0].x, (*in.box)[0].y, (*in.box)[0].z}},
                            {"max", {(*in.box)[1].x, (*in.box)[1].y, (*in.box)[1].z}}};
        else if (in.ray_box)
            j["ray_box"] = names::name_of(names::kRayBoxes, *in.ray_box);
    };
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (in.ray_box) v.ray_box = *in.ray_box;
        if (in.box) v.box = *in.box;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) {
        out.ray_box = v.ray_box;
        if (v.ray_box == P::RayBox::Given) out.box = v.box;
    };
    return {std::move(r)};
}

// "none" or {"alpha_above" | "alpha_at_least" | "transmittance_at_most": x}. Profile.cpp sets and reads
// back Profile::termination (the accumulators' type).
Rule termination_rule() {
    ProfileRule r;
    r.key = "termination";
    r.read = [](ObjectReader& o, ProfileRules& out) {
        const Json* t = o.find("termination");
        if (!t) return;
        if (t->is_object()) {
            ObjectReader tr(*t, o.path("termination"), o.context());
            tr.allow({"alpha_above", "alpha_at_least", "transmittance_at_most"});
            int n = 0;
            for (const auto& stop : names::kStops)
                if (tr.has(stop.name)) {
                    out.termination = stop.value;
                    out.termination_value = tr.number(stop.name, 1.0, Range::closed(0.0, 1.0));
                    ++n;
                }
            if (n != 1) tr.fail_here("expected one of alpha_above, alpha_at_least, transmittance_at_most");
        } else {
            out.termination = o.choice<P::Stop>("termination", P::Stop::None, {{"none", P::Stop::None}});
        }
    };
    r.is_set = [](const ProfileRules& in) { return in.termination.has_value(); };
    r.write = [](const ProfileRules& in, Json& j) {
        if (!in.termination) return;
        if (*in.termination == P::Stop::None)
            j["termination"] = "none";
        else
            j["termination"] = {{names::name_of(names::kStops, *in.termination), in.termination_value}};
    };
    return {std::move(r)};
}

// The number of table entries: 0 (the transfer function read exactly) or at least 2.
Rule table_rule() {
    ProfileRule r;
    r.key = "table";
    r.read = [](ObjectReader& o, ProfileRules& out) {
        if (o.has("table")) out.table_entries = int(o.integer("table", 0, Range::closed(0, 1 << 20)));
        if (out.table_entries == 1) o.fail("table", "expected 0 (the transfer function read exactly) or at least 2 entries");
    };
    r.is_set = [](const ProfileRules& in) { return in.table_entries.has_value(); };
    r.write = [](const ProfileRules& in, Json& j) {
        if (in.table_entries) j["table"] = *in.table_entries;
    };
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (in.table_entries) v.table_entries = *in.table_entries;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) { out.table_entries = v.table_entries; };
    return {std::move(r)};
}

// The gradients' offset in voxels, or (gradient_offset_texture) as a fraction of the domain's extent per
// axis: one of the two, setting one clears the other.
Rule gradient_offset_rule() {
    Rule rule = number_rule("gradient_offset", &ProfileRules::gradient_offset, &ProfileRuleValues::gradient_offset, Range::positive());
    ProfileRule& r = rule.r;
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (!in.gradient_offset) return;
        v.gradient_offset = *in.gradient_offset;
        v.gradient_offset_texture = 0.0;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) {
        if (!(v.gradient_offset_texture > 0.0)) out.gradient_offset = v.gradient_offset;
    };
    return rule;
}
Rule gradient_offset_texture_rule() {
    Rule rule = number_rule("gradient_offset_texture", &ProfileRules::gradient_offset_texture,
                            &ProfileRuleValues::gradient_offset_texture, Range::left_open(0.0, 1.0));
    ProfileRule& r = rule.r;
    r.read = [](ObjectReader& o, ProfileRules& out) {  // after gradient_offset (the table's order)
        out.gradient_offset_texture = o.optional_number("gradient_offset_texture", Range::left_open(0.0, 1.0));
        if (out.gradient_offset && out.gradient_offset_texture)
            o.fail("gradient_offset_texture", "also set as gradient_offset (voxels): set one");
    };
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (!in.gradient_offset_texture) return;
        v.gradient_offset_texture = *in.gradient_offset_texture;
        v.gradient_offset = 0.0;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) {
        if (v.gradient_offset_texture > 0.0) out.gradient_offset_texture = v.gradient_offset_texture;
    };
    return rule;
}

Rule clamp_shaded_rule() {
    ProfileRule r;
    r.key = "clamp_shaded";
    r.read = [](ObjectReader& o, ProfileRules& out) {
        if (o.has("clamp_shaded")) out.clamp_shaded = o.boolean("clamp_shaded", false);
    };
    r.is_set = [](const ProfileRules& in) { return in.clamp_shaded.has_value(); };
    r.write = [](const ProfileRules& in, Json& j) {
        if (in.clamp_shaded) j["clamp_shaded"] = *in.clamp_shaded;
    };
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (in.clamp_shaded) v.clamp_shaded = *in.clamp_shaded;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) { out.clamp_shaded = v.clamp_shaded; };
    return {std::move(r)};
}

// volref never jitters (every pixel its own deterministic ray): "off" is the only value.
Rule jitter_rule() {
    ProfileRule r;
    r.key = "jitter";
    r.read = [](ObjectReader& o, ProfileRules&) { o.choice<bool>("jitter", false, {{"off", false}}); };
    r.is_set = [](const ProfileRules&) { return false; };
    r.write = [](const ProfileRules&, Json&) {};
    r.only_value = "off";
    return {std::move(r)};
}

// The slicer's surfaces: an object of orientation, range, one of spacing / count / period, max_count,
// first, order (each absent key its default).
Rule slices_rule() {
    using S = P::Slices;
    ProfileRule r;
    r.key = "slices";
    r.read = [](ObjectReader& o, ProfileRules& out) {
        const Json* v = o.find("slices");
        if (!v) return;
        ObjectReader sr(*v, o.path("slices"), o.context());
        sr.allow({"orientation", "range", "spacing", "count", "period", "max_count", "first", "order"});
        S sl;
        sl.orientation = sr.choice<S::Orientation>("orientation", S::Orientation::Viewport, names::kSliceOrientations);
        sl.range = sr.choice<S::Range>("range", S::Range::Object, names::kSliceRanges);
        sl.spacing = sr.optional_number("spacing", Range::positive());
        if (sr.has("count")) sl.count = sr.integer("count", 1, Range::closed(1, 1LL << 32));
        if (const Json* p = sr.find("period")) {
            const std::vector<double> c = read_numbers(*p, sr.path("period"), o.context(), 3, Range::positive());
            sl.period = glm::dvec3(c[0], c[1], c[2]);
        }
        if (int(sl.spacing.has_value()) + int(sl.count.has_value()) + int(sl.period.has_value()) > 1)
            sr.fail(sl.count && sl.period ? "period" : sl.count ? "count" : "period", "set one of spacing, count and period");
        if (sr.has("max_count")) sl.max_count = sr.integer("max_count", 1, Range::closed(1, 1LL << 32));
        sl.first = sr.choice<S::First>("first", S::First::Bound, names::kSliceFirsts);
        sl.order = sr.choice<S::Order>("order", S::Order::BackToFront, names::kSliceOrders);
        out.slices = sl;
    };
    r.is_set = [](const ProfileRules& in) { return in.slices.has_value(); };
    r.write = [](const ProfileRules& in, Json& j) {
        if (!in.slices) return;
        const S& s = *in.slices;
        Json o;
        o["orientation"] = names::name_of(names::kSliceOrientations, s.orientation);
        o["range"] = names::name_of(names::kSliceRanges, s.range);
        if (s.spacing) o["spacing"] = *s.spacing;
        if (s.count) o["count"] = *s.count;
        if (s.period) o["period"] = {s.period->x, s.period->y, s.period->z};
        if (s.max_count) o["max_count"] = *s.max_count;
        o["first"] = names::name_of(names::kSliceFirsts, s.first);
        o["order"] = names::name_of(names::kSliceOrders, s.order);
        j["slices"] = o;
    };
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (in.slices) v.slices = *in.slices;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) { out.slices = v.slices; };
    // A search candidate "slices.KEY" sets one key over the scene's surfaces (slice_candidates).
    r.search.set_part = [](Json& object, const std::string& part, const Json& value) {
        if (part == "spacing" || part == "count" || part == "period")  // one of the three
            for (const char* other : {"spacing", "count", "period"}) object.erase(other);
        object[part] = value;
    };
    return {std::move(r)};
}

// A slicer's surfaces as the search tries them, one key of `slices` at a time.
Dimensions slice_candidates(const Scene& scene, bool slicer) {
    if (!slicer) return Dimensions{};
    const double h = scene.render.step;
    Dimensions d;
    std::vector<Json> orientation = values_of("slices.orientation", {"viewport", "axis"});
    if (scene.camera.type != CameraSpec::Type::Orthographic) orientation.push_back({{"slices.orientation", "spherical"}});
    d.push_back(orientation);
    if (scene.camera.near) d.push_back(values_of("slices.range", {"object", "view_volume"}));
    d.push_back(values_of("slices.first", {"bound", "half"}));
    std::vector<Json> spacing = values_of("slices.spacing", {h / 2.0, h, 2.0 * h});
    for (const Json& c : values_of("slices.count", {128, 256})) spacing.push_back(c);
    d.push_back(spacing);
    return d;
}

// The texels' window: "transfer-rows", "data-range", or a given [lo, hi] with lo < hi.
Rule texture_window_rule() {
    ProfileRule r;
    r.key = "texture_window";
    r.read = [](ObjectReader& o, ProfileRules& out) {
        const Json* w = o.find("texture_window");
        if (!w) return;
        if (w->is_array()) {
            const std::vector<double> c = read_numbers(*w, o.path("texture_window"), o.context(), 2);
            if (!(c[0] < c[1])) o.fail("texture_window", "expected [lo, hi] with lo < hi");
            out.texture_window = P::TextureWindow::Given;
            out.texture_window_given = glm::dvec2(c[0], c[1]);
        } else {
            out.texture_window = o.choice<P::TextureWindow>("texture_window", P::TextureWindow::TransferRows, names::kTextureWindows);
        }
    };
    r.is_set = [](const ProfileRules& in) { return in.texture_window.has_value(); };
    r.write = [](const ProfileRules& in, Json& j) {
        if (in.texture_window == P::TextureWindow::Given)
            j["texture_window"] = {in.texture_window_given.x, in.texture_window_given.y};
        else if (in.texture_window)
            j["texture_window"] = names::name_of(names::kTextureWindows, *in.texture_window);
    };
    r.apply = [](const ProfileRules& in, ProfileRuleValues& v) {
        if (!in.texture_window) return;
        v.texture_window = *in.texture_window;
        v.texture_window_given = in.texture_window_given;
    };
    r.capture = [](const ProfileRuleValues& v, ProfileRules& out) {
        out.texture_window = v.texture_window;
        out.texture_window_given = v.texture_window_given;
    };
    return {std::move(r)};
}

// The placement's candidates: midpoints, and from the entry at three first samples with each step count
// (step_count alone cannot be set over midpoints).
Dimensions placement_candidates(const Scene&, bool slicer) {
    if (slicer) return Dimensions{};
    return Dimensions{{{{"placement", "midpoints"}},
                       {{"placement", "from-entry"}, {"first", 0.0}},
                       {{"placement", "from-entry"}, {"first", 0.5}},
                       {{"placement", "from-entry"}, {"first", 1.0}},
                       {{"placement", "from-entry"}, {"first", 0.0}, {"step_count", "before-exit"}},
                       {{"placement", "from-entry"}, {"first", 0.5}, {"step_count", "before-exit"}},
                       {{"placement", "from-entry"}, {"first", 1.0}, {"step_count", "before-exit"}}}};
}

// The table, in render.profile's order of reading. The search ranks (tried(N, ...)) give the search's
// own order: a ray caster's placement, step count, ray box, table, voxel length, correction,
// termination, then the shading rules; a slicer's surfaces, frame buffer, correction, rounding,
// products, blend alpha, then the fragment's rules.
std::vector<ProfileRule> make_table() {
    using R = ProfileRules;
    using V = ProfileRuleValues;
    constexpr PlacementMask kFromEntry = placement_bit(P::Placement::FromEntry);
    constexpr PlacementMask kFromEntryOrExit = kFromEntry | placement_bit(P::Placement::FromExit);
    std::vector<ProfileRule> t;
    auto add = [&t](const Rule& rule) { t.push_back(rule.r); };

    // --- where the samples lie ------------------------------------------------------------------------
    Rule placement = choice_rule("placement", &R::placement, &V::placement, names::kPlacements).tried(0, placement_candidates);
    placement.r.search.carried = {"first", "step_count"};
    placement.r.search.joined = {"first"};
    add(placement);
    add(number_rule("first", &R::first, &V::first, Range::closed(0.0, 1e6)).read_by(kFromEntry));
    add(choice_rule("step_count", &R::step_count, &V::step_count, names::kStepCounts)
            .read_by(kFromEntryOrExit)
            .tried_on_ray_casters(1, {"through-exit", "before-exit"}));
    add(ray_box_rule().tried(2, [](const Scene& scene, bool slicer) {
        const BoundsSpec& b = scene.volume().bounds;
        const bool box = b.type == BoundsSpec::Type::Box && !b.min && !b.max;  // bounds that are the domain
        return slicer || !box ? Dimensions{} : Dimensions{values_of("ray_box", {"domain", "texel"})};
    }));
    add(choice_rule("step_voxel", &R::step_voxel, &V::voxel_length, names::kVoxelLengths).tried(4, [](const Scene& scene, bool slicer) {
        return slicer || scene.render.step_units != StepUnits::Voxel ? Dimensions{}
                                                                     : Dimensions{values_of("step_voxel", {"spacing", "extent-over-samples"})};
    }));

    // --- opacity correction and compositing (a slicer's compositing is its frame buffer's blend) -------
    add(choice_rule("correction", &R::correction, &V::correction, names::kCorrections)
            .read_by(kEveryPlacement, ReadIn::Composite)
            .tried(7, [](const Scene&, bool slicer) {
                return slicer ? Dimensions{values_of("correction", {"none", "exact"})}
                              : Dimensions{values_of("correction", {"pow", "exact", "none", "extinction"})};
            }));
    add(number_rule("correction_floor", &R::correction_floor, &V::correction_floor, Range::closed(0.0, 1.0))
            .read_by(kEveryPlacement, ReadIn::Composite));
    add(number_rule("density_scale", &R::density_scale, &V::density_scale, Range::non_negative()).read_by(kEveryPlacement, ReadIn::Composite));
    add(choice_rule("compositing", &R::compositing, &V::compositing, names::kCompositings).read_by(kRayCasterPlacements, ReadIn::Composite));
    add(termination_rule()
            .read_by(kRayCasterPlacements, ReadIn::Composite)
            .tried_on_ray_casters(16, {"none",
                                       {{"alpha_above", 1.0 - 1.0 / 255.0}},
                                       {{"alpha_at_least", 0.999}},
                                       {{"alpha_above", 0.99}},
                                       {{"alpha_above", 0.95}}}));

    // --- classification -------------------------------------------------------------------------------
    add(table_rule().tried_on_ray_casters(3, {0, 256, 1024}));
    add(choice_rule("table_coordinate", &R::table_coordinate, &V::table_coordinate, names::kTableCoordinates));

    // --- render.profile_options too -------------------------------------------------------------------
    // The canonical names only: "hardware" is render.profile_options' deprecated alias, not a rule's.
    add(choice_rule<ProfileOptions::TextureUnit>("texture_unit", &R::texture_unit, nullptr,
                                                 std::span<const Choice<ProfileOptions::TextureUnit>>(names::kTextureUnits).first(2))
            .also_option("texture_unit", [](const ProfileRules& in, ProfileOptions& o) { o.texture_unit = *in.texture_unit; }));
    add(choice_rule("arithmetic", &R::arithmetic, nullptr, names::kArithmetics).also_option("kernel", [](const ProfileRules& in, ProfileOptions& o) {
        o.kernel = *in.arithmetic == P::Arithmetic::Float32 ? ProfileOptions::Kernel::Float32 : ProfileOptions::Kernel::Double;
    }));

    // --- gradients and shading ------------------------------------------------------------------------
    add(choice_rule("normal", &R::normal_along_gradient, &V::normal_along_gradient, names::kNormals)
            .read_by(kEveryPlacement, ReadIn::ShadedComposite)
            .tried_on_ray_casters(17, {"-gradient", "+gradient"}));
    add(choice_rule("gradient", &R::gradient, &V::gradient, names::kRuleGradients)
            .read_by(kEveryPlacement, ReadIn::ShadedComposite)
            .tried_on_ray_casters(18, {"central", "forward", "central-in-domain"}));
    add(gradient_offset_rule().read_by(kEveryPlacement, ReadIn::ShadedComposite).tried_on_ray_casters(20, {0.5, 1.0, 2.0}));
    add(gradient_offset_texture_rule()  // seed 002's +-0.1 of the domain's extent
            .read_by(kEveryPlacement, ReadIn::ShadedComposite)
            .tried_on_ray_casters(21, {0.1}));
    add(clamp_shaded_rule().read_by(kEveryPlacement, ReadIn::ShadedComposite).tried_on_ray_casters(19, {false, true}));
    add(jitter_rule());

    // --- the slicers' rules (placement "slices"; conventions section 9, "Slice-order renderers") ----------
    add(slices_rule().read_by(kSlicesOnly).tried(5, slice_candidates));
    add(choice_rule("texture", &R::texture, &V::texture, names::kTextures).read_by(kSlicesOnly).tried_on_slicers(15, {"3d", "2d"}));
    add(choice_rule("texture_format", &R::texture_format, &V::texel_format, names::kTexelFormats)
            .read_by(kSlicesOnly)
            .tried_on_slicers(12, {"unorm8", "unorm16", "float"}));
    add(texture_window_rule().read_by(kSlicesOnly));
    add(choice_rule("table_lookup", &R::table_lookup, &V::table_lookup, names::kTableLookups)
            .read_by(kSlicesOnly)
            .tried_on_slicers(11, {"nearest", "linear", "texture"}));
    add(choice_rule("table_format", &R::table_format, &V::table_format, names::kTableFormats)
            .read_by(kSlicesOnly)
            .tried_on_slicers(13, {"unorm8", "float"}));
    add(choice_rule("classify", &R::classify, &V::classify, names::kSliceClassifies)
            .read_by(kSlicesOnly)
            .tried_on_slicers(14, {"post", "pre-unweighted"}));
    add(choice_rule("framebuffer", &R::framebuffer, &V::framebuffer, names::kFrameBuffers)
            .read_by(kSlicesOnly)
            .tried_on_slicers(6, {"rgba8", "rgba16f", "rgba32f", "double"})
            .explained_as("--framebuffer", 0));
    add(choice_rule("framebuffer_rounding", &R::framebuffer_rounding, &V::framebuffer_rounding, names::kRoundings)
            .read_by(kSlicesOnly)
            .tried_on_slicers(8, {"nearest", "truncate"})
            .explained_as("--rounding", 3));
    add(choice_rule("blend_products", &R::blend_products, &V::blend_products, names::kBlendProducts)
            .read_by(kSlicesOnly)
            .tried_on_slicers(9, {"exact", "rounded"})
            .explained_as("--products", 4));
    add(choice_rule("blend", &R::blend, &V::blend, names::kBlends).read_by(kSlicesOnly).explained_as("--blend", 1));
    add(choice_rule("blend_alpha", &R::blend_alpha, &V::blend_alpha, names::kBlendAlphas)
            .read_by(kSlicesOnly)
            .tried_on_slicers(10, {"src-alpha", "one"})
            .explained_as("--blend-alpha", 2));
    add(choice_rule("texture_filter", &R::texture_filter, &V::texture_filter, names::kTextureFilters).read_by(kSlicesOnly));
    return t;
}

}  // namespace

std::span<const ProfileRule> profile_rule_table() {
    static const std::vector<ProfileRule> table = make_table();
    return table;
}

const ProfileRule* find_profile_rule(std::string_view key) {
    for (const ProfileRule& r : profile_rule_table())
        if (r.key == key) return &r;
    return nullptr;
}

bool read_in_scene(const ProfileRule& rule, const Scene& scene) {
    const bool composite = is_composite(scene.render.projection);
    switch (rule.read_in) {
        case ReadIn::EveryScene: return true;
        case ReadIn::Composite: return composite;
        case ReadIn::ShadedComposite: return composite && scene.volume().shading.has_value();
    }
    return true;
}

bool option_set_as_rule(const ProfileRules& rules, std::string_view option) {
    for (const ProfileRule& r : profile_rule_table())
        if (r.option == option && r.is_set(rules)) return true;
    return false;
}

}  // namespace volref
