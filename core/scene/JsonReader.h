// JsonReader: strict reading of JSON documents for the loaders (internal; the public interface is
// SceneLoader.h). Every value is read together with its JSON path, so that any problem becomes a
// volref::Error with the one-line message "<file name>: <json path>: <problem>", e.g.
//   scene.json: volume.transfer.opacity[2][1]: expected a number in [0, 1], got 1.5
//
// Rules enforced here:
//   - parse_json rejects syntax errors (with line and column), duplicate keys in an object, and numbers
//     that overflow a double (1e999), naming the JSON path of the duplicate or overflowing value;
//   - numbers must be finite; integers must have an integral value (2.0 is 2, 2.5 is an error);
//   - an ObjectReader knows which keys it was asked for and throws on any other key (an unknown key is
//     never silently ignored).
//
// Typical use:
//   ObjectReader r(json, "volume.transfer", ctx);
//   double l = r.number("opacity_unit_distance", 1.0, Range::positive());
//   r.finish();  // throws on a key that was not read
#pragma once
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

namespace volref::json_reader {

using Json = nlohmann::json;

// Where the values come from: the document's name (the scene file as given, or "--set ..." for an
// override) and the --set overrides that replaced parts of it. An error at or under an overridden path
// says so at the end of its message ("... (set by --set render.step=-1)").
class Context {
public:
    explicit Context(std::string name) : name_(std::move(name)) {}
    const std::string& name() const { return name_; }

    // Values at and under `path` (as printed by child_path / index_path) came from `--set text`.
    void add_override(std::string path, std::string text);

    // Throws volref::Error("<name>: <path>: <problem>"), made one line; an empty path is the top level.
    [[noreturn]] void fail(std::string_view path, std::string_view problem) const;
    // Throws volref::Error("<name>: <problem>"), made one line: for problems with no JSON path.
    [[noreturn]] void fail_plain(std::string_view problem) const;

private:
    std::string name_;
    std::vector<std::pair<std::string, std::string>> overrides_;  // (path, text), in order of application
};

// JSON path helpers: child_path("volume", "transfer") = "volume.transfer", child_path("", "render") =
// "render", index_path("volume.transfer.opacity", 2) = "volume.transfer.opacity[2]".
std::string child_path(std::string_view parent, std::string_view key);
std::string index_path(std::string_view parent, std::size_t index);
// The path as printed in messages: the path itself, or "(top level)" for the empty path.
std::string display_path(std::string_view path);

// Parses `text` strictly. A syntax error throws volref::Error("<name>: line L, column C: <problem>");
// a duplicate key or a number that overflows a double throws volref::Error naming its JSON path
// (prefixed by `base_path`, for values that are parts of a bigger document).
Json parse_json(const std::string& text, const std::string& name, const std::string& base_path = "");
// As parse_json, but returns nullopt on a syntax error instead of throwing (duplicate keys and
// overflowing numbers still throw): used for --set values, which are strings when they are not JSON.
std::optional<Json> try_parse_json(const std::string& text, const std::string& name,
                                   const std::string& base_path);

// A short description of a value for "got ..." in messages: 1.5, "mip", true, null, [1,2], an object.
std::string describe(const Json& value);
// The shortest text that reads back as the same double: 0.1, 1e+300, 32768.
std::string format_number(double x);

// A range of allowed numbers; default: any finite number.
struct Range {
    std::optional<double> lo, hi;
    bool lo_open = false, hi_open = false;

    static Range any() { return {}; }
    static Range positive() { return {0.0, std::nullopt, true, false}; }      // > 0
    static Range non_negative() { return {0.0, std::nullopt, false, false}; } // >= 0
    static Range at_least(double lo) { return {lo, std::nullopt, false, false}; }
    static Range above(double lo) { return {lo, std::nullopt, true, false}; }
    static Range closed(double lo, double hi) { return {lo, hi, false, false}; }      // [lo, hi]
    static Range open(double lo, double hi) { return {lo, hi, true, true}; }          // (lo, hi)
    static Range left_open(double lo, double hi) { return {lo, hi, true, false}; }    // (lo, hi]

    bool contains(double x) const;
    // "in [0, 1]", "> 0", ">= 1", "in (0, 180)"; "" for any().
    std::string describe() const;
};

// Readers of single values at `path`; each throws volref::Error through ctx.fail on a wrong type or
// an out-of-range value.
double read_number(const Json& v, const std::string& path, const Context& ctx, const Range& range = {});
std::int64_t read_integer(const Json& v, const std::string& path, const Context& ctx,
                          const Range& range = {});
std::string read_string(const Json& v, const std::string& path, const Context& ctx);
// true or false (not 0/1, not "true").
bool read_boolean(const Json& v, const std::string& path, const Context& ctx);
// An array of exactly `count` numbers, each in `range`.
std::vector<double> read_numbers(const Json& v, const std::string& path, const Context& ctx,
                                 std::size_t count, const Range& range = {});
glm::dvec3 read_vec3(const Json& v, const std::string& path, const Context& ctx, const Range& range = {});
// Checks that `v` is an array (of any length) and returns its length.
std::size_t read_array_size(const Json& v, const std::string& path, const Context& ctx);
// Element `index` of an array already checked by read_array_size.
const Json& element(const Json& array, std::size_t index);

// One allowed value of a string-valued key and the enumerator it stands for.
template <class E>
struct Choice {
    std::string_view name;
    E value;
};

// Reads the keys of one JSON object at `path`. Every key read (or declared with allow) becomes known;
// finish() and allow() throw on any key of the object that is not known ("unknown key (expected one
// of: ...)"). Declare the keys first (allow) when a later "required" error could hide a misspelt key.
class ObjectReader {
public:
    // Throws unless `object` is a JSON object. The object must outlive the reader.
    ObjectReader(const Json& object, std::string path, const Context& ctx);

