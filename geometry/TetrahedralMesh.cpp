#include "geometry/TetrahedralMesh.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <string_view>
#include <tuple>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/io/ByteDecoding.h"
#include "core/io/VtkLegacyReader.h"

namespace volref {

namespace {

std::string number(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

std::string point(const glm::dvec3& p) { return "(" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + ")"; }

std::string upper(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
    return out;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

constexpr int kVtkTetra = 10;

const char* vtk_cell_type_name(std::int64_t type) {
    switch (type) {
        case 1: return "VTK_VERTEX";
        case 2: return "VTK_POLY_VERTEX";
        case 3: return "VTK_LINE";
        case 4: return "VTK_POLY_LINE";
        case 5: return "VTK_TRIANGLE";
        case 6: return "VTK_TRIANGLE_STRIP";
        case 7: return "VTK_POLYGON";
        case 8: return "VTK_PIXEL";
        case 9: return "VTK_QUAD";
        case 10: return "VTK_TETRA";
        case 11: return "VTK_VOXEL";
        case 12: return "VTK_HEXAHEDRON";
        case 13: return "VTK_WEDGE";
        case 14: return "VTK_PYRAMID";
        case 24: return "VTK_QUADRATIC_TETRA";
        default: return nullptr;
    }
}

// The text of a VTK legacy file after line 3, read word by word (ASCII) or as blocks of big-endian
// numbers right after a keyword's line (BINARY). Locations: "line L" or "byte B" (from 0).
class Cursor {
public:
    Cursor(std::string_view text, std::size_t pos, std::size_t line, std::string where, bool binary)
        : text_(text), pos_(pos), line_(line), where_(std::move(where)), binary_(binary) {}

    bool binary() const { return binary_; }
    const std::string& path() const { return where_; }

    // The next word, or nullopt at the end of the file.
    std::optional<std::string_view> maybe_word() {
        skip_space();
        if (pos_ == text_.size()) return std::nullopt;
        return take_word();
    }
    // The next word; at the end of the file an Error saying what was `expected`.
    std::string_view word(const std::string& expected) {
        skip_space();
        if (pos_ == text_.size()) throw Error(where_ + ": unexpected end of file: expected " + expected);
        return take_word();
    }
    // A non-negative integer of the header (a count).
    std::uint64_t count(const std::string& what) {
        const std::string_view w = word(what);
        std::uint64_t v = 0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
        if (r.ec != std::errc() || r.ptr != w.data() + w.size() || v > (std::uint64_t(1) << 53))
            fail(what + ": expected an integer >= 0, got " + io::quoted(w));
        return v;
    }
    // An integer of the data (ASCII); `what` names it in an error.
    std::int64_t integer(const std::string& what) {
        const std::string_view w = word(what);
        std::int64_t v = 0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
        if (r.ec != std::errc() || r.ptr != w.data() + w.size()) fail(what + ": expected an integer, got " + io::quoted(w));
        return v;
    }
    // A number of the data (ASCII).
    double real(const std::string& what) {
        const std::string_view w = word(what);
        const auto v = io::parse_number(w);
        if (!v) fail(what + ": expected a number, got " + io::quoted(w));
        if (!std::isfinite(*v)) fail(what + ": " + io::quoted(w) + " is not a finite number");
        return *v;
    }
    // Skips to the end of the current line (before BINARY data, which start on the next one).
    void to_next_line() {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
        if (pos_ < text_.size()) {
            ++pos_;
            ++line_;
        }
    }
    // `bytes` bytes of BINARY data at the current position (after to_next_line); `what` names them in a
    // truncation error. Returns the byte offset of their start.
    std::size_t block(std::uint64_t bytes, const std::string& what) {
        const std::size_t left = text_.size() - pos_;
        if (bytes > left)
            throw Error(io::truncated_message(where_ + ": byte " + std::to_string(pos_) + ": " + what, std::size_t(std::min<std::uint64_t>(bytes, SIZE_MAX)), left));
        const std::size_t start = pos_;
        for (std::size_t i = pos_; i < pos_ + bytes; ++i) line_ += text_[i] == '\n';
        pos_ += std::size_t(bytes);
        return start;
    }
    std::string_view bytes_at(std::size_t offset, std::size_t n) const { return text_.substr(offset, n); }
    // What is left of the file, in bytes (to bound counts before anything is allocated).
    std::size_t left() const { return text_.size() - pos_; }
    // The lines up to and including the next empty one (a METADATA block's end).
    void skip_to_blank_line() {
        to_next_line();
        while (pos_ < text_.size()) {
            std::size_t eol = text_.find('\n', pos_);
            if (eol == std::string_view::npos) eol = text_.size();
            std::string_view line = text_.substr(pos_, eol - pos_);
            const bool blank = std::all_of(line.begin(), line.end(), is_space);
            pos_ = std::min(text_.size(), eol + 1);
            if (eol < text_.size()) ++line_;
            if (blank) return;
        }
    }
    std::size_t word_line() const { return word_line_; }
    // Whether the next word is `keyword` (not case-sensitive); reads nothing.
    bool next_is(std::string_view keyword) const {
        std::size_t p = pos_;
        while (p < text_.size() && is_space(text_[p])) ++p;
        std::size_t e = p;
        while (e < text_.size() && !is_space(text_[e])) ++e;
        return upper(text_.substr(p, e - p)) == keyword;
    }
    // A location: the line of a word (ASCII) or the byte of a value (BINARY).
    std::string describe(std::size_t location) const { return (binary_ ? "byte " : "line ") + std::to_string(location); }
    [[noreturn]] void fail(const std::string& problem) const {
        throw Error(where_ + ": line " + std::to_string(word_line_) + ": " + problem);
    }
    [[noreturn]] void fail_at(const std::string& location, const std::string& problem) const {
        throw Error(where_ + ": " + location + ": " + problem);
    }

private:
    void skip_space() {
        while (pos_ < text_.size() && is_space(text_[pos_])) {
            if (text_[pos_] == '\n') ++line_;
            ++pos_;
        }
    }
    std::string_view take_word() {
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
        word_line_ = line_;
        return text_.substr(start, pos_ - start);
    }

    std::string_view text_;
    std::size_t pos_;
    std::size_t line_;
    std::size_t word_line_ = 0;
    std::string where_;
    bool binary_;
};


// A BINARY number type of the file: its size and whether it is an integer, float or double.
struct BinaryType {
    std::size_t size = 0;
    enum class Kind { Signed, Unsigned, Float } kind = Kind::Signed;
};

std::optional<BinaryType> binary_type(std::string_view name) {
    using K = BinaryType::Kind;
    const std::string t = upper(name);
    if (t == "FLOAT") return BinaryType{4, K::Float};
    if (t == "DOUBLE") return BinaryType{8, K::Float};
    if (t == "CHAR" || t == "VTKTYPEINT8") return BinaryType{1, K::Signed};
    if (t == "UNSIGNED_CHAR" || t == "VTKTYPEUINT8") return BinaryType{1, K::Unsigned};
    if (t == "SHORT" || t == "VTKTYPEINT16") return BinaryType{2, K::Signed};
    if (t == "UNSIGNED_SHORT" || t == "VTKTYPEUINT16") return BinaryType{2, K::Unsigned};
    if (t == "INT" || t == "VTKTYPEINT32") return BinaryType{4, K::Signed};
    if (t == "UNSIGNED_INT" || t == "VTKTYPEUINT32") return BinaryType{4, K::Unsigned};
    if (t == "VTKTYPEINT64" || t == "VTKIDTYPE") return BinaryType{8, K::Signed};
    if (t == "VTKTYPEUINT64") return BinaryType{8, K::Unsigned};
    return std::nullopt;  // "long" (its size is the writer's platform's), "bit", "string", ...
}

std::uint64_t big_endian(std::string_view bytes) {
    std::uint64_t v = 0;
    for (const char c : bytes) v = (v << 8) | static_cast<unsigned char>(c);
    return v;
}

// An integer stored as `t` (big-endian); false if it does not fit int64.
bool binary_integer(std::string_view bytes, const BinaryType& t, std::int64_t& out) {
    const std::uint64_t u = big_endian(bytes);
    if (t.kind == BinaryType::Kind::Unsigned) {
        if (u > std::uint64_t(INT64_MAX)) return false;
        out = std::int64_t(u);
        return true;
    }
    const unsigned bits = unsigned(8 * t.size);
    if (bits == 64) {
        out = std::bit_cast<std::int64_t>(u);
    } else {
        const std::uint64_t sign = std::uint64_t(1) << (bits - 1);
        out = std::int64_t(u & (sign - 1)) - std::int64_t(u & sign);
    }
    return true;
}

double binary_real(std::string_view bytes, const BinaryType& t) {
    const std::uint64_t u = big_endian(bytes);
    if (t.size == 4) return double(std::bit_cast<float>(std::uint32_t(u)));
    return std::bit_cast<double>(u);
}

// Numbers of a section: `n` integers (ASCII words, or BINARY values of type `t` right after the
// keyword's line). `at(i)` receives each value with its location.
template <class F>
void read_integers(Cursor& c, std::uint64_t n, const BinaryType& t, const std::string& what, F&& at) {
    if (c.binary()) {
        c.to_next_line();
        const std::size_t start = c.block(n * t.size, what);
        for (std::uint64_t i = 0; i < n; ++i) {
            const std::size_t offset = start + std::size_t(i) * t.size;
            std::int64_t v = 0;
            if (!binary_integer(c.bytes_at(offset, t.size), t, v))
                c.fail_at(c.describe(offset), what + ": value " + std::to_string(i) + " does not fit a 64-bit integer");
            at(i, v, offset);
        }
    } else {
        for (std::uint64_t i = 0; i < n; ++i) {
            const std::int64_t v = c.integer(what);
            at(i, v, c.word_line());
        }
    }
}

// The counts of a section against what is left of the file (before anything is allocated): ASCII
// numbers take at least 2 bytes each but the last, BINARY ones their size.
void check_fits(Cursor& c, std::uint64_t numbers, std::size_t size, const std::string& what) {
    const double need = c.binary() ? double(numbers) * double(size) : 2.0 * double(numbers) - 1.0;
    if (numbers > 0 && need > double(c.left()))
        c.fail(what + ": " + std::to_string(numbers) + " numbers cannot fit in the " + std::to_string(c.left()) +
               " bytes left in the file");
}

// A FIELD block's arrays (skipped): "FIELD name n", then n times "name components tuples type" and
// the values.
void skip_field(Cursor& c) {
    c.word("the FIELD name");
    const std::uint64_t arrays = c.count("FIELD's array count");
    for (std::uint64_t a = 0; a < arrays; ++a) {
        std::string_view name = c.word("a FIELD array's name");
        if (upper(name) == "METADATA") {
            c.skip_to_blank_line();
            name = c.word("a FIELD array's name");
        }
        const std::uint64_t components = c.count("FIELD array " + io::quoted(name) + "'s components");
        const std::uint64_t tuples = c.count("FIELD array " + io::quoted(name) + "'s tuples");
        const std::string_view type = c.word("FIELD array " + io::quoted(name) + "'s type");
        const auto t = binary_type(type);
        if (!t) c.fail("FIELD array " + io::quoted(name) + ": type " + io::quoted(type) + " is not supported");
        const std::uint64_t n = components * tuples;
        if (components != 0 && n / components != tuples) c.fail("FIELD array " + io::quoted(name) + ": too many values");
        check_fits(c, n, t->size, "FIELD array " + io::quoted(name));
        if (c.binary()) {
            c.to_next_line();
            c.block(n * t->size, "FIELD array " + io::quoted(name));
        } else {
            for (std::uint64_t i = 0; i < n; ++i) (void)c.word("FIELD array " + io::quoted(name) + "'s values");
        }
    }
}

struct Cells {
    std::vector<std::int64_t> offsets{0};  // cell k's points are connectivity[offsets[k] .. offsets[k + 1])
    std::vector<std::int64_t> connectivity;
    std::vector<std::size_t> where;         // each cell's location (Cursor::describe): its record, or its first index
};

// Room for `n` cells of `indices` point indices, against the memory limit first.
void reserve_cells(Cursor& c, std::uint64_t n, std::uint64_t indices, Cells& cells) {
    check_memory(std::size_t(n) * (sizeof(std::int64_t) + sizeof(std::size_t)) + std::size_t(indices) * sizeof(std::int64_t),
                 c.path() + ": CELLS: " + std::to_string(n) + " cells");
    cells.offsets.reserve(std::size_t(n) + 1);
    cells.connectivity.reserve(std::size_t(indices));
    cells.where.reserve(std::size_t(n));
}

// Versions up to 4.2: "CELLS n size", n records "k i0 .. i(k-1)" (size numbers in all).
void read_cell_records(Cursor& c, std::uint64_t n, std::uint64_t size, Cells& cells) {
    if (n > size)
        c.fail("CELLS " + std::to_string(n) + " " + std::to_string(size) + ": " + std::to_string(n) + " records cannot fit in " +
               std::to_string(size) + " numbers");
    check_fits(c, size, 4, "CELLS");
    reserve_cells(c, n, size - n, cells);
    std::uint64_t used = 0, cell = 0;
    std::int64_t pending = 0;  // the points still to read of the current record
    read_integers(c, size, BinaryType{4, BinaryType::Kind::Signed}, "CELLS", [&](std::uint64_t, std::int64_t v, std::size_t at) {
        if (pending == 0) {  // a record's size
            if (cell == n)
                c.fail_at(c.describe(at), "CELLS: the " + std::to_string(n) + " records end before the " + std::to_string(size) +
                                              " numbers CELLS gives");
            if (v < 0) c.fail_at(c.describe(at), "CELLS: cell " + std::to_string(cell) + " has " + std::to_string(v) + " points");
            if (std::uint64_t(v) > size - used - 1)
                c.fail_at(c.describe(at), "CELLS: cell " + std::to_string(cell) + "'s " + std::to_string(v) +
                                              " points run past the " + std::to_string(size) + " numbers CELLS gives");
            cells.where.push_back(at);
            ++cell;
            pending = v;
            if (v == 0) cells.offsets.push_back(std::int64_t(cells.connectivity.size()));
        } else {
            cells.connectivity.push_back(v);
            if (--pending == 0) cells.offsets.push_back(std::int64_t(cells.connectivity.size()));
        }
        ++used;
    });
    if (cell != n)
        c.fail("CELLS: the " + std::to_string(size) + " numbers hold " + std::to_string(cell) + " records, CELLS gives " +
               std::to_string(n));
}

// Version 5.1: "CELLS n_offsets n_connectivity", "OFFSETS type" and the offsets, "CONNECTIVITY type"
// and the point indices.
void read_cell_arrays(Cursor& c, std::uint64_t n_offsets, std::uint64_t n_connectivity, Cells& cells) {
    auto array_type = [&](const char* keyword) {
        const std::string_view k = c.word(keyword);
        if (upper(k) != keyword) c.fail(std::string("expected ") + keyword + ", got " + io::quoted(k));
        const std::string_view type = c.word(std::string(keyword) + "'s type");
        const auto t = binary_type(type);
        if (!t || t->kind == BinaryType::Kind::Float)
            c.fail(std::string(keyword) + ": type " + io::quoted(type) +
                   " is not supported (volref reads vtktypeint64, vtktypeint32 or int)");
        return *t;
    };
    const BinaryType to = array_type("OFFSETS");
    check_fits(c, n_offsets, to.size, "OFFSETS");
    cells.offsets.clear();
    reserve_cells(c, n_offsets, 0, cells);
    read_integers(c, n_offsets, to, "OFFSETS", [&](std::uint64_t i, std::int64_t v, std::size_t at) {
        if (i == 0 && v != 0) c.fail_at(c.describe(at), "OFFSETS: the first offset is " + std::to_string(v) + ", expected 0");
        if (i > 0 && v < cells.offsets.back())
            c.fail_at(c.describe(at), "OFFSETS: offset " + std::to_string(i) + " (" + std::to_string(v) +
                                          ") is less than the one before it (" + std::to_string(cells.offsets.back()) + ")");
        cells.offsets.push_back(v);
    });
    if (n_offsets == 0) cells.offsets.push_back(0);
    if (std::uint64_t(cells.offsets.back()) != n_connectivity)
        c.fail("OFFSETS: the last offset is " + std::to_string(cells.offsets.back()) + ", CELLS gives " +
               std::to_string(n_connectivity) + " indices");
    const BinaryType tc = array_type("CONNECTIVITY");
    const std::size_t keyword_line = c.word_line();
    check_fits(c, n_connectivity, tc.size, "CONNECTIVITY");
    reserve_cells(c, n_offsets, n_connectivity, cells);
    std::size_t cell = 0;
    read_integers(c, n_connectivity, tc, "CONNECTIVITY", [&](std::uint64_t i, std::int64_t v, std::size_t at) {
        while (cell + 1 < cells.offsets.size() && std::uint64_t(cells.offsets[cell]) == i) {
            cells.where.push_back(at);  // cell `cell` starts here (empty cells share the place)
            ++cell;
        }
        cells.connectivity.push_back(v);
    });
    while (cells.where.size() + 1 < cells.offsets.size()) cells.where.push_back(c.binary() ? 0 : keyword_line);
}

// Orients tetrahedron k of `mesh` positively; Error `where` + `what` + "... is degenerate" when it has no volume.
void orient_one(TetrahedralMesh& mesh, std::size_t k, const std::string& where, const std::string& what) {
    auto& t = mesh.tetrahedra[k];
    const glm::dvec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]], &d = mesh.vertices[t[3]];
    const double det = tetrahedron_det(a, b, c, d);
    const double l = std::sqrt(std::max({glm::dot(b - a, b - a), glm::dot(c - a, c - a), glm::dot(d - a, d - a),
                                         glm::dot(c - b, c - b), glm::dot(d - b, d - b), glm::dot(d - c, d - c)}));
    const double bound = conventions::kTetrahedronDegenerateRelative * l * l * l;
    if (!(std::fabs(det) > bound))
        throw Error(where + what + " (points " + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " +
                    std::to_string(t[2]) + ", " + std::to_string(t[3]) + ") is degenerate: |det(b - a, c - a, d - a)| = " +
                    number(std::fabs(det)) + " <= 1e-12 l^3 = " + number(bound) + " (l = " + number(l) +
                    ", its longest edge)");
    if (det < 0) std::swap(t[2], t[3]);
}

void check_vertex(const glm::dvec3& p, const std::string& where) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw Error(where + " is not finite " + point(p));
    // within volref's number range, like every coordinate of a scene (conventions::kMaxMagnitude)
    if (std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > conventions::kMaxMagnitude)
        throw Error(where + " " + point(p) + " is beyond volref's range (|x| <= 1e100)");
}

}  // namespace

