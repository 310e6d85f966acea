// volref resample IN OUT --to cylindrical|spherical|cartesian --dims NX,NY,NZ [--shell JSON]
//   [--interpolation NAME] [--origin X,Y,Z --spacing SX,SY,SZ] [--fill V] [--type f64|f32]
//   [--encoding raw|gzip] [--format nrrd|raw]
// (docs/shells.md). Every argument is checked, the input read and resampled before anything is
// written; the NRRD goes to a temporary file renamed into place (core/io/NrrdWriter.h).
// A beam-space output carries its shell in the header as the key/value pair
//   volref_bounds:={"type": "cylindrical", ...}
// (the scene's volume.bounds object), which `--to cartesian` reads back when --shell is absent.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "core/InputFile.h"
#include "core/Error.h"
#include "core/sample/Resample.h"
#include "core/io/NrrdWriter.h"
#include "core/io/VolumeReader.h"
#include "core/scene/SceneLoader.h"
#include "geometry/ShellCoordinates.h"
#include "core/scene/SceneNames.h"

namespace volref::cli {

namespace {

namespace fs = std::filesystem;

constexpr const char* kBoundsKey = "volref_bounds";

std::string trim(std::string_view s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string_view::npos) return "";
    const auto e = s.find_last_not_of(" \t\r\n");
    return std::string(s.substr(b, e - b + 1));
}

std::vector<std::string> split_commas(const std::string& s) {
    std::vector<std::string> parts;
    std::string part;
    std::istringstream in(s);
    while (std::getline(in, part, ',')) parts.push_back(trim(part));
    if (!s.empty() && s.back() == ',') parts.push_back("");
    return parts;
}

bool parse_double(const std::string& s, double& x) {
    if (s.empty()) return false;
    std::size_t used = 0;
    try {
        x = std::stod(s, &used);
    } catch (const std::exception&) {
        return false;
    }
    return used == s.size();
}

std::array<std::int64_t, 3> parse_dims(const std::string& s) {
    const std::vector<std::string> parts = split_commas(s);
    std::array<std::int64_t, 3> dims{0, 0, 0};
    bool ok = parts.size() == 3;
    for (std::size_t a = 0; ok && a < 3; ++a) {
        std::size_t used = 0;
        try {
            const long long v = std::stoll(parts[a], &used);
            ok = used == parts[a].size() && v >= 1;
            dims[a] = v;
        } catch (const std::exception&) {
            ok = false;
        }
    }
    if (!ok) throw Error("--dims: expected 3 integers >= 1 like 64,32,16, got '" + s + "'");
    return dims;
}

glm::dvec3 parse_vec3(const std::string& s, const std::string& option, bool positive) {
    const std::vector<std::string> parts = split_commas(s);
    glm::dvec3 v(0.0);
    bool ok = parts.size() == 3;
    for (std::size_t a = 0; ok && a < 3; ++a) ok = parse_double(parts[a], v[int(a)]) && std::isfinite(v[int(a)]) &&
                                                   (!positive || v[int(a)] > 0.0);
    if (!ok)
        throw Error(option + ": expected 3 " + (positive ? "numbers > 0" : "finite numbers") + " like " +
                    (positive ? "0.5,0.5,1" : "-1,0,2.5") + ", got '" + s + "'");
    return v;
}

Interpolation parse_interpolation(const std::string& s) {
    if (const auto named = scene_names::value_of(scene_names::kInterpolations, s)) return *named;
    throw Error("--interpolation: expected " + scene_names::listing(scene_names::kInterpolations) + ", got '" + s + "'");
}

// ---- the shell, as the scene's volume.bounds object (read by the scene loader's parse_shell) ----

bool is_spherical(const BoundsSpec& s) { return s.type == BoundsSpec::Type::Spherical; }

// The shell as the scene's volume.bounds object (every key explicit), for the output's header.
std::string shell_json(const BoundsSpec& s) {
    nlohmann::ordered_json j;
    if (!is_spherical(s)) {
        const CylindricalShell& c = s.cylinder;
        j["type"] = "cylindrical";
        j["center"] = {c.center.x, c.center.y, c.center.z};
        j["radius"] = {c.r0, c.r1};
        j["angle"] = {c.a0, c.a1};
        j["height"] = {c.h0, c.h1};
    } else {
        const SphericalShell& p = s.sphere;
        static const char* names[3] = {"longitude", "latitude", "radius"};
        j["type"] = "spherical";
        j["center"] = {p.center.x, p.center.y, p.center.z};
        j["radius"] = {p.r0, p.r1};
        j["longitude"] = {p.lon0, p.lon1};
        j["latitude"] = {p.lat0, p.lat1};
        j["axes"] = {names[p.axes[0]], names[p.axes[1]], names[p.axes[2]]};
    }
    return j.dump();
}

std::string read_text_file(const fs::path& path, const std::string& why) {
    try {
        return io::read_file_bytes(path);  // a regular file that fits the memory limit
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + why);
    }
}

// The value of key `key` in a NRRD header (unescaped), or "" when absent or not a NRRD file.
std::string nrrd_key_value(const fs::path& path, const std::string& key) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    if (!std::getline(in, line) || line.rfind("NRRD", 0) != 0) return "";
    const std::string prefix = key + ":=";
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) break;  // end of the header
        if (line.rfind(prefix, 0) != 0) continue;
        std::string value;
        for (std::size_t i = prefix.size(); i < line.size(); ++i) {
            if (line[i] == '\\' && i + 1 < line.size()) {
                ++i;
                value += line[i] == 'n' ? '\n' : line[i];
            } else {
                value += line[i];
            }
        }
        return value;
    }
    return "";
}

