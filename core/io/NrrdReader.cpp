#include "core/io/NrrdReader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/io/ByteDecoding.h"
#include "core/io/VolumeLayout.h"

namespace volref {

namespace {

// ---- text helpers ----

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

// Lower case, surrounding white space removed and inner runs of white space made one space, so that
// "Unsigned  Char" matches "unsigned char".
std::string normalized(std::string_view s) {
    std::string out;
    for (char c : trim(s)) {
        if (is_space(c)) {
            if (out.back() != ' ') out += ' ';
        } else {
            out += (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c;
        }
    }
    return out;
}

std::vector<std::string_view> split_whitespace(std::string_view s) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && is_space(s[i])) ++i;
        const std::size_t start = i;
        while (i < s.size() && !is_space(s[i])) ++i;
        if (i > start) words.push_back(s.substr(start, i - start));
    }
    return words;
}

// A whole string as a number, in the C locale: an optional sign, then decimal or exponent notation,
// "nan" or "inf". Returns nullopt for anything else, including numbers beyond double's range.
std::optional<double> parse_double(std::string_view s) {
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    if (s.empty() || s.front() == '+' || (s.size() > 1 && s[0] == '-' && s[1] == '+')) return std::nullopt;
    double value = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return value;
}

// A whole string as a decimal integer with an optional sign.
std::optional<std::int64_t> parse_int(std::string_view s) {
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    if (s.empty() || s.front() == '+') return std::nullopt;
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return value;
}

// "(x,y,z)" (any number of components, white space allowed around them) as its components.
std::optional<std::vector<double>> parse_vector(std::string_view s) {
    s = trim(s);
    if (s.size() < 2 || s.front() != '(' || s.back() != ')') return std::nullopt;
    s = s.substr(1, s.size() - 2);
    std::vector<double> components;
    for (;;) {
        const std::size_t comma = s.find(',');
        const auto value = parse_double(trim(s.substr(0, comma)));
        if (!value) return std::nullopt;
        components.push_back(*value);
        if (comma == std::string_view::npos) return components;
        s.remove_prefix(comma + 1);
    }
}

// The words of a `space directions` value: parenthesised vectors (which may contain spaces) and
// bare words such as "none".
std::optional<std::vector<std::string_view>> split_vectors(std::string_view s) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < s.size()) {
        if (is_space(s[i])) {
            ++i;
            continue;
        }
        std::size_t end = i;
        if (s[i] == '(') {
            end = s.find(')', i);
            if (end == std::string_view::npos) return std::nullopt;
            ++end;
        } else {
            while (end < s.size() && !is_space(s[end])) ++end;
        }
        words.push_back(s.substr(i, end - i));
        i = end;
    }
    return words;
}

// ---- the header ----

// A field's value (white space trimmed) and its line in the file (the magic is line 1).
struct Field {
    std::string value;
    int line = 0;
};

struct NrrdHeader {
    std::map<std::string, Field> fields;     // by canonical field name
    std::optional<std::size_t> data_offset;  // start of attached data, when a blank line ended the header
};

// Every field identifier of NRRD0005, as teem spells them (with and without inner spaces), mapped to
// its canonical name.
const std::map<std::string, std::string, std::less<>>& field_names() {
    static const std::map<std::string, std::string, std::less<>> kNames = [] {
        std::map<std::string, std::string, std::less<>> names;
        // clang-format off
        for (const char* name :
             {"content", "number", "type", "block size", "dimension", "space", "space dimension", "sizes",
              "spacings", "thicknesses", "axis mins", "axis maxs", "space directions", "centers", "kinds",
              "labels", "units", "min", "max", "old min", "old max", "endian", "encoding", "line skip",
              "byte skip", "sample units", "space units", "space origin", "measurement frame", "data file"}) {
            // clang-format on
            std::string squeezed;
            for (const char* c = name; *c; ++c)
                if (*c != ' ') squeezed += *c;
            names[name] = name;
            names[squeezed] = name;
        }
        names["centerings"] = "centers";
        return names;
    }();
    return kNames;
}

