#include "cli/mpi/BrickReader.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"

namespace volref::mpi {

namespace {

ScalarType parse_type(const std::string& t, const std::string& where) {
    static const std::pair<const char*, ScalarType> kTypes[] = {
        {"u8", ScalarType::U8},   {"i8", ScalarType::I8},   {"u16", ScalarType::U16}, {"i16", ScalarType::I16},
        {"u32", ScalarType::U32}, {"i32", ScalarType::I32}, {"f32", ScalarType::F32}, {"f64", ScalarType::F64}};
    for (const auto& [name, type] : kTypes)
        if (t == name) return type;
    throw Error(where + ": type: expected u8, i8, u16, i16, u32, i32, f32 or f64, got \"" + t + "\"");
}

VolumeHeader read_raw_header(const std::filesystem::path& path) {
    const std::filesystem::path sidecar = path.string() + ".json";
    const std::string where = sidecar.string();
    std::ifstream in(sidecar);
    if (!in) throw Error(where + ": cannot open the sidecar");
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(in);
    } catch (const std::exception&) {
        throw Error(where + ": not valid JSON");
    }
    VolumeHeader h;
    h.data = path;
    try {
        for (int a = 0; a < 3; ++a) h.dims[a] = doc.at("dims").at(a).get<std::int64_t>();
        h.type = parse_type(doc.at("type").get<std::string>(), where);
        if (doc.contains("endian")) h.endian = doc["endian"].get<std::string>() == "big" ? std::endian::big : std::endian::little;
        if (doc.contains("origin"))
            for (int a = 0; a < 3; ++a) h.origin[a] = doc["origin"].at(a).get<double>();
        if (doc.contains("spacing"))
            for (int a = 0; a < 3; ++a) h.spacing[a] = doc["spacing"].at(a).get<double>();
        if (doc.contains("header_bytes")) h.header_bytes = doc["header_bytes"].get<std::int64_t>();
        if (doc.contains("encoding") && doc["encoding"].get<std::string>() != "raw")
            throw Error(where + ": encoding: volref-mpi reads bricks of \"raw\" encoding only (gzip is not supported yet)");
    } catch (const nlohmann::json::exception& e) {
        throw Error(where + ": " + e.what());
    }
    for (int a = 0; a < 3; ++a)
        if (h.dims[a] < 1) throw Error(where + ": dims: expected integers >= 1");
    return h;
}

}  // namespace

VolumeHeader read_volume_header(const std::filesystem::path& path, const std::string& format) {
    std::string f = format;
    if (f.empty()) f = path.extension() == ".raw" ? "raw" : path.extension().string();
    if (f == "raw") return read_raw_header(path);
    throw Error(path.string() + ": volref-mpi reads bricks of raw files (+ JSON sidecar) only; " +
                (f.empty() ? std::string("this format") : "\"" + f + "\"") +
                " is not supported yet (convert with `volref convert IN OUT.raw`)");
}

Volume read_brick(const VolumeHeader& h, const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims) {
    const std::string where = h.data.string();
    Volume v;
    v.dims = dims;
    v.origin = h.origin + glm::dvec3(double(lo[0]), double(lo[1]), double(lo[2])) * h.spacing;
    v.spacing = h.spacing;
    io::allocate_samples(v, h.type, where + " (this rank's brick)");  // checks the memory limit first
    const std::size_t size = scalar_type_size(h.type);
    const std::size_t row = std::size_t(dims[0]) * size;
    std::FILE* file = std::fopen(where.c_str(), "rb");
    if (!file) throw Error(where + ": cannot open the file");
    auto* out = static_cast<unsigned char*>(v.values.raw());
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            const std::int64_t gk = lo[2] + k, gj = lo[1] + j;
            const std::uint64_t offset =
                std::uint64_t(h.header_bytes) + (std::uint64_t(gk * h.dims[1] + gj) * std::uint64_t(h.dims[0]) + std::uint64_t(lo[0])) * size;
            if (std::fseek(file, long(offset), SEEK_SET) != 0 || std::fread(out, 1, row, file) != row) {
                std::fclose(file);
                throw Error(where + ": the file ends before this rank's brick (voxels (" + std::to_string(lo[0]) + ".." +
                            std::to_string(lo[0] + dims[0] - 1) + ", " + std::to_string(gj) + ", " + std::to_string(gk) +
                            ") at byte " + std::to_string(offset) + ")");
            }
            out += row;
        }
    std::fclose(file);
    io::to_native_order(v.values, h.endian);
    return v;
}

}  // namespace volref::mpi
