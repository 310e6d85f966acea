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
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tiny_obj_loader.h>  // TINYOBJLOADER_USE_DOUBLE comes with the tinyobjloader_double target

#include "core/Error.h"

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

TriangleMesh read_obj(const std::string& path) {
    static_assert(sizeof(tinyobj::real_t) == sizeof(double), "tinyobjloader must be its double build");
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
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

// The PLY header, checked by volref before assimp sees the file: assimp 5.2 (Debian 12) loops forever
// or aborts on some malformed headers (found by fuzz_ply; tests/fuzz/regressions/fuzz_ply/). Accepted:
//   ply / format ascii|binary_little_endian|binary_big_endian 1.0 / comment ... / obj_info ...
//   element vertex N   with scalar properties only, among them x, y and z
//   element face M     with exactly one list property (vertex_indices or vertex_index) and scalars
//   other elements     with scalar properties only
//   end_header
// Types: char uchar short ushort int uint float double and int8 .. float64; counts <= 2^31 - 1.
void check_ply_header(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error(path + ": cannot read the PLY file");
    std::string header;
    int c = 0;
    while (header.size() < (1u << 16) && (c = std::fgetc(f)) != EOF) {
        header.push_back(char(c));
        if (header.size() >= 11 && header.compare(header.size() - 11, 11, "end_header\n") == 0) break;
        if (header.size() >= 12 && header.compare(header.size() - 12, 12, "end_header\r\n") == 0) break;
    }
    std::fclose(f);
    auto fail = [&](int line, const std::string& why) {
        throw Error(path + ": PLY header line " + std::to_string(line) + ": " + why);
    };
    static const char* kTypes[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8",
                                   "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
    auto is_type = [](const std::string& t) { return std::find(std::begin(kTypes), std::end(kTypes), t) != std::end(kTypes); };
    std::vector<std::string> lines;
    std::string cur;
    for (char ch : header) {
        if (ch == '\n') {
            if (!cur.empty() && cur.back() == '\r') cur.pop_back();
            lines.push_back(cur);
            cur.clear();
        } else {
            cur.push_back(ch);
        }
    }
    if (lines.empty() || lines[0] != "ply") fail(1, "expected \"ply\"");
    if (lines.back() != "end_header") fail(int(lines.size()), "no end_header within the first 64 KiB");
    std::string element;
    bool have_format = false, have_vertex = false, have_face = false, face_list = false;
    bool x = false, y = false, z = false;
    for (std::size_t i = 1; i + 1 < lines.size(); ++i) {
        const int n = int(i) + 1;
        std::vector<std::string> w;
        std::string word;
        for (char ch : lines[i]) {
            if (ch == ' ' || ch == '\t') {
                if (!word.empty()) w.push_back(word);
                word.clear();
            } else {
                word.push_back(ch);
            }
        }
        if (!word.empty()) w.push_back(word);
        if (w.empty()) fail(n, "empty line");
        if (w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "format") {
            if (have_format || w.size() != 3 || w[2] != "1.0" ||
                (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
                fail(n, "expected one \"format ascii|binary_little_endian|binary_big_endian 1.0\"");
            have_format = true;
        } else if (w[0] == "element") {
            if (w.size() != 3 || w[2].empty() || w[2].size() > 10 ||
                w[2].find_first_not_of("0123456789") != std::string::npos || std::stoll(w[2]) > 0x7fffffffLL)
                fail(n, "expected \"element NAME COUNT\" with 0 <= COUNT < 2^31");
            if (element == "face" && !face_list) fail(n, "the face element has no list property");
            element = w[1];
            if ((element == "vertex" && have_vertex) || (element == "face" && have_face)) fail(n, "a second " + element + " element");
            have_vertex = have_vertex || element == "vertex";
            have_face = have_face || element == "face";
        } else if (w[0] == "property") {
            if (element.empty()) fail(n, "a property before any element");
            if (w.size() == 5 && w[1] == "list") {
                if (element != "face" || face_list || !is_type(w[2]) || !is_type(w[3]) ||
                    (w[4] != "vertex_indices" && w[4] != "vertex_index"))
                    fail(n, "only the face element may have a list property, one: vertex_indices");
                face_list = true;
            } else if (w.size() == 3 && is_type(w[1])) {
                if (element == "vertex") {
                    x = x || w[2] == "x";
                    y = y || w[2] == "y";
                    z = z || w[2] == "z";
                }
            } else {
                fail(n, "expected \"property TYPE NAME\" or \"property list TYPE TYPE vertex_indices\"");
            }
        } else {
            fail(n, "unknown keyword \"" + w[0].substr(0, 32) + "\"");
        }
    }
    if (!have_format) fail(2, "no format line");
    if (!have_vertex || !(x && y && z)) fail(int(lines.size()), "no vertex element with x, y and z");
    if (!have_face || !face_list) fail(int(lines.size()), "no face element with a vertex_indices list");
}

TriangleMesh read_ply(const std::string& path) {
    if (!std::filesystem::is_regular_file(path)) throw Error(path + ": cannot read the PLY file (no such file)");
    check_ply_header(path);
    Assimp::Importer importer;
    // No post-processing: assimp's Triangulate step aborts the process on a face with an out-of-range
    // vertex index (found by fuzz_ply; tests/fuzz/regressions/fuzz_ply/). Polygons are fanned below,
    // after every index has been checked.
    const aiScene* scene = importer.ReadFile(path, 0u);
    if (!scene || !scene->mRootNode) {
        const std::string why = first_line(importer.GetErrorString());
        throw Error(path + ": cannot read the PLY file" + (why.empty() ? "" : " (" + why + ")"));
    }
    TriangleMesh mesh;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* am = scene->mMeshes[m];
        const std::uint32_t base = std::uint32_t(mesh.vertices.size());
        for (unsigned i = 0; i < am->mNumVertices; ++i)
            mesh.vertices.emplace_back(am->mVertices[i].x, am->mVertices[i].y, am->mVertices[i].z);
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices < 3) continue;  // points and lines bound nothing
            for (unsigned k = 0; k < face.mNumIndices; ++k)
                if (face.mIndices[k] >= am->mNumVertices)
                    throw Error(path + ": the PLY file's face " + std::to_string(f) + " has an invalid vertex index " +
                                std::to_string(face.mIndices[k]) + " (" + std::to_string(am->mNumVertices) +
                                " vertices)");
            // A polygon v0 v1 ... v(n-1) becomes the fan (v0, vk, vk+1): exact for the planar convex faces
            // of a bounding mesh; the closedness check rejects anything the fan leaves open.
            for (unsigned k = 1; k + 1 < face.mNumIndices; ++k)
                mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[k], base + face.mIndices[k + 1]});
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
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    TriangleMesh mesh;
    if (ext == ".obj")
        mesh = read_obj(path);
    else if (ext == ".ply")
        mesh = read_ply(path);
    else
        throw Error(path + ": unknown mesh format '" + ext + "' (expected .obj or .ply)");
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const glm::dvec3& p = mesh.vertices[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error(path + ": vertex " + std::to_string(i) + " is not finite");
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

void check_closed(TriangleMesh& mesh, const std::string& name) {
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