// Adds one header line that is not the magic and not blank: a comment ("#..."), a key/value pair
// ("key:=value", ignored) or a field ("field: value").
void parse_header_line(std::string_view line, int line_no, NrrdHeader& header, const std::string& where) {
    if (line.front() == '#') return;
    const std::string at = where + ": line " + std::to_string(line_no) + ": ";
    const std::size_t colon = line.find(':');
    const bool key_value_sep =
        colon != std::string_view::npos && colon + 1 < line.size() && line[colon + 1] == '=';
    const auto known = colon == std::string_view::npos
                           ? field_names().end()
                           : field_names().find(normalized(line.substr(0, colon)));
    if (known == field_names().end() || key_value_sep) {
        if (line.find(":=") != std::string_view::npos) return;  // a key/value pair: free-form, ignored
        if (colon == std::string_view::npos)
            throw Error(at + "expected 'field: value', 'key:=value' or a '#' comment, got " +
                        io::quoted(line));
        throw Error(at + "unknown field " + io::quoted(trim(line.substr(0, colon))));
    }
    const std::string& name = known->second;
    if (auto it = header.fields.find(name); it != header.fields.end())
        throw Error(at + "field '" + name + "' given twice (first on line " +
                    std::to_string(it->second.line) + ")");
    header.fields[name] = Field{std::string(trim(line.substr(colon + 1))), line_no};
}

// The header of a NRRD file: the magic line, then lines up to the first blank line (after which
// attached data begins) or the end of the file (a detached header).
NrrdHeader parse_header(std::string_view file, const std::string& where) {
    std::size_t eol = file.find('\n');
    const std::string_view first = file.substr(0, eol);
    const std::string_view magic = trim(first);
    if (magic.size() != 8 || magic.substr(0, 7) != "NRRD000" || magic[7] < '1' || magic[7] > '5')
        throw Error(where + ": not a NRRD file: the first line is " + io::quoted(first, 32) +
                    ", expected the magic NRRD0001 to NRRD0005");
    NrrdHeader header;
    std::size_t pos = eol == std::string_view::npos ? file.size() : eol + 1;
    int line_no = 1;
    while (pos < file.size()) {
        ++line_no;
        eol = file.find('\n', pos);
        std::string_view line =
            file.substr(pos, eol == std::string_view::npos ? std::string_view::npos : eol - pos);
        pos = eol == std::string_view::npos ? file.size() : eol + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (line.empty()) {
            header.data_offset = pos;
            break;
        }
        parse_header_line(line, line_no, header, where);
    }
    return header;
}

// Read access to the fields, with messages "PATH: line N: FIELD: PROBLEM".
class Fields {
public:
    Fields(const NrrdHeader& header, const std::string& where) : header_(header), where_(where) {}

    const Field* find(const std::string& name) const {
        auto it = header_.fields.find(name);
        return it == header_.fields.end() ? nullptr : &it->second;
    }
    const Field& require(const std::string& name) const {
        if (const Field* f = find(name)) return *f;
        throw Error(where_ + ": missing required field '" + name + "'");
    }
    [[noreturn]] void fail(const std::string& name, const std::string& problem) const {
        throw Error(where_ + ": line " + std::to_string(require(name).line) + ": " + name + ": " + problem);
    }
    const std::string& where() const { return where_; }

private:
    const NrrdHeader& header_;
    const std::string& where_;
};

// ---- the fields volref uses ----

// `dimension`: the number of axes, 1 to 3 here (missing axes are padded with size 1).
int parse_dimension(const Fields& fields) {
    const auto d = parse_int(fields.require("dimension").value);
    if (!d)
        fields.fail("dimension", "expected an integer, got " + io::quoted(fields.require("dimension").value));
    if (*d < 1 || *d > 3)
        fields.fail("dimension", std::to_string(*d) + " axes are not supported (volref reads 1 to 3 axes)");
    return int(*d);
}