double tetrahedron_det(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
    const glm::dvec3 u = b - a, v = c - a, w = d - a;
    return u.x * (v.y * w.z - v.z * w.y) + u.y * (v.z * w.x - v.x * w.z) + u.z * (v.x * w.y - v.y * w.x);
}

TetrahedralMesh read_tetrahedra(const std::string& path) {
    const std::string file = io::read_file_bytes(path);  // a regular file within the memory limit
    const auto [start, binary] = read_vtk_legacy_preamble(file, path);
    Cursor c(file, start, 4, path, binary);

    const std::string_view dataset = c.word("DATASET");
    if (upper(dataset) != "DATASET") c.fail("expected DATASET, got " + io::quoted(dataset));
    const std::string_view kind = c.word("the dataset type");
    if (upper(kind) != "UNSTRUCTURED_GRID")
        c.fail("DATASET " + io::quoted(kind) + " is not a set of tetrahedra (volref reads UNSTRUCTURED_GRID with cell type 10)");

    TetrahedralMesh mesh;
    Cells cells;
    std::map<std::string, std::size_t> seen;  // each section once
    std::uint64_t type_count = 0;
    std::size_t types_line = 0;
    for (;;) {
        const std::optional<std::string_view> w = c.maybe_word();
        if (!w) break;
        const std::string key = upper(*w);
        if (key == "POINT_DATA" || key == "CELL_DATA") break;  // attributes: not read
        if (key == "METADATA") {
            c.skip_to_blank_line();
            continue;
        }
        if (key == "FIELD") {
            skip_field(c);
            continue;
        }
        if (key != "POINTS" && key != "CELLS" && key != "CELL_TYPES")
            c.fail("unknown keyword " + io::quoted(*w) + " (expected POINTS, CELLS, CELL_TYPES, FIELD, POINT_DATA or CELL_DATA)");
        if (const auto it = seen.find(key); it != seen.end())
            c.fail(key + " given twice (first on line " + std::to_string(it->second) + ")");
        seen[key] = c.word_line();
        if (key == "POINTS") {
            const std::uint64_t n = c.count("POINTS");
            const std::string_view type = c.word("the POINTS data type");
            const std::string t = upper(type);
            if (t != "FLOAT" && t != "DOUBLE")
                c.fail("POINTS: type " + io::quoted(type) + " is not supported (volref reads float or double)");
            if (n > std::uint64_t(UINT32_MAX)) c.fail("POINTS: " + std::to_string(n) + " points are more than volref indexes (2^32 - 1)");
            const BinaryType bt = *binary_type(t);
            check_fits(c, 3 * n, bt.size, "POINTS");
            check_memory(std::size_t(n) * sizeof(glm::dvec3), path + ": " + std::to_string(n) + " points");
            mesh.vertices.resize(std::size_t(n));
            if (binary) {
                c.to_next_line();
                const std::size_t at = c.block(3 * n * bt.size, "POINTS");
                for (std::size_t i = 0; i < n; ++i) {
                    glm::dvec3& p = mesh.vertices[i];
                    for (int a = 0; a < 3; ++a) p[a] = binary_real(c.bytes_at(at + (3 * i + std::size_t(a)) * bt.size, bt.size), bt);
                    check_vertex(p, path + ": " + c.describe(at + 3 * i * bt.size) + ": POINTS: point " + std::to_string(i));
                }
            } else {
                for (std::size_t i = 0; i < n; ++i) {
                    glm::dvec3& p = mesh.vertices[i];
                    for (int a = 0; a < 3; ++a) {
                        const double v = c.real("POINTS: point " + std::to_string(i));
                        p[a] = t == "FLOAT" ? double(float(v)) : v;  // as VTK holds a float point
                        if (!std::isfinite(p[a])) c.fail("POINTS: point " + std::to_string(i) + ": " + number(v) + " is out of the range of float");
                    }
                    check_vertex(p, path + ": line " + std::to_string(c.word_line()) + ": POINTS: point " + std::to_string(i));
                }
            }
        } else if (key == "CELLS") {
            const std::uint64_t n = c.count("CELLS");
            const std::uint64_t size = c.count("CELLS size");
            // Version 5.1 names its arrays: the next word is OFFSETS. (The older layout's BINARY records
            // never spell OFFSETS as a whole word: its first 4 bytes are a cell's point count.)
            if (c.next_is("OFFSETS"))
                read_cell_arrays(c, n, size, cells);
            else
                read_cell_records(c, n, size, cells);
        } else {  // CELL_TYPES
            type_count = c.count("CELL_TYPES");
            types_line = c.word_line();
            check_fits(c, type_count, 4, "CELL_TYPES");
            read_integers(c, type_count, BinaryType{4, BinaryType::Kind::Signed}, "CELL_TYPES",
                          [&](std::uint64_t i, std::int64_t v, std::size_t at) {
                              if (v == kVtkTetra) return;
                              const char* name = vtk_cell_type_name(v);
                              c.fail_at(c.describe(at), "CELL_TYPES: cell " + std::to_string(i) + " has type " + std::to_string(v) +
                                                (name ? std::string(" (") + name + ")" : std::string()) +
                                                "; volref reads tetrahedra only (type 10, VTK_TETRA): export the volume's "
                                                "cells alone");
                          });
        }
    }
    for (const char* section : {"POINTS", "CELLS", "CELL_TYPES"})
        if (!seen.count(section))
            throw Error(path + ": no " + section + " section (tetrahedra need POINTS, CELLS and CELL_TYPES)");
    const std::size_t n = cells.offsets.size() - 1;
    if (type_count != n)
        throw Error(path + ": line " + std::to_string(types_line) + ": CELL_TYPES " + std::to_string(type_count) +
                    " does not match the " + std::to_string(n) + " cells of CELLS (line " + std::to_string(seen["CELLS"]) + ")");
    if (n == 0) throw Error(path + ": line " + std::to_string(seen["CELLS"]) + ": CELLS: the file has no tetrahedra");

    // the boundary's memory (conventions::kMeshBytesPerTriangle per face) before it is built.
    check_memory(n * 4 * conventions::kMeshBytesPerTriangle, path + ": " + std::to_string(n) + " tetrahedra");
    const std::size_t nv = mesh.vertices.size();
    mesh.tetrahedra.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::string where = path + ": " + c.describe(cells.where[k]) + ": ";
        const std::int64_t size = cells.offsets[k + 1] - cells.offsets[k];
        if (size != 4)
            throw Error(where + "cell " + std::to_string(k) + " has " + std::to_string(size) +
                        " points; a tetrahedron (type 10) has 4");
        for (int i = 0; i < 4; ++i) {
            const std::int64_t v = cells.connectivity[std::size_t(cells.offsets[k]) + std::size_t(i)];
            if (v < 0 || std::uint64_t(v) >= nv)
                throw Error(where + "cell " + std::to_string(k) + ": point index " + std::to_string(v) + " is not one of the " +
                            std::to_string(nv) + " POINTS" + (nv > 0 ? " (0 to " + std::to_string(nv - 1) + ")" : std::string()));
            mesh.tetrahedra[k][std::size_t(i)] = std::uint32_t(v);
        }
        orient_one(mesh, k, where, "cell " + std::to_string(k));
    }
    return mesh;
}

