#include "core/io/RawReader.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"
#include "core/io/VolumeLayout.h"
#include "core/scene/JsonReader.h"

namespace volref {

namespace {

using nlohmann::json;

// What a sidecar says about its data file.
struct Sidecar {
    std::array<std::int64_t, 3> dims{1, 1, 1};
    ScalarType type = ScalarType::U8;
    std::endian endian = std::endian::little;
    glm::dvec3 origin{0.0};
    glm::dvec3 spacing{1.0};
    std::int64_t header_bytes = 0;
    io::BinaryEncoding encoding = io::BinaryEncoding::Raw;
};

// A JSON value as compact one-line text for messages, cut after 64 characters.
std::string shown(const json& value) {
    std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
    if (text.size() > 64) text = text.substr(0, 64) + "...";
    return text;
}

// Reads the keys of one sidecar; every message is "SIDECAR: KEY: PROBLEM".
class SidecarReader {
public:
    explicit SidecarReader(std::string where) : where_(std::move(where)) {}

    [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
        throw Error(where_ + ": " + key + ": " + problem);
    }

    // An integer >= min (and within int64).
    std::int64_t integer(const json& v, const std::string& key, std::int64_t min) const {
        if (v.is_number_unsigned()) {
            const auto u = v.get<std::uint64_t>();
            if (u <= std::uint64_t(std::numeric_limits<std::int64_t>::max()) && std::int64_t(u) >= min)
                return std::int64_t(u);
        } else if (v.is_number_integer()) {
            const auto i = v.get<std::int64_t>();
            if (i >= min) return i;
        }
        fail(key, "expected an integer >= " + std::to_string(min) + ", got " + shown(v));
    }

    // A finite number, > 0 when `positive`.
    double number(const json& v, const std::string& key, bool positive) const {
        const bool ok =
            v.is_number() && std::isfinite(v.get<double>()) && (!positive || v.get<double>() > 0.0);
        if (!ok)
            fail(key, std::string(positive ? "expected a number > 0" : "expected a finite number") +
                          ", got " + shown(v));
        return v.get<double>();
    }

    // An array of 3 numbers (each > 0 when `positive`).
    glm::dvec3 vec3(const json& v, const std::string& key, bool positive) const {
        if (!v.is_array() || v.size() != 3)
            fail(key, std::string("expected an array of 3 ") + (positive ? "numbers > 0" : "numbers") +
                          ", got " + shown(v));
        glm::dvec3 out;
        for (int a = 0; a < 3; ++a) out[a] = number(v[a], key + "[" + std::to_string(a) + "]", positive);
        return out;
    }

    // One of `choices`, as a string.
    std::string choice(const json& v, const std::string& key,
                       std::initializer_list<const char*> choices) const {
        std::string list;
        for (const char* c : choices) {
            if (v.is_string() && v.get<std::string>() == c) return c;
            list += std::string(list.empty() ? "" : ", ") + "\"" + c + "\"";
        }
        fail(key, "expected one of " + list + ", got " + shown(v));
    }