// `type`: every spelling teem accepts for the 8 supported types.
ScalarType parse_type(const Fields& fields) {
    // clang-format off
    static const std::pair<const char*, ScalarType> kTypes[] = {
        {"uchar", ScalarType::U8},          {"unsigned char", ScalarType::U8},
        {"uint8", ScalarType::U8},          {"uint8_t", ScalarType::U8},
        {"signed char", ScalarType::I8},    {"int8", ScalarType::I8},
        {"int8_t", ScalarType::I8},         {"short", ScalarType::I16},
        {"short int", ScalarType::I16},     {"signed short", ScalarType::I16},
        {"signed short int", ScalarType::I16}, {"int16", ScalarType::I16},
        {"int16_t", ScalarType::I16},       {"ushort", ScalarType::U16},
        {"unsigned short", ScalarType::U16}, {"unsigned short int", ScalarType::U16},
        {"uint16", ScalarType::U16},        {"uint16_t", ScalarType::U16},
        {"int", ScalarType::I32},           {"signed int", ScalarType::I32},
        {"int32", ScalarType::I32},         {"int32_t", ScalarType::I32},
        {"uint", ScalarType::U32},          {"unsigned int", ScalarType::U32},
        {"uint32", ScalarType::U32},        {"uint32_t", ScalarType::U32},
        {"float", ScalarType::F32},         {"double", ScalarType::F64},
    };
    // clang-format on
    // Types NRRD has but Volume does not hold.
    static const char* const kUnsupported[] = {
        "longlong", "long long", "long long int", "signed long long",   "signed long long int",
        "int64",    "int64_t",   "ulonglong",     "unsigned long long", "unsigned long long int",
        "uint64",   "uint64_t",  "block"};
    const std::string& value = fields.require("type").value;
    const std::string name = normalized(value);
    for (const auto& [alias, type] : kTypes)
        if (name == alias) return type;
    for (const char* alias : kUnsupported)
        if (name == alias)
            fields.fail("type",
                        "type " + io::quoted(value) +
                            " is not supported (volref reads 8-, 16- and 32-bit integers, float and double)");
    fields.fail("type", "unknown type " + io::quoted(value));
}

// `sizes`: one integer per axis; axes beyond `dimension` get size 1. Sizes < 1 are caught later by
// checked_voxel_count.
std::array<std::int64_t, 3> parse_sizes(const Fields& fields, int dimension) {
    const std::string& value = fields.require("sizes").value;
    const auto words = split_whitespace(value);
    std::array<std::int64_t, 3> dims{1, 1, 1};
    const std::string expected = "expected " + std::to_string(dimension) + " integers (one per axis), got ";
    if (words.size() != std::size_t(dimension)) fields.fail("sizes", expected + io::quoted(value));
    for (int a = 0; a < dimension; ++a) {
        const auto size = parse_int(words[a]);
        if (!size) fields.fail("sizes", expected + io::quoted(value));
        dims[a] = *size;
    }
    return dims;
}

enum class Encoding { Raw, Gzip, Ascii };

// `encoding`: raw, gzip (alias gz), or ascii (aliases text, txt).
Encoding parse_encoding(const Fields& fields) {
    const std::string& value = fields.require("encoding").value;
    const std::string name = normalized(value);
    if (name == "raw") return Encoding::Raw;
    if (name == "gzip" || name == "gz") return Encoding::Gzip;
    if (name == "ascii" || name == "text" || name == "txt") return Encoding::Ascii;
    if (name == "hex" || name == "bzip2" || name == "bz2" || name == "zrl")
        fields.fail("encoding",
                    "encoding " + io::quoted(value) + " is not supported (volref reads raw, gzip and ascii)");
    fields.fail("encoding", "unknown encoding " + io::quoted(value) + " (expected raw, gzip or ascii)");
}

// `endian`: little or big; absent is nullopt.
std::optional<std::endian> parse_endian(const Fields& fields) {
    const Field* f = fields.find("endian");
    if (!f) return std::nullopt;
    const std::string name = normalized(f->value);
    if (name == "little") return std::endian::little;
    if (name == "big") return std::endian::big;
    fields.fail("endian", "expected little or big, got " + io::quoted(f->value));
}

