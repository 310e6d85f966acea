#include "core/scene/JsonReader.h"

#include "core/Conventions.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/Error.h"

namespace volref::json_reader {

namespace {

// Messages are one line: control characters (from keys, strings or --set texts) are escaped.
std::string one_line(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (const char c : s) {
        const auto u = static_cast<unsigned char>(c);
        if (c == '\n') {
            out += "\\n";
        } else if (c == '\r') {
            out += "\\r";
        } else if (c == '\t') {
            out += "\\t";
        } else if (u < 0x20 || u == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            out += "\\x";
            out += hex[u >> 4];
            out += hex[u & 15];
        } else {
            out += c;
        }
    }
    return out;
}

// True when `path` is `prefix` or lies under it ("render.step" is under "render", not under "rend").
bool is_under(std::string_view path, std::string_view prefix) {
    if (path.substr(0, prefix.size()) != prefix) return false;
    return path.size() == prefix.size() || path[prefix.size()] == '.' || path[prefix.size()] == '[';
}

std::string dump(const Json& v) {
    return v.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// "line L, column C" of byte offset `offset` (0-based) in `text`; columns count bytes from 1.
std::string line_and_column(const std::string& text, std::size_t offset) {
    const std::string_view before(text.data(), std::min(offset, text.size()));
    const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t newline = before.rfind('\n');
    const std::size_t column = newline == std::string_view::npos ? before.size() + 1 : before.size() - newline;
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// Builds the document like nlohmann's own DOM parser, and in addition rejects duplicate keys and
// numbers that overflow a double, naming their JSON path. Syntax errors are recorded, not thrown.
class StrictSax : public nlohmann::json_sax<Json> {
public:
    StrictSax(Json& root, const std::string& text, const Context& ctx, std::string base_path)
        : root_(root), text_(text), ctx_(ctx), base_path_(std::move(base_path)) {}

    // The nlohmann message of the syntax error, "line L, column C: <problem>", if parsing failed.
    const std::string& syntax_error() const { return syntax_error_; }

    bool null() override { return add(Json(nullptr)) != nullptr; }
    bool boolean(bool v) override { return add(Json(v)) != nullptr; }
    bool number_integer(number_integer_t v) override { return add(Json(v)) != nullptr; }
    bool number_unsigned(number_unsigned_t v) override { return add(Json(v)) != nullptr; }
    bool number_float(number_float_t v, const string_t& text) override {
        // 0 or a magnitude in [kMinMagnitude, kMaxMagnitude] (conventions.md, "Extreme numbers")
        if (v != 0.0 && !(std::fabs(v) <= conventions::kMaxMagnitude && std::fabs(v) >= conventions::kMinMagnitude))
            ctx_.fail(pending_path(), "the number " + text + " is beyond volref's range (0, or a magnitude in [1e-100, 1e100]: "
                                      "products of two such numbers stay finite doubles)");
        return add(Json(v)) != nullptr;
    }
    bool string(string_t& v) override { return add(Json(std::move(v))) != nullptr; }
    bool binary(binary_t& v) override { return add(Json::binary(std::move(v))) != nullptr; }

    bool start_object(std::size_t) override {
        check_depth();
        frames_.push_back({add(Json::object()), {}});
        return true;
    }
    bool key(string_t& k) override {
        Frame& f = frames_.back();
        f.key = k;
        if (f.container->contains(k)) ctx_.fail(pending_path(), "duplicate key");
        return true;
    }
    bool end_object() override {
        frames_.pop_back();
        return true;
    }
    bool start_array(std::size_t) override {
        check_depth();
        frames_.push_back({add(Json::array()), {}});
        return true;
    }
    bool end_array() override {
        frames_.pop_back();
        return true;
    }

    bool parse_error(std::size_t position, const std::string& last_token,
                     const nlohmann::json::exception& ex) override {
        if (ex.id == 406) {  // out_of_range.406: number overflow (e.g. 1e999)
            const std::size_t start = position >= last_token.size() ? position - last_token.size() : 0;
            ctx_.fail(pending_path(), "the number " + last_token + " is out of range for a double (" +
                                          line_and_column(text_, start) + ")");
        }
        syntax_error_ = nlohmann_message(ex.what(), position);
        return false;
    }

private:
    struct Frame {
        Json* container;
        std::string key;  // objects: the key whose value is being read
    };

    // Appends `v` where the parser is (the root, the end of the current array, or the current key).
    Json* add(Json&& v) {
        if (frames_.empty()) {
            root_ = std::move(v);
            return &root_;
        }
        Frame& f = frames_.back();
        if (f.container->is_array()) {
            f.container->push_back(std::move(v));
            return &f.container->back();
        }
        Json& slot = (*f.container)[f.key];
        slot = std::move(v);
        return &slot;
    }

    // conventions::kMaxJsonDepth: the error names the path of the outermost two levels.
    void check_depth() const {
        if (frames_.size() >= std::size_t(conventions::kMaxJsonDepth))
            ctx_.fail(pending_path(2), "nested deeper than " + std::to_string(conventions::kMaxJsonDepth) +
                                           " arrays and objects");
    }

    // The path of the value being read (the next element of the innermost array, or the current key);
    // with `levels`, only the outermost `levels` containers.
    std::string pending_path(std::size_t levels = std::size_t(-1)) const {
        std::string path = base_path_;
        const std::size_t n = std::min(levels, frames_.size());
        for (std::size_t i = 0; i < n; ++i) {
            const Frame& f = frames_[i];
            const bool innermost = i + 1 == frames_.size();
            if (f.container->is_object())
                path = child_path(path, f.key);
            else
                path = index_path(path, f.container->size() - (innermost ? 0 : 1));
        }
        return path;
    }

    // nlohmann says "[json.exception.parse_error.101] parse error at line 2, column 7: syntax error
    // ..."; keep "line 2, column 7: syntax error ...".
    std::string nlohmann_message(const std::string& what, std::size_t position) const {
        const std::size_t at = what.find("at line ");
        if (at != std::string::npos) return what.substr(at + 3);
        const std::size_t bracket = what.find("] ");
        return "byte " + std::to_string(position) + ": " +
               (bracket == std::string::npos ? what : what.substr(bracket + 2));
    }

    Json& root_;
    const std::string& text_;
    const Context& ctx_;
    std::string base_path_;
    std::vector<Frame> frames_;
    std::string syntax_error_;
};

}  // namespace

// ---- Context ----

void Context::add_override(std::string path, std::string text) {
    overrides_.emplace_back(std::move(path), std::move(text));
}

void Context::fail(std::string_view path, std::string_view problem) const {
    std::string message = name_ + ": " + display_path(path) + ": " + std::string(problem);
    for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it) {
        if (is_under(path, it->first)) {
            message += " (set by --set " + it->second + ")";
            break;
        }
    }
    throw Error(one_line(message));
}

void Context::fail_plain(std::string_view problem) const {
    throw Error(one_line(name_ + ": " + std::string(problem)));
}

// ---- paths ----

std::string child_path(std::string_view parent, std::string_view key) {
    if (parent.empty()) return std::string(key);
    std::string path(parent);
    path += '.';
    path += key;
    return path;
}

std::string index_path(std::string_view parent, std::size_t index) {
    return std::string(parent) + "[" + std::to_string(index) + "]";
}

std::string display_path(std::string_view path) {
    return path.empty() ? std::string("(top level)") : std::string(path);
}

// ---- parsing ----

namespace {
// JSON is text: a NUL byte (and whatever follows it) is an error naming its byte.
void refuse_nul(const std::string& text, const std::string& name) {
    if (const auto at = text.find('\0'); at != std::string::npos)
        throw Error(name + ": byte " + std::to_string(at) + ": a NUL byte (a JSON document is text)");
}
}  // namespace

std::optional<Json> try_parse_json(const std::string& text, const std::string& name,
                                   const std::string& base_path) {
    refuse_nul(text, name);
    const Context ctx(name);
    Json root;
    StrictSax sax(root, text, ctx, base_path);
    if (!Json::sax_parse(text, &sax, nlohmann::json::input_format_t::json, true, false)) return std::nullopt;
    return root;
}

Json parse_json(const std::string& text, const std::string& name, const std::string& base_path) {
    refuse_nul(text, name);
    const Context ctx(name);
    Json root;
    StrictSax sax(root, text, ctx, base_path);
    if (!Json::sax_parse(text, &sax, nlohmann::json::input_format_t::json, true, false))
        throw Error(one_line(name + ": " + sax.syntax_error()));
    return root;
}

// ---- descriptions ----

std::string format_number(double x) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
    return std::string(buffer, result.ptr);
}

std::string describe(const Json& value) {
    constexpr std::size_t max_chars = 40;
    switch (value.type()) {
        case Json::value_t::number_float:
            return format_number(value.get<double>());
        case Json::value_t::string: {
            std::string s = value.get<std::string>();
            if (s.size() > max_chars) s = s.substr(0, max_chars) + "...";
            return dump(Json(s));
        }
        case Json::value_t::array: {
            std::string s = dump(value);
            if (s.size() <= max_chars) return s;
            return "an array of " + std::to_string(value.size()) + " elements";
        }
        case Json::value_t::object:
            return value.empty() ? "{}" : "an object";
        default:
            return dump(value);
    }
}

// ---- ranges ----

bool Range::contains(double x) const {
    if (lo && (lo_open ? !(x > *lo) : !(x >= *lo))) return false;
    if (hi && (hi_open ? !(x < *hi) : !(x <= *hi))) return false;
    return true;
}

std::string Range::describe() const {
    if (lo && hi)
        return std::string("in ") + (lo_open ? "(" : "[") + format_number(*lo) + ", " + format_number(*hi) +
               (hi_open ? ")" : "]");
    if (lo) return (lo_open ? "> " : ">= ") + format_number(*lo);
    if (hi) return (hi_open ? "< " : "<= ") + format_number(*hi);
    return "";
}

// ---- single values ----

namespace {

std::string expected(std::string_view what, const Range& range) {
    const std::string r = range.describe();
    return "expected " + std::string(what) + (r.empty() ? "" : " " + r);
}

}  // namespace

double read_number(const Json& v, const std::string& path, const Context& ctx, const Range& range) {
    if (!v.is_number()) ctx.fail(path, expected("a number", range) + ", got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) ctx.fail(path, expected("a finite number", range) + ", got " + describe(v));
    if (!range.contains(x)) ctx.fail(path, expected("a number", range) + ", got " + describe(v));
    return x;
}

std::int64_t read_integer(const Json& v, const std::string& path, const Context& ctx, const Range& range) {
    const auto wrong = [&] { ctx.fail(path, expected("an integer", range) + ", got " + describe(v)); };
    std::int64_t n = 0;
    if (v.is_number_unsigned()) {
        const auto u = v.get<std::uint64_t>();
        if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) wrong();
        n = static_cast<std::int64_t>(u);
    } else if (v.is_number_integer()) {
        n = v.get<std::int64_t>();
    } else if (v.is_number_float()) {
        // JSON has one number type: 512.0 or 5.12e2 is the integer 512; 2.5 is not an integer.
        const double x = v.get<double>();
        if (!std::isfinite(x) || x != std::floor(x) || std::fabs(x) >= 9.2e18) wrong();
        n = static_cast<std::int64_t>(x);
    } else {
        wrong();
    }
    if (!range.contains(static_cast<double>(n))) wrong();
    return n;
}

std::string read_string(const Json& v, const std::string& path, const Context& ctx) {
    if (!v.is_string()) ctx.fail(path, "expected a string, got " + describe(v));
    return v.get<std::string>();
}

bool read_boolean(const Json& v, const std::string& path, const Context& ctx) {
    if (!v.is_boolean()) ctx.fail(path, "expected true or false, got " + describe(v));
    return v.get<bool>();
}

std::vector<double> read_numbers(const Json& v, const std::string& path, const Context& ctx,
                                 std::size_t count, const Range& range) {
    if (!v.is_array() || v.size() != count) {
        const std::string r = range.describe();
        ctx.fail(path, "expected an array of " + std::to_string(count) + " numbers" + (r.empty() ? "" : " " + r) +
                           ", got " + describe(v));
    }
    std::vector<double> out;
    out.reserve(count);
    for (std::size_t i = 0; i < count; ++i) out.push_back(read_number(v[i], index_path(path, i), ctx, range));
    return out;
}

glm::dvec3 read_vec3(const Json& v, const std::string& path, const Context& ctx, const Range& range) {
    const std::vector<double> x = read_numbers(v, path, ctx, 3, range);
    return {x[0], x[1], x[2]};
}

std::size_t read_array_size(const Json& v, const std::string& path, const Context& ctx) {
    if (!v.is_array()) ctx.fail(path, "expected an array, got " + describe(v));
    return v.size();
}

const Json& element(const Json& array, std::size_t index) { return array[index]; }

// ---- ObjectReader ----

ObjectReader::ObjectReader(const Json& object, std::string path, const Context& ctx)
    : object_(object), path_(std::move(path)), ctx_(ctx) {
    if (!object_.is_object()) ctx_.fail(path_, "expected an object, got " + describe(object_));
}

bool ObjectReader::has(std::string_view key) const { return object_.contains(std::string(key)); }

void ObjectReader::mark(std::string_view key) {
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.emplace_back(key);
}

void ObjectReader::allow(std::initializer_list<std::string_view> keys, std::string_view what) {
    for (const std::string_view k : keys) mark(k);
    finish(what);
}

void ObjectReader::finish(std::string_view what) const {
    for (const auto& item : object_.items()) {
        if (std::find(known_.begin(), known_.end(), item.key()) != known_.end()) continue;
        std::string problem = "unknown key";
        if (!what.empty()) problem += " " + std::string(what);
        if (known_.empty()) {
            problem += " (expected no keys)";
        } else {
            problem += " (expected one of: ";
            for (std::size_t i = 0; i < known_.size(); ++i) problem += (i ? ", " : "") + known_[i];
            problem += ")";
        }
        fail(item.key(), problem);
    }
}

const Json* ObjectReader::find(std::string_view key) {
    mark(key);
    const auto it = object_.find(std::string(key));
    return it == object_.end() ? nullptr : &*it;
}

const Json& ObjectReader::required(std::string_view key) {
    const Json* v = find(key);
    if (!v) fail(key, "required");
    return *v;
}

void ObjectReader::reject(std::string_view key, std::string_view problem) {
    if (find(key)) fail(key, problem);
}

void ObjectReader::fail(std::string_view key, std::string_view problem) const { ctx_.fail(path(key), problem); }

void ObjectReader::fail_here(std::string_view problem) const { ctx_.fail(path_, problem); }

double ObjectReader::number(std::string_view key, double fallback, const Range& range) {
    return optional_number(key, range).value_or(fallback);
}

std::optional<double> ObjectReader::optional_number(std::string_view key, const Range& range) {
    const Json* v = find(key);
    if (!v) return std::nullopt;
    return read_number(*v, path(key), ctx_, range);
}

std::int64_t ObjectReader::integer(std::string_view key, std::int64_t fallback, const Range& range) {
    const Json* v = find(key);
    return v ? read_integer(*v, path(key), ctx_, range) : fallback;
}

std::string ObjectReader::string(std::string_view key, std::string_view fallback) {
    return optional_string(key).value_or(std::string(fallback));
}

std::optional<std::string> ObjectReader::optional_string(std::string_view key) {
    const Json* v = find(key);
    if (!v) return std::nullopt;
    return read_string(*v, path(key), ctx_);
}

bool ObjectReader::boolean(std::string_view key, bool fallback) {
    const Json* v = find(key);
    return v ? read_boolean(*v, path(key), ctx_) : fallback;
}

glm::dvec3 ObjectReader::vec3(std::string_view key, const glm::dvec3& fallback, const Range& range) {
    return optional_vec3(key, range).value_or(fallback);
}

std::optional<glm::dvec3> ObjectReader::optional_vec3(std::string_view key, const Range& range) {
    const Json* v = find(key);
    if (!v) return std::nullopt;
    return read_vec3(*v, path(key), ctx_, range);
}

void ObjectReader::fail_choice(std::string_view key, const std::string& got,
                               const std::vector<std::string_view>& options,
                               std::initializer_list<std::string_view> planned) const {
    std::string list;
    for (std::size_t i = 0; i < options.size(); ++i) list += (i ? ", \"" : "\"") + std::string(options[i]) + "\"";
    if (std::find(planned.begin(), planned.end(), got) != planned.end())
        fail(key, "\"" + got + "\" is not implemented yet (implemented: " + list + ")");
    fail(key, "expected one of " + list + ", got " + describe(Json(got)));
}

}  // namespace volref::json_reader
