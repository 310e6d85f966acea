#include "geometry/PlyReader.h"

#include <algorithm>
#include <cmath>
#include <bit>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/InputFile.h"
#include "core/Error.h"

namespace volref {

namespace {

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyProperty {
    std::string name;
    bool list = false;
    std::string count_type, type;  // list: count_type then `count` values of type
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

std::size_t type_size(const std::string& t) {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
}

std::vector<std::string> words(const std::string& line) {
    std::vector<std::string> w;
    std::istringstream in(line);
    std::string s;
    while (in >> s) w.push_back(s);
    return w;
}

// Reads one value of type `t` (binary) or one token (ASCII) as double.
class PlyBody {
public:
    PlyBody(const std::string& path, const std::string& bytes, std::size_t offset, PlyFormat format)
        : path_(path), bytes_(bytes), pos_(offset), format_(format) {}

    std::size_t remaining() const { return bytes_.size() - pos_; }

    double value(const std::string& t, const std::string& what) {
        if (format_ == PlyFormat::Ascii) return token(what);
        const std::size_t n = type_size(t);
        if (remaining() < n) throw Error(path_ + ": the PLY data end inside " + what);
        unsigned char b[8];
        std::memcpy(b, bytes_.data() + pos_, n);
        pos_ += n;
        const bool big = format_ == PlyFormat::BinaryBig;
        if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + n);
        if (t == "char" || t == "int8") return double(std::int8_t(b[0]));
        if (t == "uchar" || t == "uint8") return double(b[0]);
        if (n == 2) {
            std::uint16_t u;
            std::memcpy(&u, b, 2);
            return (t == "short" || t == "int16") ? double(std::int16_t(u)) : double(u);
        }
        if (t == "float" || t == "float32") {
            float f;
            std::memcpy(&f, b, 4);
            return double(f);
        }
        if (n == 4) {
            std::uint32_t u;
            std::memcpy(&u, b, 4);
            return (t == "int" || t == "int32") ? double(std::int32_t(u)) : double(u);
        }
        double d;
        std::memcpy(&d, b, 8);
        return d;
    }

private:
    double token(const std::string& what) {
        while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
        std::size_t end = pos_;
        while (end < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[end]))) ++end;
        if (end == pos_) throw Error(path_ + ": the PLY data end inside " + what);
        const std::string tok = bytes_.substr(pos_, std::min<std::size_t>(end - pos_, 64));
        pos_ = end;
        char* stop = nullptr;
        const double v = std::strtod(tok.c_str(), &stop);
        if (stop != tok.c_str() + tok.size()) throw Error(path_ + ": " + what + ": \"" + tok + "\" is not a number");
        return v;
    }
    const std::string& path_;
    const std::string& bytes_;
    std::size_t pos_;
    PlyFormat format_;
};

}  // namespace

