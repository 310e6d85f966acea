#include "geometry/TriangleMesh.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>

#include <glm/common.hpp>
#include <tiny_obj_loader.h>  // TINYOBJLOADER_USE_DOUBLE comes with the tinyobjloader_double target

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/io/ByteDecoding.h"
#include "geometry/PlyReader.h"

namespace volref {

namespace {

std::string number(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

std::string point(const glm::dvec3& p) {
    return "(" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + ")";
}

// The first line of a library's message, without trailing whitespace.
std::string first_line(const std::string& s) {
    std::string line = s.substr(0, s.find('\n'));
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    return line;
}

// What tinyobjloader lets pass, checked on the text first: a vertex coordinate that is not a
// finite number (it reads "nan" or "1e999" as 0 or inf), and a face index that is 0, beyond the vertices
// read so far or does not fit an int (it wraps 99999999999999999999 to a small index). Errors name the line.
void check_obj_text(const std::string& path, std::string_view text) {
    std::size_t line_no = 0, vertices = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_no;
        auto tokens = [&] {
            std::vector<std::string_view> t;
            std::size_t i = 0;
            while (i < line.size()) {
                while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
                std::size_t j = i;
                while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
                if (j > i) t.push_back(line.substr(i, j - i));
                i = j;
            }
            return t;
        }();
        if (tokens.empty()) continue;
        const std::string where = path + ": line " + std::to_string(line_no) + ": ";
        if (tokens[0] == "v") {
            if (tokens.size() < 4) throw Error(where + "a vertex needs 3 coordinates");
            for (std::size_t k = 1; k < 4; ++k) {
                const std::optional<double> v = io::parse_number(tokens[k]);
                if (!v || !std::isfinite(*v))
                    throw Error(where + "vertex coordinate " + io::quoted(tokens[k]) + " is not a finite number");
            }
            ++vertices;
        } else if (tokens[0] == "f" || tokens[0] == "l" || tokens[0] == "p") {
            for (std::size_t k = 1; k < tokens.size(); ++k) {
                const std::string_view idx = tokens[k].substr(0, tokens[k].find('/'));
                long long i = 0;
                const auto r = std::from_chars(idx.data(), idx.data() + idx.size(), i);
                const long long n = static_cast<long long>(vertices);
                if (r.ec != std::errc() || r.ptr != idx.data() + idx.size() || i == 0 || i > n || i < -n)
                    throw Error(where + "face vertex index " + io::quoted(idx) + " is not one of the " + std::to_string(vertices) +
                                " vertices defined before it");
            }
        }
    }
}

TriangleMesh read_obj(const std::string& path) {
    static_assert(sizeof(tinyobj::real_t) == sizeof(double), "tinyobjloader must be its double build");
    const std::string text = io::read_file_bytes(path);  // a regular file that fits the memory limit
    if (text.find('\0') != std::string::npos)
        throw Error(path + ": byte " + std::to_string(text.find('\0')) + ": a NUL byte in an OBJ (text) file");
    check_obj_text(path, text);
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    // From the text, with no material text: tinyobjloader opens no mtllib file (one could be a FIFO or
    // /dev/zero) and volref does not use materials.
    if (!reader.ParseFromString(text, std::string(), config)) {
        const std::string why = first_line(reader.Error());
        throw Error(path + ": cannot read the OBJ file" + (why.empty() ? "" : " (" + why + ")"));
    }
    // tinyobjloader skips faces with invalid vertex indices with only a warning: refuse them.
    const std::string& warn = reader.Warning();
    for (const char* bad : {"invalid vertex index", "Degenerated face"}) {
        if (warn.find(bad) != std::string::npos)
            throw Error(path + ": the OBJ file has a face with fewer than 3 vertices or an invalid vertex index");
    }
    const auto& attrib = reader.GetAttrib();
    TriangleMesh mesh;
    const std::size_t nv = attrib.vertices.size() / 3;
    mesh.vertices.reserve(nv);
    for (std::size_t i = 0; i < nv; ++i)
        mesh.vertices.emplace_back(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    for (const auto& shape : reader.GetShapes()) {
        std::size_t offset = 0;
        for (const auto fv : shape.mesh.num_face_vertices) {
            if (fv != 3) throw Error(path + ": the OBJ file has a face tinyobjloader did not triangulate");
            std::array<std::uint32_t, 3> t{};
            for (int k = 0; k < 3; ++k) {
                const int vi = shape.mesh.indices[offset + std::size_t(k)].vertex_index;
                if (vi < 0 || std::size_t(vi) >= nv)
                    throw Error(path + ": the OBJ file has a face with an invalid vertex index");
                t[std::size_t(k)] = std::uint32_t(vi);
            }
            mesh.triangles.push_back(t);
            offset += fv;
        }
    }
    return mesh;
}

}  // namespace

void merge_coincident_vertices(TriangleMesh& mesh) {
    auto less = [](const glm::dvec3& a, const glm::dvec3& b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    };
    std::map<glm::dvec3, std::uint32_t, decltype(less)> index(less);
    std::vector<std::uint32_t> remap(mesh.vertices.size(), 0);
    std::vector<bool> used(mesh.vertices.size(), false);
    for (const auto& t : mesh.triangles)
        for (const auto v : t) {
            if (v >= mesh.vertices.size()) throw Error("merge_coincident_vertices: a triangle refers to a missing vertex");
            used[v] = true;
        }
    std::vector<glm::dvec3> merged;
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        if (!used[i]) continue;
        // +0.0 and -0.0 are the same position.
        const glm::dvec3 p = mesh.vertices[i] + glm::dvec3(0.0);
        const auto [it, inserted] = index.emplace(p, std::uint32_t(merged.size()));
        if (inserted) merged.push_back(p);
        remap[i] = it->second;
    }
    for (auto& t : mesh.triangles)
        for (auto& v : t) v = remap[v];
    mesh.vertices = std::move(merged);
}

TriangleMesh read_mesh(const std::string& path) {
    io::check_input_file(path, path);  // a FIFO or a device: refused by type, before its name is read
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    TriangleMesh mesh;
    if (ext == ".obj")
        mesh = read_obj(path);
    else if (ext == ".ply")
        mesh = read_ply_mesh(path);
    else
        throw Error(path + ": unknown mesh format '" + ext + "' (expected .obj or .ply)");
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const glm::dvec3& p = mesh.vertices[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error(path + ": vertex " + std::to_string(i) + " is not finite");
        // within volref's number range, like every coordinate of a scene (conventions::kMaxMagnitude)
        if (std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > conventions::kMaxMagnitude)
            throw Error(path + ": vertex " + std::to_string(i) + " " + point(p) + " is beyond volref's range (|x| <= 1e100)");
    }
    merge_coincident_vertices(mesh);
    return mesh;
}

double signed_volume(const TriangleMesh& mesh) {
    if (mesh.vertices.empty()) return 0.0;
    glm::dvec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
    for (const auto& p : mesh.vertices) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::dvec3 r = 0.5 * (lo + hi);
    double sum = 0.0;
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a = mesh.vertices[t[0]] - r, b = mesh.vertices[t[1]] - r, c = mesh.vertices[t[2]] - r;
        sum += a.x * (b.y * c.z - b.z * c.y) + a.y * (b.z * c.x - b.x * c.z) + a.z * (b.x * c.y - b.y * c.x);
    }
    return sum / 6.0;
}