// `spacings`: one number per axis, each > 0 and finite, or nan for "unknown" (read as 1 here).
// Returns nullopt entries for the nan ones.
std::array<std::optional<double>, 3> parse_spacings(const Fields& fields, int dimension) {
    const std::string& value = fields.require("spacings").value;
    const auto words = split_whitespace(value);
    if (words.size() != std::size_t(dimension))
        fields.fail("spacings", "expected " + std::to_string(dimension) + " numbers (one per axis), got " +
                                    io::quoted(value));
    std::array<std::optional<double>, 3> spacings;
    for (int a = 0; a < dimension; ++a) {
        const auto s = parse_double(words[a]);
        if (!s)
            fields.fail("spacings",
                        "axis " + std::to_string(a) + ": expected a number, got " + io::quoted(words[a]));
        if (std::isnan(*s)) continue;
        if (!(*s > 0.0) || !std::isfinite(*s))
            fields.fail("spacings", "axis " + std::to_string(a) + ": spacing must be finite and > 0, got " +
                                        io::quoted(words[a]));
        spacings[a] = *s;
    }
    return spacings;
}

// "(x,y,z)" with each number in its shortest round-trip form, for messages.
std::string vector_text(const std::vector<double>& v) {
    std::string s = "(";
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (i > 0) s += ',';
        char buf[32];
        const auto end = std::to_chars(buf, buf + sizeof(buf), v[i]).ptr;
        s.append(buf, end);
    }
    s += ')';
    return s;
}

// `space directions`: one vector per axis. volref supports only axis-aligned, unflipped grids: the
// k-th vector's one non-zero component is on world axis k and positive; it is that axis's spacing.
// Returns the spacings and the space dimension (the vectors' length).
std::pair<glm::dvec3, std::size_t> parse_space_directions(const Fields& fields, int dimension) {
    const std::string& value = fields.require("space directions").value;
    const auto words = split_vectors(value);
    if (!words || words->size() != std::size_t(dimension))
        fields.fail("space directions", "expected " + std::to_string(dimension) +
                                            " vectors like (1,0,0) (one per axis), got " + io::quoted(value));
    glm::dvec3 spacing{1.0};
    std::size_t space_dim = 0;
    for (int a = 0; a < dimension; ++a) {
        const std::string axis = "axis " + std::to_string(a) + ": ";
        const std::string_view word = (*words)[a];
        if (normalized(word) == "none")
            fields.fail("space directions", axis +
                                                "'none' (a non-spatial axis) is not supported: volref reads "
                                                "scalar volumes, so every axis needs a direction");
        const auto v = parse_vector(word);
        if (!v)
            fields.fail("space directions", axis + "expected a vector like (1,0,0), got " + io::quoted(word));
        if (a == 0) space_dim = v->size();
        if (v->size() != space_dim || space_dim > 3)
            fields.fail("space directions",
                        axis + "vectors must all have the same 1 to 3 components, got " + io::quoted(value));
        for (double c : *v)
            if (!std::isfinite(c))
                fields.fail("space directions", axis + "non-finite component in " + vector_text(*v));
        int nonzero = 0;
        for (double c : *v) nonzero += c != 0.0;
        const bool aligned = nonzero == 1 && std::size_t(a) < v->size() && (*v)[a] > 0.0;
        if (!aligned)
            fields.fail("space directions",
                        axis + vector_text(*v) +
                            ": non-axis-aligned or flipped directions are not supported yet "
                            "(axis k needs a positive component on world axis k only)");
        spacing[a] = (*v)[a];
    }
    return {spacing, space_dim};
}

// The voxel spacing: from `space directions`, else `spacings` (nan entries read as 1), else 1.
glm::dvec3 parse_spacing(const Fields& fields, int dimension) {
    std::array<std::optional<double>, 3> spacings;
    if (fields.find("spacings")) spacings = parse_spacings(fields, dimension);
    if (fields.find("space directions")) {
        for (const auto& s : spacings)
            if (s)
                fields.fail("spacings",
                            "give either spacings or space directions, not both (a spacing with a "
                            "space direction must be nan)");
        return parse_space_directions(fields, dimension).first;
    }
    glm::dvec3 spacing{1.0};
    for (int a = 0; a < 3; ++a) spacing[a] = spacings[a].value_or(1.0);
    return spacing;
}