TriangleMesh read_ply_mesh(const std::string& path) {
    const std::string bytes = io::read_file_bytes(path);  // a regular file that fits the memory limit

    // Header.
    auto fail = [&](int line, const std::string& why) {
        throw Error(path + ": PLY header line " + std::to_string(line) + ": " + why);
    };
    std::size_t pos = 0;
    int line_no = 0;
    auto next_line = [&]() -> std::string {
        const std::size_t end = bytes.find('\n', pos);
        if (end == std::string::npos || end - pos > 4096) fail(line_no + 1, "no end_header (or a line over 4 KiB)");
        std::string l = bytes.substr(pos, end - pos);
        if (!l.empty() && l.back() == '\r') l.pop_back();
        pos = end + 1;
        ++line_no;
        return l;
    };
    if (next_line() != "ply") fail(1, "expected \"ply\"");
    PlyFormat format = PlyFormat::Ascii;
    bool have_format = false;
    std::vector<PlyElement> elements;
    for (;;) {
        const std::string l = next_line();
        const std::vector<std::string> w = words(l);
        if (w.empty()) fail(line_no, "empty line");
        if (w[0] == "end_header") break;
        if (w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "format") {
            if (have_format || w.size() != 3 || w[2] != "1.0") fail(line_no, "expected one \"format FORMAT 1.0\"");
            if (w[1] == "ascii") format = PlyFormat::Ascii;
            else if (w[1] == "binary_little_endian") format = PlyFormat::BinaryLittle;
            else if (w[1] == "binary_big_endian") format = PlyFormat::BinaryBig;
            else fail(line_no, "unknown format \"" + w[1].substr(0, 32) + "\"");
            have_format = true;
        } else if (w[0] == "element") {
            if (w.size() != 3 || w[2].empty() || w[2].size() > 10 || w[2].find_first_not_of("0123456789") != std::string::npos)
                fail(line_no, "expected \"element NAME COUNT\"");
            for (const PlyElement& e : elements)
                if (e.name == w[1]) fail(line_no, "a second \"" + w[1].substr(0, 32) + "\" element");
            elements.push_back({w[1], std::stoull(w[2]), {}});
        } else if (w[0] == "property") {
            if (elements.empty()) fail(line_no, "a property before any element");
            PlyElement& e = elements.back();
            if (w.size() == 5 && w[1] == "list") {
                const bool ok = e.name == "face" && type_size(w[2]) > 0 && type_size(w[3]) > 0 &&
                                (w[4] == "vertex_indices" || w[4] == "vertex_index") &&
                                std::none_of(e.properties.begin(), e.properties.end(), [](const PlyProperty& p) { return p.list; });
                if (!ok) fail(line_no, "only the face element may have a list property, one: vertex_indices");
                e.properties.push_back({w[4], true, w[2], w[3]});
            } else if (w.size() == 3 && type_size(w[1]) > 0) {
                e.properties.push_back({w[2], false, "", w[1]});
            } else {
                fail(line_no, "expected \"property TYPE NAME\" or \"property list TYPE TYPE vertex_indices\"");
            }
        } else {
            fail(line_no, "unknown keyword \"" + w[0].substr(0, 32) + "\"");
        }
    }
    if (!have_format) fail(2, "no format line");
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    for (const PlyElement& e : elements) {
        if (e.name == "vertex") vertex = &e;
        if (e.name == "face") face = &e;
    }
    auto has = [](const PlyElement* e, const char* n) {
        return e && std::any_of(e->properties.begin(), e->properties.end(), [&](const PlyProperty& p) { return p.name == n; });
    };
    if (!has(vertex, "x") || !has(vertex, "y") || !has(vertex, "z")) fail(line_no, "no vertex element with x, y and z");
    if (!face || std::none_of(face->properties.begin(), face->properties.end(), [](const PlyProperty& p) { return p.list; }))
        fail(line_no, "no face element with a vertex_indices list");

    // Body: every element in header order. A value takes at least 1 byte (binary) or 2 (ASCII: a digit
    // and a separator), so a count the file cannot hold is an error before any allocation.
    PlyBody body(path, bytes, pos, format);
    const std::size_t min_bytes = format == PlyFormat::Ascii ? 2 : 1;
    TriangleMesh mesh;
    for (const PlyElement& e : elements) {
        const std::uint64_t per = std::max<std::uint64_t>(e.properties.size(), 1);
        if (e.count > body.remaining() / (min_bytes * per) + 1)
            throw Error(path + ": the PLY element \"" + e.name + "\" declares " + std::to_string(e.count) +
                        " items, more than the file's data can hold");
        if (&e == vertex) mesh.vertices.reserve(std::size_t(e.count));
        for (std::uint64_t i = 0; i < e.count; ++i) {
            const std::string what = e.name + " " + std::to_string(i);
            glm::dvec3 p(0.0);
            for (const PlyProperty& prop : e.properties) {
                if (!prop.list) {
                    const double v = body.value(prop.type, what);
                    if (&e == vertex) {
                        if (prop.name == "x") p.x = v;
                        if (prop.name == "y") p.y = v;
                        if (prop.name == "z") p.z = v;
                    }
                    continue;
                }
                const double n = body.value(prop.count_type, what);
                // Range first: converting a double beyond 2^64 to an integer is undefined (found by fuzz_ply).
                if (!(n >= 0.0 && n <= double(body.remaining() / min_bytes) && n == std::floor(n)))
                    throw Error(path + ": PLY " + what + ": a list of " + std::to_string(n) + " indices");
                std::vector<std::uint32_t> idx(static_cast<std::size_t>(n));
                for (auto& v : idx) {
                    const double x = body.value(prop.type, what);
                    if (!(x >= 0.0 && x < double(vertex->count) && x == double(std::uint64_t(x))))
                        throw Error(path + ": PLY " + what + " has an invalid vertex index " + std::to_string(x) + " (" +
                                    std::to_string(vertex->count) + " vertices)");
                    v = std::uint32_t(x);
                }
                // A polygon v0 v1 ... v(n-1) becomes the fan (v0, vk, vk+1); fewer than 3 bound nothing.
                for (std::size_t k = 1; k + 1 < idx.size(); ++k) mesh.triangles.push_back({idx[0], idx[k], idx[k + 1]});
            }
            if (&e == vertex) mesh.vertices.push_back(p);
        }
    }
    return mesh;
}

}  // namespace volref
