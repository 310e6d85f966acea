#include "core/io/MetaImageReader.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"
#include "core/io/VolumeLayout.h"

namespace volref {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return out;
}

std::vector<std::string_view> split_words(std::string_view s) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
        if (i > start) words.push_back(s.substr(start, i - start));
    }
    return words;
}

struct Field {
    std::string key;  // as written
    std::string value;
    std::size_t line = 0;
};

// The header: its fields by lower-case key, and where the data start when ElementDataFile = LOCAL.
struct Header {
    std::map<std::string, Field> fields;
    std::size_t data_offset = 0;  // the byte after the ElementDataFile line
    bool has_data_file = false;
};

Header parse_header(const std::string& file, const std::string& where) {
    Header h;
    std::size_t pos = 0;
    std::size_t line = 0;
    while (pos < file.size()) {
        ++line;
        std::size_t eol = file.find('\n', pos);
        const std::size_t end = eol == std::string::npos ? file.size() : eol;
        const std::string_view text = trim(std::string_view(file).substr(pos, end - pos));
        pos = eol == std::string::npos ? file.size() : eol + 1;
        if (text.empty()) continue;
        const std::size_t eq = text.find('=');
        if (eq == std::string_view::npos)
            throw Error(where + ": line " + std::to_string(line) + ": expected 'Key = Value', got " + io::quoted(text));
        const std::string key(trim(text.substr(0, eq)));
        const std::string value(trim(text.substr(eq + 1)));
        if (key.empty() || key.find_first_of("\t ") != std::string::npos)
            throw Error(where + ": line " + std::to_string(line) + ": expected 'Key = Value', got " + io::quoted(text));
        const std::string k = lower(key);
        if (auto it = h.fields.find(k); it != h.fields.end())
            throw Error(where + ": line " + std::to_string(line) + ": " + key + " given twice (first on line " +
                        std::to_string(it->second.line) + ")");
        h.fields[k] = Field{key, value, line};
        if (k == "elementdatafile") {
            h.data_offset = pos;
            h.has_data_file = true;
            break;
        }
    }
    return h;
}

class Fields {
public:
    Fields(const Header& h, std::string where) : h_(h), where_(std::move(where)) {}

    const Field* find(const std::string& lower_key) const {
        const auto it = h_.fields.find(lower_key);
        return it == h_.fields.end() ? nullptr : &it->second;
    }
    // The first of `keys` present.
    const Field* find_any(std::initializer_list<const char*> keys) const {
        for (const char* k : keys)
            if (const Field* f = find(k)) return f;
        return nullptr;
    }
    // The first of the synonyms `keys` present; each other one present must say the same (`same` compares
    // two fields), or the header contradicts itself: an error naming both lines.
    template <class Same>
    const Field* find_agreeing(std::initializer_list<const char*> keys, Same same) const {
        const Field* first = nullptr;
        for (const char* k : keys) {
            const Field* f = find(k);
            if (!f) continue;
            if (!first) {
                first = f;
            } else if (!same(*first, *f)) {
                const Field* a = first->line < f->line ? first : f;
                const Field* b = a == first ? f : first;
                throw Error(where_ + ": line " + std::to_string(b->line) + ": " + b->key + " = " + io::quoted(b->value) +
                            " contradicts " + a->key + " = " + io::quoted(a->value) + " on line " + std::to_string(a->line));
            }
        }
        return first;
    }
    const Field& require(const char* lower_key, const char* name) const {
        const Field* f = find(lower_key);
        if (!f) throw Error(where_ + ": missing required key '" + name + "'");
        return *f;
    }
    [[noreturn]] void fail(const Field& f, const std::string& problem) const {
        throw Error(where_ + ": line " + std::to_string(f.line) + ": " + f.key + ": " + problem);
    }
    bool boolean(const Field& f) const {
        const std::string v = lower(f.value);
        if (v == "true" || v == "1") return true;
        if (v == "false" || v == "0") return false;
        fail(f, "expected True or False, got " + io::quoted(f.value));
    }
    std::vector<double> numbers(const Field& f, std::size_t n, bool positive) const {
        const auto words = split_words(f.value);
        if (words.size() != n)
            fail(f, "expected " + std::to_string(n) + " numbers, got " + io::quoted(f.value));
        std::vector<double> out;
        for (std::string_view w : words) {
            const auto v = io::parse_number(w);
            if (!v || !std::isfinite(*v) || (positive && !(*v > 0.0)))
                fail(f, std::string("expected ") + (positive ? "numbers > 0" : "finite numbers") + ", got " +
                            io::quoted(w));
            out.push_back(*v);
        }
        return out;
    }
    std::int64_t integer(const Field& f, std::int64_t min) const {
        const auto v = io::parse_number(f.value);
        if (!v || std::floor(*v) != *v || *v < double(min) || *v > 9.0e18)
            fail(f, "expected an integer >= " + std::to_string(min) + ", got " + io::quoted(f.value));
        return static_cast<std::int64_t>(*v);
    }

private:
    const Header& h_;
    std::string where_;
};