// `space origin`: the world position of the first sample, "(x,y,z)" with as many components as the
// space directions (1 to 3; missing ones are 0). Absent means the origin is 0.
glm::dvec3 parse_origin(const Fields& fields, int dimension) {
    const Field* f = fields.find("space origin");
    if (!f) return glm::dvec3(0.0);
    const auto v = parse_vector(f->value);
    if (!v || v->empty() || v->size() > 3)
        fields.fail("space origin",
                    "expected a vector of 1 to 3 numbers like (0,0,0), got " + io::quoted(f->value));
    if (fields.find("space directions")) {
        const std::size_t space_dim = parse_space_directions(fields, dimension).second;
        if (v->size() != space_dim)
            fields.fail("space origin", "expected " + std::to_string(space_dim) +
                                            " components (as in space directions), got " +
                                            io::quoted(f->value));
    }
    glm::dvec3 origin{0.0};
    for (std::size_t i = 0; i < v->size(); ++i) {
        if (!std::isfinite((*v)[i]))
            fields.fail("space origin", "non-finite component in " + io::quoted(f->value));
        origin[int(i)] = (*v)[i];
    }
    return origin;
}

// An optional integer field >= `min` (`line skip`, `byte skip`), 0 when absent.
std::int64_t parse_skip(const Fields& fields, const std::string& name, std::int64_t min) {
    const Field* f = fields.find(name);
    if (!f) return 0;
    const auto n = parse_int(f->value);
    if (!n || *n < min)
        fields.fail(name, "expected an integer >= " + std::to_string(min) + ", got " + io::quoted(f->value));
    return *n;
}

// `data file`: one file, relative to the header's folder unless absolute. The multi-file forms
// ("LIST" and "FORMAT MIN MAX STEP [SUBDIM]") are not supported.
std::filesystem::path parse_data_file(const Fields& fields, const std::filesystem::path& header_path) {
    const std::string& value = fields.require("data file").value;
    const auto words = split_whitespace(value);
    const bool list = !words.empty() && words[0] == "LIST";
    const bool pattern = (words.size() == 4 || words.size() == 5) &&
                         words[0].find('%') != std::string_view::npos && parse_int(words[1]) &&
                         parse_int(words[2]) && parse_int(words[3]);
    if (list || pattern) fields.fail("data file", "several data files are not supported (give one file)");
    if (value.empty()) fields.fail("data file", "no file name given");
    return header_path.parent_path() / value;
}

// ---- the data ----

// `region` after its first `line_skip` lines.
std::string_view skip_lines(std::string_view region, std::int64_t line_skip, const std::string& where) {
    for (std::int64_t n = 0; n < line_skip; ++n) {
        const std::size_t eol = region.find('\n');
        if (eol == std::string_view::npos)
            throw Error(where + ": line skip " + std::to_string(line_skip) +
                        " goes past the end of the data (" + std::to_string(n) + " lines found)");
        region.remove_prefix(eol + 1);
    }
    return region;
}

// One ascii sample as stored in `type`: integer types need an integer in the type's range; float
// values are rounded to float, as a float file would hold them.
double ascii_sample(std::string_view word, ScalarType type, std::size_t index, const std::string& where) {
    const std::string at = where + ": ascii sample " + std::to_string(index) + ": ";
    const auto v = parse_double(word);
    if (!v) throw Error(at + io::quoted(word) + " is not a number");
    if (scalar_type_is_integer(type)) {
        const auto [lo, hi] = scalar_type_range(type);
        if (!(*v >= lo && *v <= hi && std::floor(*v) == *v))
            throw Error(at + io::quoted(word) + " is not an integer in the range of " +
                        scalar_type_name(type));
        return *v;
    }
    if (type == ScalarType::F32) {
        if (std::isfinite(*v) && std::fabs(*v) > double(std::numeric_limits<float>::max()))
            throw Error(at + io::quoted(word) + " is out of the range of f32");
        return double(float(*v));
    }
    return *v;
}