void check_closed(TriangleMesh& mesh, const std::string& name, Closedness rule) {
    const std::size_t nv = mesh.vertices.size();
    for (const auto& t : mesh.triangles)
        for (const auto v : t)
            if (v >= nv) throw Error(name + ": a triangle refers to vertex " + std::to_string(v) + " of " + std::to_string(nv));
    // A triangle with a repeated vertex has edges (a, b) and (b, a) that cancel: it bounds nothing.
    std::erase_if(mesh.triangles, [](const auto& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; });
    if (mesh.triangles.empty()) throw Error(name + ": the mesh has no triangles");

    struct Edge {
        std::uint32_t lo, hi;
        bool forward;  // used as lo -> hi
    };
    std::vector<Edge> edges;
    edges.reserve(3 * mesh.triangles.size());
    for (const auto& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
            edges.push_back({std::min(a, b), std::max(a, b), a < b});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
        return std::tie(x.lo, x.hi, x.forward) < std::tie(y.lo, y.hi, y.forward);
    });
    auto where = [&](const Edge& e) {
        return "the edge between vertices " + point(mesh.vertices[e.lo]) + " and " + point(mesh.vertices[e.hi]);
    };
    std::size_t same_direction = edges.size();  // the first edge used twice in one direction, if any
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i;
        while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
        const std::size_t n = j - i;
        if (rule == Closedness::Cycle) {
            std::size_t forward = 0;
            for (std::size_t k = i; k < j; ++k) forward += edges[k].forward;
            if (2 * forward != n)
                throw Error(name + ": the surface is not closed (" + where(edges[i]) + " is used " + std::to_string(forward) +
                            " times in one direction and " + std::to_string(n - forward) + " in the other)");
            i = j;
            continue;
        }
        if (n != 2)
            throw Error(name + ": the mesh is not closed (" + where(edges[i]) + " is used by " + std::to_string(n) +
                        (n == 1 ? " triangle)" : " triangles)"));
        if (edges[i].forward == edges[i + 1].forward && same_direction == edges.size()) same_direction = i;
        i = j;
    }
    if (same_direction != edges.size())
        throw Error(name + ": the mesh is not consistently oriented (" + where(edges[same_direction]) +
                    " is used in the same direction by both its triangles)");

    const double volume = signed_volume(mesh);
    glm::dvec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
    for (const auto& p : mesh.vertices) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::dvec3 e = hi - lo;
    const double scale = std::max({e.x, e.y, e.z});
    if (!(std::abs(volume) > 1e-12 * scale * scale * scale))
        throw Error(name + ": the mesh encloses no volume (signed volume " + number(volume) + ")");
    if (volume < 0)
        for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
}

TriangleMesh read_closed_mesh(const std::string& path) {
    TriangleMesh mesh = read_mesh(path);
    check_closed(mesh, path);
    return mesh;
}

}  // namespace volref