void orient_tetrahedra(TetrahedralMesh& mesh, const std::string& name) {
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) check_vertex(mesh.vertices[i], name + ": vertex " + std::to_string(i));
    if (mesh.tetrahedra.empty()) throw Error(name + ": no tetrahedra");
    for (std::size_t k = 0; k < mesh.tetrahedra.size(); ++k) {
        for (const auto v : mesh.tetrahedra[k])
            if (v >= mesh.vertices.size())
                throw Error(name + ": tetrahedron " + std::to_string(k) + ": vertex index " + std::to_string(v) + " is not one of the " +
                            std::to_string(mesh.vertices.size()) + " vertices");
        orient_one(mesh, k, name + ": ", "tetrahedron " + std::to_string(k));
    }
}

TetrahedralBoundary tetrahedra_boundary(const TetrahedralMesh& mesh) {
    // Vertices at exactly the same position are one (+0.0 and -0.0 too).
    const std::size_t nv = mesh.vertices.size();
    std::vector<std::uint32_t> order(nv);
    for (std::size_t i = 0; i < nv; ++i) order[i] = std::uint32_t(i);
    auto pos = [&](std::uint32_t i) { return mesh.vertices[i] + glm::dvec3(0.0); };
    auto less = [&](std::uint32_t a, std::uint32_t b) {
        const glm::dvec3 p = pos(a), q = pos(b);
        return std::tie(p.x, p.y, p.z, a) < std::tie(q.x, q.y, q.z, b);
    };
    std::sort(order.begin(), order.end(), less);
    std::vector<std::uint32_t> id(nv, 0);
    TetrahedralBoundary out;
    for (std::size_t k = 0; k < nv; ++k) {
        if (k == 0 || pos(order[k]) != pos(order[k - 1])) out.surface.vertices.push_back(pos(order[k]));
        id[order[k]] = std::uint32_t(out.surface.vertices.size() - 1);
    }

    // Each face, outward for a positive tetrahedron (a, b, c, d): (a, c, b), (a, b, d), (b, c, d), (a, d, c);
    // keyed by its sorted vertices with the sign of its orientation against that order.
    struct Face {
        std::array<std::uint32_t, 3> key;
        int sign;
    };
    std::vector<Face> faces;
    faces.reserve(4 * mesh.tetrahedra.size());
    for (const auto& t0 : mesh.tetrahedra) {
        std::array<std::uint32_t, 4> t{id[t0[0]], id[t0[1]], id[t0[2]], id[t0[3]]};
        if (tetrahedron_det(mesh.vertices[t0[0]], mesh.vertices[t0[1]], mesh.vertices[t0[2]], mesh.vertices[t0[3]]) < 0)
            std::swap(t[2], t[3]);
        const std::array<std::array<std::uint32_t, 3>, 4> fs{{{t[0], t[2], t[1]}, {t[0], t[1], t[3]}, {t[1], t[2], t[3]}, {t[0], t[3], t[2]}}};
        for (auto f : fs) {
            // Sort with a parity count: each swap flips the orientation.
            int sign = 1;
            if (f[0] > f[1]) std::swap(f[0], f[1]), sign = -sign;
            if (f[1] > f[2]) std::swap(f[1], f[2]), sign = -sign;
            if (f[0] > f[1]) std::swap(f[0], f[1]), sign = -sign;
            faces.push_back({f, sign});
        }
    }
    std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) { return x.key < y.key; });
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i;
        int net = 0;
        for (; j < faces.size() && faces[j].key == faces[i].key; ++j) net += faces[j].sign;
        const auto& k = faces[i].key;
        // A face and its reverse cancel; what is left stays (twice if two tetrahedra hold it on one side).
        out.internal_faces += (j - i - std::size_t(std::abs(net))) / 2;
        for (int m = 0; m < std::abs(net); ++m)
            out.surface.triangles.push_back(net > 0 ? std::array<std::uint32_t, 3>{k[0], k[1], k[2]}
                                                    : std::array<std::uint32_t, 3>{k[0], k[2], k[1]});
        i = j;
    }
    merge_coincident_vertices(out.surface);  // drops the interior vertices
    return out;
}

TriangleMesh read_tetrahedral_bounds(const std::string& path) {
    TetrahedralBoundary b = tetrahedra_boundary(read_tetrahedra(path));
    check_closed(b.surface, path, Closedness::Cycle);
    return std::move(b.surface);
}

double tetrahedra_volume(const TetrahedralMesh& mesh) {
    double sum = 0.0;
    for (const auto& t : mesh.tetrahedra)
        sum += std::fabs(tetrahedron_det(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], mesh.vertices[t[3]]));
    return sum / 6.0;
}

}  // namespace volref