ScalarType element_type(const Fields& fields) {
    const Field& f = fields.require("elementtype", "ElementType");
    const std::string& v = f.value;
    if (v == "MET_UCHAR") return ScalarType::U8;
    if (v == "MET_CHAR") return ScalarType::I8;
    if (v == "MET_USHORT") return ScalarType::U16;
    if (v == "MET_SHORT") return ScalarType::I16;
    if (v == "MET_UINT") return ScalarType::U32;
    if (v == "MET_INT") return ScalarType::I32;
    if (v == "MET_FLOAT") return ScalarType::F32;
    if (v == "MET_DOUBLE") return ScalarType::F64;
    if (v.rfind("MET_", 0) == 0)
        fields.fail(f, "type " + io::quoted(v) +
                           " is not supported (volref reads MET_UCHAR, MET_CHAR, MET_USHORT, MET_SHORT, MET_UINT, "
                           "MET_INT, MET_FLOAT, MET_DOUBLE)");
    fields.fail(f, "unknown type " + io::quoted(v));
}

}  // namespace

namespace {

// The header and what it says about the data, shared by read_metaimage and metaimage_layout.
struct ParsedMetaImage {
    Header header;
    Volume volume;  // dims, spacing, origin; no samples
    ScalarType type = ScalarType::U8;
    bool msb = false, compressed = false;
    std::optional<std::int64_t> compressed_size;
    std::int64_t header_size = 0;
    bool local = false;            // ElementDataFile = LOCAL
    std::filesystem::path data;    // the data file (the file itself when local)
    std::string at;                // how errors in the data name it
};

// `limited`: the whole volume is about to be read (its size is checked against the memory limit).
ParsedMetaImage parse_metaimage(const std::filesystem::path& path, const std::string& file, bool limited) {
    const std::string where = path.string();
    ParsedMetaImage p;
    p.header = parse_header(file, where);
    const Header& header = p.header;
    const Fields fields(header, where);

    if (const Field* f = fields.find("objecttype"); f && lower(f->value) != "image")
        fields.fail(*f, "ObjectType " + io::quoted(f->value) + " is not supported (volref reads Image)");
    const Field& ndims_field = fields.require("ndims", "NDims");
    const std::int64_t ndims = fields.integer(ndims_field, 1);
    if (ndims > 3) fields.fail(ndims_field, std::to_string(ndims) + " dimensions are not supported (volref reads 1 to 3)");
    const auto n = static_cast<std::size_t>(ndims);

    Volume& volume = p.volume;
    volume.dims = {1, 1, 1};
    const Field& dim_field = fields.require("dimsize", "DimSize");
    const std::vector<double> dims = fields.numbers(dim_field, n, true);
    for (std::size_t a = 0; a < n; ++a) {
        if (std::floor(dims[a]) != dims[a] || dims[a] > 9.0e18)
            fields.fail(dim_field, "expected integers >= 1, got " + io::quoted(dim_field.value));
        volume.dims[a] = static_cast<std::int64_t>(dims[a]);
    }
    p.type = element_type(fields);
    if (const Field* f = fields.find("elementnumberofchannels"); f && fields.integer(*f, 1) != 1)
        fields.fail(*f, "only 1 channel is supported, got " + io::quoted(f->value));
    auto same_numbers = [&](std::size_t count) {
        return [&fields, count](const Field& a, const Field& b) {
            return fields.numbers(a, count, false) == fields.numbers(b, count, false);
        };
    };
    if (const Field* f = fields.find_agreeing({"elementspacing", "elementsize"}, same_numbers(n))) {
        const auto s = fields.numbers(*f, n, true);
        for (std::size_t a = 0; a < n; ++a) volume.spacing[int(a)] = s[a];
    }
    if (const Field* f = fields.find_agreeing({"offset", "position", "origin"}, same_numbers(n))) {
        const auto o = fields.numbers(*f, n, false);
        for (std::size_t a = 0; a < n; ++a) volume.origin[int(a)] = o[a];
    }
    if (const Field* f = fields.find_agreeing({"transformmatrix", "rotation", "orientation"}, same_numbers(n * n))) {
        const auto m = fields.numbers(*f, n * n, false);
        for (std::size_t r = 0; r < n; ++r)
            for (std::size_t c = 0; c < n; ++c)
                if (m[r * n + c] != (r == c ? 1.0 : 0.0))
                    fields.fail(*f, "only the identity is supported (volref reads axis-aligned, unrotated grids), got " +
                                        io::quoted(f->value));
    }
    if (const Field* f = fields.find("binarydata"); f && !fields.boolean(*f))
        fields.fail(*f, "ASCII MetaImage data (BinaryData = False) is not supported");
    if (const Field* f = fields.find_agreeing({"binarydatabyteordermsb", "elementbyteordermsb"},
                                              [&](const Field& a, const Field& b) { return fields.boolean(a) == fields.boolean(b); }))
        p.msb = fields.boolean(*f);
    if (const Field* f = fields.find("compresseddata")) p.compressed = fields.boolean(*f);
    if (const Field* f = fields.find("compresseddatasize")) p.compressed_size = fields.integer(*f, 0);
    if (const Field* f = fields.find("headersize")) p.header_size = fields.integer(*f, -1);
    if (limited) checked_voxel_count(volume.dims, where, scalar_type_size(p.type));
    else checked_voxel_count_unlimited(volume.dims, where, scalar_type_size(p.type));
    if (!header.has_data_file) throw Error(where + ": missing required key 'ElementDataFile'");
    const Field& data_field = *fields.find("elementdatafile");
    if (p.compressed && p.header_size != 0)
        fields.fail(*fields.find("headersize"), "HeaderSize with CompressedData is not supported");

    // The data region: after the header line (LOCAL), or the named file.
    const std::string data_name = data_field.value;
    p.local = lower(data_name) == "local";
    if (p.local) {
        p.data = path;
        p.at = where;
    } else {
        if (lower(data_name) == "list" || data_name.find('%') != std::string::npos ||
            split_words(data_name).size() > 1)
            fields.fail(data_field, "several data files are not supported (give one file or LOCAL)");
        p.data = std::filesystem::path(data_name);
        if (p.data.is_relative()) p.data = path.parent_path() / p.data;
        // Errors in a data file name it first.
        p.at = p.data.string() + " (data file of " + where + ")";
    }
    return p;
}

}  // namespace