BoundsSpec read_shell(const ResampleArgs& args) {
    const std::string text = trim(args.shell);
    if (!text.empty() && text.front() == '{') return parse_shell(text, "--shell");
    if (!text.empty()) return parse_shell(read_text_file(args.shell, " (the --shell file)"), args.shell);
    // No --shell: the input's own description (--to cartesian).
    const std::string stored = nrrd_key_value(args.input, kBoundsKey);
    if (stored.empty())
        throw Error(args.input.string() + ": no '" + kBoundsKey +
                    "' key in the header to place the beam-space samples; give --shell");
    return parse_shell(stored, args.input.string() + " (" + kBoundsKey + ")");
}

}  // namespace

int run_resample(const ResampleArgs& args) {
    const auto start = std::chrono::steady_clock::now();
    // Every argument first, so that a bad one fails before any work.
    if (args.to != "cylindrical" && args.to != "spherical" && args.to != "cartesian")
        throw Error("--to: expected cylindrical, spherical or cartesian, got '" + args.to + "'");
    const bool to_cartesian = args.to == "cartesian";
    const std::array<std::int64_t, 3> dims = parse_dims(args.dims);
    checked_voxel_count(dims, "--dims");
    const Interpolation interpolation = parse_interpolation(args.interpolation);
    double fill = 0.0;
    if (!parse_double(trim(args.fill), fill)) throw Error("--fill: expected a number, got '" + args.fill + "'");
    NrrdWriteOptions out;
    if (args.type == "f64") out.type = ScalarType::F64;
    else if (args.type == "f32") out.type = ScalarType::F32;
    else throw Error("--type: expected f64 or f32, got '" + args.type + "'");
    if (args.encoding == "raw") out.encoding = NrrdWriteOptions::Encoding::Raw;
    else if (args.encoding == "gzip") out.encoding = NrrdWriteOptions::Encoding::Gzip;
    else throw Error("--encoding: expected raw or gzip, got '" + args.encoding + "'");
    if (!to_cartesian && (!args.origin.empty() || !args.spacing.empty()))
        throw Error("--origin and --spacing apply only to --to cartesian (a shell places its own samples)");
    if (args.origin.empty() != args.spacing.empty()) throw Error("give both --origin and --spacing, or neither");
    std::optional<glm::dvec3> origin, spacing;
    if (!args.origin.empty()) {
        origin = parse_vec3(args.origin, "--origin", false);
        spacing = parse_vec3(args.spacing, "--spacing", true);
    }
    if (!to_cartesian && trim(args.shell).empty()) throw Error("--to " + args.to + " needs --shell");
    check_nrrd_output_path(args.output);

    const BoundsSpec shell = read_shell(args);
    const bool spherical = is_spherical(shell);
    if (!to_cartesian && spherical != (args.to == "spherical"))
        throw Error(std::string(trim(args.shell).front() == '{' ? "--shell" : args.shell) +
                    ": type: expected \"" + args.to + "\" for --to " + args.to + ", got \"" +
                    (spherical ? "spherical" : "cylindrical") + "\"");
    if (!to_cartesian) {
        // Checks the grid (dims against the shell) before reading the input.
        if (spherical) static_cast<void>(ShellGrid(shell.sphere, dims));
        else static_cast<void>(ShellGrid(shell.cylinder, dims));
    }

    const Volume input = read_volume(args.input, args.format);
    Volume result;
    const std::string kind = spherical ? "spherical" : "cylindrical";
    if (to_cartesian) {
        if (!origin) {
            // The shell's bounding box, sampled by dims (spacing 1 on an axis with one sample).
            const auto box = spherical ? bounding_box(shell.sphere) : bounding_box(shell.cylinder);
            origin = box[0];
            spacing = glm::dvec3(1.0);
            for (int a = 0; a < 3; ++a)
                if (dims[std::size_t(a)] > 1 && box[1][a] > box[0][a])
                    (*spacing)[a] = (box[1][a] - box[0][a]) / double(dims[std::size_t(a)] - 1);
        }
        result = spherical
                     ? resample_to_cartesian(input, shell.sphere, interpolation, *origin, *spacing, dims, fill)
                     : resample_to_cartesian(input, shell.cylinder, interpolation, *origin, *spacing, dims, fill);
        out.comments.push_back("volref resample: a Cartesian grid from the " + kind + " beam-space volume " +
                               args.input.filename().string());
    } else {
        result = spherical ? resample_to_spherical(input, interpolation, shell.sphere, dims, fill)
                           : resample_to_cylindrical(input, interpolation, shell.cylinder, dims, fill);
        out.comments.push_back("volref resample: a " + kind + " beam-space grid from " + args.input.filename().string() +
                               "; " + kBoundsKey + " places its samples (origin and spacing are grid indices)");
        out.key_values.emplace_back(kBoundsKey, shell_json(shell));
    }
    write_nrrd(result, args.output, out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "volref: resampled %lld x %lld x %lld to a %s grid of %lld x %lld x %lld in %.3f s\n",
                 static_cast<long long>(input.dims[0]), static_cast<long long>(input.dims[1]),
                 static_cast<long long>(input.dims[2]), args.to.c_str(), static_cast<long long>(dims[0]),
                 static_cast<long long>(dims[1]), static_cast<long long>(dims[2]), seconds);
    std::printf("%s\n", args.output.string().c_str());
    return 0;
}

}  // namespace volref::cli