// The ascii encoding: `count` numbers separated by white space, after `byte_skip` bytes.
std::vector<double> parse_ascii(std::string_view region, std::int64_t byte_skip, ScalarType type,
                                std::size_t count, const std::string& where) {
    region.remove_prefix(std::min<std::uint64_t>(region.size(), std::uint64_t(byte_skip)));
    std::vector<double> values;
    values.reserve(count);
    std::size_t i = 0;
    while (i < region.size()) {
        while (i < region.size() && is_space(region[i])) ++i;
        const std::size_t start = i;
        while (i < region.size() && !is_space(region[i])) ++i;
        if (i == start) break;
        if (values.size() == count) throw Error(io::too_long_message(where, count, "more", "values"));
        if (cancel_polled(std::int64_t(values.size()))) throw_if_cancelled();  // SIGINT / SIGTERM while reading
        values.push_back(ascii_sample(region.substr(start, i - start), type, values.size(), where));
    }
    if (values.size() < count) throw Error(io::truncated_message(where, count, values.size(), "values"));
    return values;
}

struct DataLayout {
    Encoding encoding = Encoding::Raw;
    ScalarType type = ScalarType::U8;
    std::endian endian = std::endian::native;
    std::int64_t line_skip = 0;
    std::int64_t byte_skip = 0;
    std::size_t count = 0;
};

io::BinaryEncoding binary_encoding(const DataLayout& layout) {
    return layout.encoding == Encoding::Gzip ? io::BinaryEncoding::Gzip : io::BinaryEncoding::Raw;
}

// Reads the samples held in `region` (the data file, or what follows an attached header) into the
// volume's typed storage.
void decode_data(Volume& volume, std::string_view region, const DataLayout& layout, const std::string& where) {
    region = skip_lines(region, layout.line_skip, where);
    if (layout.encoding == Encoding::Ascii) {
        io::store_samples(volume, layout.type, parse_ascii(region, layout.byte_skip, layout.type, layout.count, where),
                          where);
        return;
    }
    io::ByteSource source(region);
    io::read_samples(volume, layout.type, layout.endian, source, binary_encoding(layout), layout.byte_skip, where);
}

// Raw and gzip data without line skips are read from the file in pieces, straight into the volume.
bool streamable(const DataLayout& layout) { return layout.encoding != Encoding::Ascii && layout.line_skip == 0; }

// Whether `prefix` (the start of a NRRD file) holds the blank line that ends the header.
bool has_header_end(std::string_view prefix) {
    std::size_t pos = prefix.find('\n');
    while (pos != std::string_view::npos && pos + 1 < prefix.size()) {
        const std::size_t eol = prefix.find('\n', pos + 1);
        if (eol == std::string_view::npos) return false;
        std::string_view line = prefix.substr(pos + 1, eol - pos - 1);
        if (line.empty() || line == "\r") return true;
        pos = eol;
    }
    return false;
}

}  // namespace

