#include "core/io/VtkLegacyReader.h"

#include <cmath>
#include <cstdint>
#include <optional>
#include <map>
#include <string>
#include <string_view>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"

namespace volref {

namespace {

std::string upper(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
    return out;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Words of the file after line 3, with the line each is on.
class Words {
public:
    Words(std::string_view text, std::size_t pos, std::size_t line, std::string where)
        : text_(text), pos_(pos), line_(line), where_(std::move(where)) {}

    // The next word; at the end of the file an Error saying what was `expected`.
    std::string_view next(const std::string& expected) {
        while (pos_ < text_.size() && is_space(text_[pos_])) {
            if (text_[pos_] == '\n') ++line_;
            ++pos_;
        }
        if (pos_ == text_.size()) throw Error(where_ + ": unexpected end of file: expected " + expected);
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
        word_line_ = line_;
        return text_.substr(start, pos_ - start);
    }
    // The next word, or nullopt at the end of the file.
    std::optional<std::string_view> maybe_next() {
        std::size_t p = pos_;
        while (p < text_.size() && is_space(text_[p])) ++p;
        if (p == text_.size()) return std::nullopt;
        return next("");
    }
    std::int64_t integer(const std::string& what, std::int64_t min) {
        const std::string_view w = next(what);
        const auto v = io::parse_number(w);
        if (!v || std::floor(*v) != *v || *v < double(min) || *v > 9.0e18)
            fail(what + ": expected an integer >= " + std::to_string(min) + ", got " + io::quoted(w));
        return static_cast<std::int64_t>(*v);
    }
    double number(const std::string& what, bool positive) {
        const std::string_view w = next(what);
        const auto v = io::parse_number(w);
        if (!v || !std::isfinite(*v) || (positive && !(*v > 0.0)))
            fail(what + ": expected " + (positive ? "a number > 0" : "a finite number") + ", got " + io::quoted(w));
        return *v;
    }
    // The rest of the file after the current line's end (for BINARY data).
    std::string_view after_line_end() {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
        if (pos_ < text_.size()) ++pos_;
        ++line_;
        return text_.substr(pos_);
    }
    std::string_view rest() const { return text_.substr(pos_); }
    std::size_t line() const { return line_; }
    [[noreturn]] void fail(const std::string& problem) const {
        throw Error(where_ + ": line " + std::to_string(word_line_) + ": " + problem);
    }

private:
    std::string_view text_;
    std::size_t pos_;
    std::size_t line_;
    std::size_t word_line_ = 0;
    std::string where_;
};


ScalarType scalar_type(Words& words) {
    const std::string_view w = words.next("the SCALARS data type");
    const std::string t = upper(w);
    if (t == "UNSIGNED_CHAR") return ScalarType::U8;
    if (t == "CHAR") return ScalarType::I8;
    if (t == "UNSIGNED_SHORT") return ScalarType::U16;
    if (t == "SHORT") return ScalarType::I16;
    if (t == "UNSIGNED_INT") return ScalarType::U32;
    if (t == "INT") return ScalarType::I32;
    if (t == "FLOAT") return ScalarType::F32;
    if (t == "DOUBLE") return ScalarType::F64;
    if (t == "BIT" || t == "LONG" || t == "UNSIGNED_LONG" || t == "VTKTYPEINT64" || t == "VTKTYPEUINT64" ||
        t == "VTKIDTYPE")
        words.fail("SCALARS: type " + io::quoted(w) +
                   " is not supported (volref reads unsigned_char, char, unsigned_short, short, unsigned_int, "
                   "int, float, double)");
    words.fail("SCALARS: unknown type " + io::quoted(w));
}

}  // namespace

std::pair<std::size_t, bool> read_vtk_legacy_preamble(std::string_view file, const std::string& where) {
    std::size_t pos = 0;
    std::string_view lines[3];
    for (int n = 0; n < 3; ++n) {
        const std::size_t eol = file.find('\n', pos);
        if (eol == std::string_view::npos)
            throw Error(where + ": truncated header: line " + std::to_string(n + 1) + " has no end");
        std::string_view line = file.substr(pos, eol - pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        lines[n] = line;
        pos = eol + 1;
    }
    if (upper(lines[0]).rfind("# VTK DATAFILE VERSION", 0) != 0)
        throw Error(where + ": not a VTK legacy file: line 1 is " + io::quoted(lines[0]) +
                    ", expected '# vtk DataFile Version x.y'");
    std::string_view mode = lines[2];
    while (!mode.empty() && is_space(mode.back())) mode.remove_suffix(1);
    while (!mode.empty() && is_space(mode.front())) mode.remove_prefix(1);
    const std::string m = upper(mode);
    if (m != "ASCII" && m != "BINARY")
        throw Error(where + ": line 3: expected ASCII or BINARY, got " + io::quoted(lines[2]));
    return {pos, m == "BINARY"};
}

Volume read_vtk_legacy(const std::filesystem::path& path) {
    const std::string where = path.string();
    const std::string file = io::read_file_bytes(path);
    const auto [start, binary] = read_vtk_legacy_preamble(file, where);
    Words words(file, start, 4, where);

    const std::string_view dataset = words.next("DATASET");
    if (upper(dataset) != "DATASET") words.fail("expected DATASET, got " + io::quoted(dataset));
    const std::string_view kind = words.next("the dataset type");
    if (upper(kind) != "STRUCTURED_POINTS")
        words.fail("DATASET " + io::quoted(kind) + " is not supported (volref reads STRUCTURED_POINTS)");

    Volume volume;
    bool have_dims = false;
    std::int64_t point_count = -1;
    std::size_t dims_line = 0;
    std::map<std::string, std::size_t> seen;  // each keyword once: a header that says two things is an error
    for (;;) {
        const std::string_view w = words.next("DIMENSIONS, SPACING, ORIGIN or POINT_DATA");
        const std::string key = upper(w);
        const std::string slot = key == "ASPECT_RATIO" ? "SPACING" : key;  // synonyms
        if (const auto it = seen.find(slot); it != seen.end())
            words.fail(slot + " given twice" + (key != slot ? " (as " + key + ")" : std::string()) + " (first on line " +
                       std::to_string(it->second) + ")");
        seen[slot] = words.line();
        if (key == "DIMENSIONS") {
            for (int a = 0; a < 3; ++a)
                volume.dims[std::size_t(a)] = words.integer("DIMENSIONS", 1);
            have_dims = true;
            dims_line = words.line();
        } else if (key == "SPACING" || key == "ASPECT_RATIO") {
            for (int a = 0; a < 3; ++a) volume.spacing[a] = words.number(key, true);
        } else if (key == "ORIGIN") {
            for (int a = 0; a < 3; ++a) volume.origin[a] = words.number("ORIGIN", false);
        } else if (key == "POINT_DATA") {
            point_count = words.integer("POINT_DATA", 0);
            break;
        } else if (key == "CELL_DATA") {
            words.fail("CELL_DATA is not supported (volref reads point data: POINT_DATA)");
        } else {
            words.fail("unknown keyword " + io::quoted(w) + " (expected DIMENSIONS, SPACING, ORIGIN or POINT_DATA)");
        }
    }
    if (!have_dims) words.fail("POINT_DATA before DIMENSIONS");
    const std::size_t count = checked_voxel_count(volume.dims, where + ": line " + std::to_string(dims_line),
                                                  sizeof(double));
    if (std::uint64_t(point_count) != count)
        words.fail("POINT_DATA " + std::to_string(point_count) + " does not match DIMENSIONS " +
                   std::to_string(volume.dims[0]) + " x " + std::to_string(volume.dims[1]) + " x " +
                   std::to_string(volume.dims[2]) + " = " + std::to_string(count));

    const std::string_view scalars = words.next("SCALARS");
    if (upper(scalars) != "SCALARS")
        words.fail("expected SCALARS after POINT_DATA, got " + io::quoted(scalars) +
                   " (volref reads one scalar attribute)");
    words.next("the SCALARS name");
    const ScalarType type = scalar_type(words);
    // An optional component count, then LOOKUP_TABLE name.
    std::string_view w = words.next("LOOKUP_TABLE");
    if (upper(w) != "LOOKUP_TABLE") {
        const auto components = io::parse_number(w);
        if (!components) words.fail("expected LOOKUP_TABLE or a component count, got " + io::quoted(w));
        if (*components != 1.0)
            words.fail("SCALARS with " + std::string(w) + " components are not supported (volref reads 1)");
        w = words.next("LOOKUP_TABLE");
        if (upper(w) != "LOOKUP_TABLE") words.fail("expected LOOKUP_TABLE, got " + io::quoted(w));
    }
    words.next("the LOOKUP_TABLE name");

    if (binary) {
        // The samples start right after the LOOKUP_TABLE line; anything after them (such as another
        // attribute) is ignored.
        const std::size_t data_line = words.line() + 1;
        const std::string_view data = words.after_line_end();
        const std::size_t expected = count * scalar_type_size(type);
        if (data.size() < expected)
            throw Error(io::truncated_message(where + ": line " + std::to_string(data_line), expected, data.size()));
        io::store_sample_bytes(volume, type, std::endian::big, data.substr(0, expected), where);
    } else {
        // Exactly `count` numbers; a later attribute (a keyword) ends them.
        const std::size_t line = words.line();
        std::string_view text = words.rest();
        // Cut the text at the first word that starts with a letter other than n/i (nan, inf): a keyword.
        std::size_t i = 0;
        while (i < text.size()) {
            while (i < text.size() && is_space(text[i])) ++i;
            if (i == text.size()) break;
            const char c = text[i];
            const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
            if (letter && upper(text.substr(i, 3)) != "NAN" && upper(text.substr(i, 3)) != "INF") {
                text = text.substr(0, i);
                break;
            }
            while (i < text.size() && !is_space(text[i])) ++i;
        }
        io::store_samples(volume, type, io::decode_ascii_samples(text, type, count, where, line), where);
    }
    return volume;
}

}  // namespace volref