    const std::string& where() const { return where_; }

private:
    std::string where_;
};

ScalarType type_from_name(const std::string& name) {
    for (ScalarType t : {ScalarType::U8, ScalarType::I8, ScalarType::U16, ScalarType::I16, ScalarType::U32,
                         ScalarType::I32, ScalarType::F32, ScalarType::F64})
        if (name == scalar_type_name(t)) return t;
    return ScalarType::U8;  // not reached: `choice` only returns listed names
}

// The sidecar's keys, checked: dims and type are required, the others have defaults.
Sidecar parse_sidecar(const json& doc, const SidecarReader& reader) {
    if (!doc.is_object()) throw Error(reader.where() + ": expected a JSON object, got " + shown(doc));
    static const char* const kKeys[] = {"dims",    "type",         "endian",  "origin",
                                        "spacing", "header_bytes", "encoding"};
    for (const auto& [key, value] : doc.items()) {
        bool known = false;
        for (const char* k : kKeys) known = known || key == k;
        if (!known)
            throw Error(
                reader.where() + ": " + io::quoted(key) +
                ": unknown key (expected dims, type, endian, origin, spacing, header_bytes, encoding)");
    }
    for (const char* required : {"dims", "type"})
        if (!doc.contains(required))
            throw Error(reader.where() + ": missing required key '" + required + "'");

    Sidecar sidecar;
    const json& dims = doc.at("dims");
    if (!dims.is_array() || dims.size() != 3)
        reader.fail("dims", "expected an array of 3 integers >= 1, got " + shown(dims));
    for (int a = 0; a < 3; ++a)
        sidecar.dims[a] = reader.integer(dims[a], "dims[" + std::to_string(a) + "]", 1);
    sidecar.type = type_from_name(
        reader.choice(doc.at("type"), "type", {"u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"}));
    if (doc.contains("endian"))
        sidecar.endian = reader.choice(doc.at("endian"), "endian", {"little", "big"}) == "big"
                             ? std::endian::big
                             : std::endian::little;
    if (doc.contains("origin")) sidecar.origin = reader.vec3(doc.at("origin"), "origin", false);
    if (doc.contains("spacing")) sidecar.spacing = reader.vec3(doc.at("spacing"), "spacing", true);
    if (doc.contains("header_bytes"))
        sidecar.header_bytes = reader.integer(doc.at("header_bytes"), "header_bytes", 0);
    if (doc.contains("encoding"))
        sidecar.encoding = reader.choice(doc.at("encoding"), "encoding", {"raw", "gzip"}) == "gzip"
                               ? io::BinaryEncoding::Gzip
                               : io::BinaryEncoding::Raw;
    return sidecar;
}

// The sidecar at `sidecar_path`, which describes the data file `data_where`.
Sidecar read_sidecar(const std::filesystem::path& sidecar_path, const std::string& data_where) {
    const std::string where = sidecar_path.string();
    std::string text;
    try {
        text = io::read_file_bytes(sidecar_path);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (the JSON sidecar describing " + data_where + ")");
    }
    // The scene's strict parser: a key given twice, a NUL byte, nesting beyond kMaxJsonDepth or a number
    // beyond a double is an error naming it, not the last value silently.
    const json doc = json_reader::parse_json(text, where + ": invalid JSON");
    return parse_sidecar(doc, SidecarReader(where));
}

}  // namespace

Volume read_raw_volume(const std::filesystem::path& path) {
    const std::string where = path.string();
    io::open_for_reading(path);  // a wrong data path is reported as such, not as a missing sidecar
    std::filesystem::path sidecar_path = path;
    sidecar_path += ".json";
    const Sidecar sidecar = read_sidecar(sidecar_path, where);

    Volume volume;
    volume.dims = sidecar.dims;
    volume.type = sidecar.type;
    volume.origin = sidecar.origin;
    volume.spacing = sidecar.spacing;
    checked_voxel_count(volume.dims, sidecar_path.string(), scalar_type_size(volume.type));

    // Straight from the file into the typed storage (no copy of the file in memory).
    io::ByteSource data(path, 0, where);
    io::read_samples(volume, sidecar.type, sidecar.endian, data, sidecar.encoding, sidecar.header_bytes, where);
    return volume;
}

VolumeLayout raw_layout(const std::filesystem::path& path) {
    const std::string where = path.string();
    io::open_for_reading(path);  // as read_raw_volume: a wrong data path is reported as such
    std::filesystem::path sidecar_path = path;
    sidecar_path += ".json";
    const Sidecar sidecar = read_sidecar(sidecar_path, where);
    checked_voxel_count_unlimited(sidecar.dims, sidecar_path.string(), scalar_type_size(sidecar.type));
    VolumeLayout out;
    out.dims = sidecar.dims;
    out.origin = sidecar.origin;
    out.spacing = sidecar.spacing;
    out.type = sidecar.type;
    out.endian = sidecar.endian;
    out.data = path;
    out.data_where = where;
    out.offset = std::uint64_t(sidecar.header_bytes);
    if (sidecar.encoding == io::BinaryEncoding::Gzip) out.not_direct = "gzip encoding";
    return out;
}

}  // namespace volref