    const std::string& path() const { return path_; }
    std::string path(std::string_view key) const { return child_path(path_, key); }
    const Context& context() const { return ctx_; }
    bool has(std::string_view key) const;

    // Declares keys as known and checks at once that the object has no other key. `what` qualifies
    // the message, e.g. "for camera type \"orthographic\"".
    void allow(std::initializer_list<std::string_view> keys, std::string_view what = {});
    // Throws on the first key of the object that was neither read nor allowed.
    void finish(std::string_view what = {}) const;

    // The value of `key` (marking it known), or nullptr when absent.
    const Json* find(std::string_view key);
    // The value of `key`, or an error "<path.key>: required".
    const Json& required(std::string_view key);
    // Throws "<path.key>: <problem>" when `key` is present: for keys that are recognised but not
    // implemented yet.
    void reject(std::string_view key, std::string_view problem);

    [[noreturn]] void fail(std::string_view key, std::string_view problem) const;
    [[noreturn]] void fail_here(std::string_view problem) const;

    double number(std::string_view key, double fallback, const Range& range = {});
    std::optional<double> optional_number(std::string_view key, const Range& range = {});
    std::int64_t integer(std::string_view key, std::int64_t fallback, const Range& range = {});
    std::string string(std::string_view key, std::string_view fallback);
    std::optional<std::string> optional_string(std::string_view key);
    bool boolean(std::string_view key, bool fallback);
    glm::dvec3 vec3(std::string_view key, const glm::dvec3& fallback, const Range& range = {});
    std::optional<glm::dvec3> optional_vec3(std::string_view key, const Range& range = {});

    // A string key with a fixed set of values (a table of SceneNames.h, or a list). A value listed in
    // `planned` is recognised but rejected as "not implemented yet"; any other unknown value is an
    // error listing `options`.
    template <class E>
    E choice(std::string_view key, E fallback, std::span<const Choice<E>> options,
             std::initializer_list<std::string_view> planned = {}) {
        const std::optional<std::string> s = optional_string(key);
        return s ? match(key, *s, options, planned) : fallback;
    }
    template <class E>
    E choice(std::string_view key, E fallback, std::initializer_list<Choice<E>> options,
             std::initializer_list<std::string_view> planned = {}) {
        return choice(key, fallback, std::span<const Choice<E>>(options.begin(), options.size()), planned);
    }
    // The same, absent when the key is (render.profile's rules: a rule not set is the base's).
    template <class E>
    std::optional<E> optional_choice(std::string_view key, std::span<const Choice<E>> options) {
        const std::optional<std::string> s = optional_string(key);
        return s ? std::optional<E>(match(key, *s, options, {})) : std::nullopt;
    }
    template <class E>
    std::optional<E> optional_choice(std::string_view key, std::initializer_list<Choice<E>> options) {
        return optional_choice(key, std::span<const Choice<E>>(options.begin(), options.size()));
    }
    template <class E>
    E required_choice(std::string_view key, std::span<const Choice<E>> options,
                      std::initializer_list<std::string_view> planned = {}) {
        required(key);
        return choice(key, options.front().value, options, planned);
    }
    template <class E>
    E required_choice(std::string_view key, std::initializer_list<Choice<E>> options,
                      std::initializer_list<std::string_view> planned = {}) {
        return required_choice(key, std::span<const Choice<E>>(options.begin(), options.size()), planned);
    }

private:
    template <class E>
    E match(std::string_view key, const std::string& s, std::span<const Choice<E>> options,
            std::initializer_list<std::string_view> planned) const {
        std::vector<std::string_view> names;
        for (const Choice<E>& o : options) {
            if (o.name == s) return o.value;
            names.push_back(o.name);
        }
        fail_choice(key, s, names, planned);
    }
    [[noreturn]] void fail_choice(std::string_view key, const std::string& got,
                                  const std::vector<std::string_view>& options,
                                  std::initializer_list<std::string_view> planned) const;
    void mark(std::string_view key);

    const Json& object_;
    std::string path_;
    const Context& ctx_;
    std::vector<std::string> known_;  // keys read or allowed, in that order (for messages)
};

}  // namespace volref::json_reader