Volume read_metaimage(const std::filesystem::path& path) {
    const std::string file = io::read_file_bytes(path);
    ParsedMetaImage p = parse_metaimage(path, file, true);
    Volume& volume = p.volume;
    // The data: after the header line (LOCAL), or the named file (read in pieces, straight into the
    // volume).
    std::optional<io::ByteSource> source;
    if (p.local) source.emplace(std::string_view(file).substr(p.header.data_offset));
    else source.emplace(p.data, 0, p.data.string());
    const std::string& at = p.at;
    const std::uint64_t region_size = source->size();
    const std::endian order = p.msb ? std::endian::big : std::endian::little;
    if (p.compressed) {
        if (p.compressed_size) {
            if (std::uint64_t(*p.compressed_size) > region_size)
                throw Error(at + ": truncated: CompressedDataSize is " + std::to_string(*p.compressed_size) +
                            " bytes, found " + std::to_string(region_size));
            if (std::uint64_t(*p.compressed_size) < region_size)
                throw Error(at + ": CompressedDataSize is " + std::to_string(*p.compressed_size) + " bytes, but " +
                            std::to_string(region_size) + " bytes of compressed data follow");
        }
        io::read_samples(volume, p.type, order, *source, io::BinaryEncoding::Gzip, 0, at);
    } else {
        io::read_samples(volume, p.type, order, *source, io::BinaryEncoding::Raw, p.header_size, at);
    }
    return volume;
}

VolumeLayout metaimage_layout(const std::filesystem::path& path) {
    // The header only: it ends with the ElementDataFile line (an .mha's samples follow it).
    constexpr std::size_t kPrefix = std::size_t(1) << 20;
    bool whole = false;
    std::string file = io::read_file_prefix(path, kPrefix, whole);
    ParsedMetaImage p = parse_metaimage(path, file, false);
    if (!whole && (!p.header.has_data_file || p.header.data_offset >= file.size())) {
        file = io::read_file_bytes(path);  // a header longer than the prefix
        p = parse_metaimage(path, file, false);
    }
    VolumeLayout out;
    out.dims = p.volume.dims;
    out.origin = p.volume.origin;
    out.spacing = p.volume.spacing;
    out.type = p.type;
    out.endian = p.msb ? std::endian::big : std::endian::little;
    out.data = p.data;
    out.data_where = p.at;
    if (p.compressed) {
        out.not_direct = "compressed data (CompressedData = True)";
        return out;
    }
    const std::uint64_t base = p.local ? p.header.data_offset : 0;
    if (p.header_size >= 0) {
        out.offset = base + std::uint64_t(p.header_size);
    } else {  // -1: the samples end the file
        const std::uint64_t bytes = std::uint64_t(checked_voxel_count_unlimited(out.dims, path.string(), scalar_type_size(out.type))) *
                                    scalar_type_size(out.type);
        out.offset = trailing_samples_offset(out, base, bytes);
    }
    return out;
}

}  // namespace volref