namespace {

// The header and what it says about the data, shared by read_nrrd and nrrd_layout.
struct ParsedNrrd {
    std::string file;  // the start of the file (all of it when `whole`)
    bool whole = false;
    NrrdHeader header;
    Volume volume;  // dims, type, spacing, origin; no samples
    DataLayout layout;
    std::optional<std::filesystem::path> data_path;  // a detached header's data file
};

// `limited`: the whole volume is about to be read (its size is checked against the memory limit).
ParsedNrrd parse_nrrd(const std::filesystem::path& path, bool limited) {
    const std::string where = path.string();
    ParsedNrrd p;
    // The header, from the start of the file: a big file's attached data is not read here.
    constexpr std::size_t kPrefix = std::size_t(1) << 20;
    p.file = io::read_file_prefix(path, kPrefix, p.whole);
    if (!p.whole && !has_header_end(p.file)) {
        p.file = io::read_file_bytes(path);
        p.whole = true;
    }
    p.header = parse_header(p.file, where);
    const Fields fields(p.header, where);

    Volume& volume = p.volume;
    const int dimension = parse_dimension(fields);
    volume.type = parse_type(fields);
    volume.dims = parse_sizes(fields, dimension);
    volume.spacing = parse_spacing(fields, dimension);
    volume.origin = parse_origin(fields, dimension);

    DataLayout& layout = p.layout;
    layout.type = volume.type;
    layout.encoding = parse_encoding(fields);
    // The NRRD format requires `endian` whenever byte order matters: multi-byte raw or gzip data.
    const auto endian = parse_endian(fields);
    if (!endian && layout.encoding != Encoding::Ascii && scalar_type_size(volume.type) > 1)
        throw Error(where + ": missing field 'endian' (required for " + scalar_type_name(volume.type) +
                    " data with raw or gzip encoding)");
    layout.endian = endian.value_or(std::endian::native);
    layout.line_skip = parse_skip(fields, "line skip", 0);
    layout.byte_skip = parse_skip(fields, "byte skip", -1);
    if (layout.byte_skip == -1 && layout.encoding != Encoding::Raw)
        fields.fail("byte skip", "-1 (data at the end of the file) is only allowed with raw encoding");
    layout.count = limited ? checked_voxel_count(volume.dims, where, scalar_type_size(volume.type))
                           : checked_voxel_count_unlimited(volume.dims, where, scalar_type_size(volume.type));
    if (fields.find("data file")) p.data_path = parse_data_file(fields, path);
    return p;
}

[[noreturn]] void no_data(const std::string& where) {
    throw Error(where + ": no data: the header has no 'data file' field and no blank line before attached data");
}

}  // namespace

Volume read_nrrd(const std::filesystem::path& path) {
    const std::string where = path.string();
    ParsedNrrd p = parse_nrrd(path, true);
    Volume& volume = p.volume;
    const DataLayout& layout = p.layout;
    if (p.data_path) {
        const std::filesystem::path& data_path = *p.data_path;
        try {
            if (streamable(layout)) {
                io::ByteSource source(data_path, 0, data_path.string());
                io::read_samples(volume, layout.type, layout.endian, source, binary_encoding(layout), layout.byte_skip,
                                 data_path.string());
            } else {
                decode_data(volume, io::read_file_bytes(data_path), layout, data_path.string());
            }
        } catch (const Error& e) {
            throw Error(std::string(e.what()) + " (data file of " + where + ")");
        }
    } else if (p.header.data_offset) {
        if (streamable(layout)) {
            io::ByteSource source(path, *p.header.data_offset, where);
            io::read_samples(volume, layout.type, layout.endian, source, binary_encoding(layout), layout.byte_skip, where);
        } else {
            if (!p.whole) p.file = io::read_file_bytes(path);
            decode_data(volume, std::string_view(p.file).substr(*p.header.data_offset), layout, where);
        }
    } else {
        no_data(where);
    }
    volume.type = layout.type;
    return volume;
}

VolumeLayout nrrd_layout(const std::filesystem::path& path) {
    const std::string where = path.string();
    const ParsedNrrd p = parse_nrrd(path, false);
    const DataLayout& layout = p.layout;
    VolumeLayout out;
    out.dims = p.volume.dims;
    out.origin = p.volume.origin;
    out.spacing = p.volume.spacing;
    out.type = layout.type;
    out.endian = layout.endian;
    std::uint64_t base = 0;
    if (p.data_path) {
        out.data = *p.data_path;
        out.data_where = p.data_path->string() + " (data file of " + where + ")";
    } else if (p.header.data_offset) {
        out.data = path;
        out.data_where = where;
        base = *p.header.data_offset;
    } else {
        no_data(where);
    }
    if (layout.encoding == Encoding::Gzip) out.not_direct = "gzip encoding";
    else if (layout.encoding == Encoding::Ascii) out.not_direct = "ascii encoding";
    else if (layout.line_skip != 0) out.not_direct = "a line skip";
    if (!out.not_direct.empty()) return out;
    if (layout.byte_skip >= 0) {
        out.offset = base + std::uint64_t(layout.byte_skip);
    } else {  // -1: the samples end the file
        out.offset = trailing_samples_offset(out, base, std::uint64_t(layout.count) * scalar_type_size(layout.type));
    }
    return out;
}

}  // namespace volref
