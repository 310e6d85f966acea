#include "core/io/VtiReader.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <expat.h>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"

namespace volref {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

struct Element {
    std::string name;
    std::map<std::string, std::string> attributes;
    std::size_t line = 0;
    std::string text;  // DataArray: its inline contents

    const std::string* find(const std::string& key) const {
        const auto it = attributes.find(key);
        return it == attributes.end() ? nullptr : &it->second;
    }
};

// What the XML holds, for an ImageData file.
struct Document {
    std::optional<Element> file, image, appended;
    std::vector<Element> pieces;
    std::optional<Element> point_data;
    std::vector<Element> arrays;  // DataArray elements directly under PointData (of the first piece)
};

struct ParseState {
    Document doc;
    std::vector<std::string> stack;
    XML_Parser parser = nullptr;
    Element* text_target = nullptr;
};

void XMLCALL on_start(void* user, const XML_Char* name, const XML_Char** attributes) {
    auto* s = static_cast<ParseState*>(user);
    Element e;
    e.name = name;
    e.line = XML_GetCurrentLineNumber(s->parser);
    for (const XML_Char** a = attributes; a && a[0]; a += 2) e.attributes[a[0]] = a[1];
    const std::string parent = s->stack.empty() ? "" : s->stack.back();
    s->text_target = nullptr;
    if (e.name == "VTKFile" && s->stack.empty()) s->doc.file = e;
    else if (e.name == "ImageData" && parent == "VTKFile") s->doc.image = e;
    else if (e.name == "Piece" && parent == "ImageData") s->doc.pieces.push_back(e);
    else if (e.name == "PointData" && parent == "Piece" && s->doc.pieces.size() == 1) s->doc.point_data = e;
    else if (e.name == "DataArray" && parent == "PointData" && s->doc.pieces.size() == 1) {
        s->doc.arrays.push_back(e);
        s->text_target = &s->doc.arrays.back();
    } else if (e.name == "AppendedData" && parent == "VTKFile") s->doc.appended = e;
    s->stack.push_back(e.name);
}

void XMLCALL on_end(void* user, const XML_Char*) {
    auto* s = static_cast<ParseState*>(user);
    s->stack.pop_back();
    s->text_target = nullptr;
}

void XMLCALL on_text(void* user, const XML_Char* text, int len) {
    auto* s = static_cast<ParseState*>(user);
    if (s->text_target) s->text_target->text.append(text, std::size_t(len));
}

// Parses the XML of `file`; when it has <AppendedData>, only up to that start tag (the raw data after
// it are not XML) and `appended_start` is set to the byte after its '_' marker.
Document parse_xml(const std::string& file, const std::string& where, std::size_t& appended_start) {
    ParseState state;
    std::unique_ptr<std::remove_pointer_t<XML_Parser>, void (*)(XML_Parser)> parser(XML_ParserCreate(nullptr),
                                                                                   &XML_ParserFree);
    if (!parser) throw Error(where + ": cannot create an XML parser");
    state.parser = parser.get();
    XML_SetUserData(parser.get(), &state);
    XML_SetElementHandler(parser.get(), &on_start, &on_end);
    XML_SetCharacterDataHandler(parser.get(), &on_text);

    std::size_t xml_end = file.size();
    bool final_chunk = true;
    appended_start = std::string::npos;
    const std::size_t tag = file.find("<AppendedData");
    if (tag != std::string::npos) {
        const std::size_t gt = file.find('>', tag);
        if (gt == std::string::npos) throw Error(where + ": truncated: the <AppendedData> tag has no end");
        xml_end = gt + 1;
        final_chunk = false;  // the XML goes on after the data; expat sees only what comes before them
        std::size_t p = gt + 1;
        while (p < file.size() && is_space(file[p])) ++p;
        if (p == file.size() || file[p] != '_')
            throw Error(where + ": byte " + std::to_string(p) +
                        ": expected '_' to start the appended data after <AppendedData>");
        appended_start = p + 1;
    }
    if (xml_end > std::size_t(INT32_MAX)) throw Error(where + ": the XML part is too large");
    if (XML_Parse(parser.get(), file.data(), static_cast<int>(xml_end), final_chunk) == XML_STATUS_ERROR)
        throw Error(where + ": line " + std::to_string(XML_GetCurrentLineNumber(parser.get())) +
                    ": XML error: " + XML_ErrorString(XML_GetErrorCode(parser.get())));
    return std::move(state.doc);
}

// ---- reading attributes ----

class Attributes {
public:
    Attributes(const Element& e, std::string where) : e_(e), where_(std::move(where)) {}

    [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
        throw Error(where_ + ": line " + std::to_string(e_.line) + ": " + e_.name + (key.empty() ? "" : " " + key) +
                    ": " + problem);
    }
    std::vector<double> numbers(const std::string& key, std::size_t n) const {
        const std::string& text = *e_.find(key);
        std::vector<double> out;
        std::size_t i = 0;
        while (i < text.size()) {
            while (i < text.size() && is_space(text[i])) ++i;
            const std::size_t start = i;
            while (i < text.size() && !is_space(text[i])) ++i;
            if (i == start) break;
            const auto v = io::parse_number(std::string_view(text).substr(start, i - start));
            if (!v || !std::isfinite(*v)) fail(key, "expected " + std::to_string(n) + " numbers, got " + io::quoted(text));
            out.push_back(*v);
        }
        if (out.size() != n) fail(key, "expected " + std::to_string(n) + " numbers, got " + io::quoted(text));
        return out;
    }
    std::optional<std::string> text(const std::string& key) const {
        const std::string* v = e_.find(key);
        return v ? std::optional<std::string>(*v) : std::nullopt;
    }
    const Element& element() const { return e_; }

private:
    const Element& e_;
    std::string where_;
};

std::array<std::int64_t, 6> extent(const Attributes& a, const std::string& key) {
    const auto x = a.numbers(key, 6);
    std::array<std::int64_t, 6> e{};
    for (int i = 0; i < 6; ++i) {
        if (std::floor(x[std::size_t(i)]) != x[std::size_t(i)] || std::fabs(x[std::size_t(i)]) > 1e15)
            a.fail(key, "expected 6 integers, got " + io::quoted(*a.text(key)));
        e[std::size_t(i)] = static_cast<std::int64_t>(x[std::size_t(i)]);
    }
    for (int axis = 0; axis < 3; ++axis)
        if (e[std::size_t(2 * axis + 1)] < e[std::size_t(2 * axis)])
            a.fail(key, "axis " + std::to_string(axis) + ": the extent ends before it starts (" +
                            io::quoted(*a.text(key)) + ")");
    return e;
}

ScalarType array_type(const Attributes& a) {
    const auto t = a.text("type");
    if (!t) a.fail("", "missing attribute 'type'");
    if (*t == "UInt8") return ScalarType::U8;
    if (*t == "Int8") return ScalarType::I8;
    if (*t == "UInt16") return ScalarType::U16;
    if (*t == "Int16") return ScalarType::I16;
    if (*t == "UInt32") return ScalarType::U32;
    if (*t == "Int32") return ScalarType::I32;
    if (*t == "Float32") return ScalarType::F32;
    if (*t == "Float64") return ScalarType::F64;
    if (*t == "Int64" || *t == "UInt64" || *t == "String" || *t == "Bit")
        a.fail("type", io::quoted(*t) + " is not supported (volref reads Int8, UInt8, Int16, UInt16, Int32, UInt32, "
                                        "Float32, Float64)");
    a.fail("type", "unknown type " + io::quoted(*t));
}

// ---- binary data: raw bytes or base64 text, in "streams" (VTK encodes a compression header and the
// blocks after it as separate base64 streams) ----

int base64_value(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

class BinarySource {
public:
    BinarySource(std::string_view data, bool base64, std::string where)
        : data_(data), base64_(base64), where_(std::move(where)) {}

    // The next `n` bytes of the current stream; `what` names them in a message.
    std::string read(std::size_t n, const std::string& what) {
        if (!base64_) {
            const std::size_t left = data_.size() - std::min(data_.size(), pos_);
            if (left < n)
                throw Error(where_ + ": truncated: " + what + " needs " + std::to_string(n) + " bytes, found " +
                            std::to_string(left));
            std::string out(data_.substr(pos_, n));
            pos_ += n;
            return out;
        }
        const std::size_t total = done_ + n;
        const std::size_t chars = (total + 2) / 3 * 4;
        const std::size_t left = data_.size() - std::min(data_.size(), pos_);
        if (left < chars)
            throw Error(where_ + ": truncated: " + what + " needs " + std::to_string(chars) +
                        " base64 characters, found " + std::to_string(left));
        const std::string decoded = decode(data_.substr(pos_, chars), pos_);
        if (decoded.size() < total)
            throw Error(where_ + ": truncated: " + what + " needs " + std::to_string(total) +
                        " bytes, the base64 stream holds " + std::to_string(decoded.size()));
        std::string out = decoded.substr(done_, n);
        done_ = total;
        return out;
    }
    // Base64: the next read starts a new stream (after the padded end of this one).
    void end_stream() {
        if (base64_) pos_ += (done_ + 2) / 3 * 4;
        done_ = 0;
    }

private:
    std::string decode(std::string_view text, std::size_t offset) const {
        std::string out;
        out.reserve(text.size() / 4 * 3);
        for (std::size_t g = 0; g + 4 <= text.size(); g += 4) {
            int v[4];
            int pad = 0;
            for (int i = 0; i < 4; ++i) {
                const char c = text[g + std::size_t(i)];
                if (c == '=' && i >= 2) {
                    v[i] = 0;
                    ++pad;
                    continue;
                }
                v[i] = pad ? -1 : base64_value(c);
                if (v[i] < 0)
                    throw Error(where_ + ": base64 character " + std::to_string(offset + g + std::size_t(i)) + ": " +
                                io::quoted(std::string_view(&text[g + std::size_t(i)], 1)) + " is not base64");
            }
            const std::uint32_t bits = std::uint32_t(v[0]) << 18 | std::uint32_t(v[1]) << 12 |
                                       std::uint32_t(v[2]) << 6 | std::uint32_t(v[3]);
            out += char(bits >> 16);
            if (pad < 2) out += char((bits >> 8) & 0xff);
            if (pad < 1) out += char(bits & 0xff);
            if (pad && g + 4 < text.size())
                throw Error(where_ + ": base64 character " + std::to_string(offset + g + 4) +
                            ": data after the '=' padding of a stream");
        }
        return out;
    }

    std::string_view data_;
    bool base64_;
    std::string where_;
    std::size_t pos_ = 0;   // bytes (raw) or characters (base64) consumed by finished streams
    std::size_t done_ = 0;  // base64: bytes of the current stream already returned
};

// The header words (UInt32 or UInt64, in the file's byte order).
std::vector<std::uint64_t> header_words(const std::string& bytes, std::size_t word, std::endian order) {
    std::vector<std::uint64_t> out;
    const bool swap = order != std::endian::native;
    for (std::size_t p = 0; p + word <= bytes.size(); p += word)
        out.push_back(word == 4 ? io::load_value<std::uint32_t>(bytes.data() + p, swap)
                                : io::load_value<std::uint64_t>(bytes.data() + p, swap));
    return out;
}

// The `expected` bytes of samples from `src`: after a byte-count header, or zlib blocks after a
// compression header.
std::string binary_samples(BinarySource& src, std::size_t expected, std::size_t word, std::endian order,
                           bool compressed, const std::string& where) {
    if (!compressed) {
        const std::uint64_t count = header_words(src.read(word, "the byte-count header"), word, order)[0];
        if (count != expected)
            throw Error(where + ": the header gives " + std::to_string(count) + " bytes of data, expected " +
                        std::to_string(expected) + " (the extent times the type's size)");
        std::string data = src.read(expected, "the data");
        src.end_stream();
        return data;
    }
    const auto head = header_words(src.read(3 * word, "the compression header"), word, order);
    const std::uint64_t blocks = head[0], block_size = head[1], last_size = head[2];
    if (blocks > (std::uint64_t(1) << 40) / word)
        throw Error(where + ": the compression header gives " + std::to_string(blocks) + " blocks, too many");
    const auto sizes = header_words(src.read(std::size_t(blocks) * word, "the compressed block sizes"), word, order);
    src.end_stream();
    std::uint64_t total = 0;
    if (blocks > 0) total = (blocks - 1) * block_size + (last_size ? last_size : block_size);
    if (total != expected)
        throw Error(where + ": the compression header describes " + std::to_string(total) + " bytes (" +
                    std::to_string(blocks) + " blocks of " + std::to_string(block_size) + ", the last " +
                    std::to_string(last_size ? last_size : block_size) + "), expected " + std::to_string(expected) +
                    " (the extent times the type's size)");
    std::string out;
    out.reserve(expected);
    for (std::uint64_t b = 0; b < blocks; ++b) {
        const std::uint64_t size = (b + 1 == blocks && last_size) ? last_size : block_size;
        const std::string block_where = where + ": block " + std::to_string(b);
        const std::string compressed_block = src.read(std::size_t(sizes[std::size_t(b)]),
                                                      "block " + std::to_string(b) + " (compressed size " +
                                                          std::to_string(sizes[std::size_t(b)]) + ")");
        const io::Inflated inflated = io::inflate_stream(compressed_block, 0, std::size_t(size) + 1, block_where);
        if (inflated.data.size() != size)
            throw Error(block_where + ": expected " + std::to_string(size) + " bytes after inflating, found " +
                        (inflated.data.size() > size ? "more" : std::to_string(inflated.data.size())));
        out += inflated.data;
    }
    src.end_stream();
    return out;
}

}  // namespace

Volume read_vti(const std::filesystem::path& path) {
    const std::string where = path.string();
    const std::string file = io::read_file_bytes(path);
    std::size_t appended_start = 0;
    const Document doc = parse_xml(file, where, appended_start);

    if (!doc.file) throw Error(where + ": not a VTK XML file: no <VTKFile> root element");
    const Attributes vtk(*doc.file, where);
    const auto type_name = vtk.text("type");
    if (type_name != "ImageData")
        vtk.fail("type", io::quoted(type_name.value_or("")) + " is not supported (volref reads ImageData)");
    std::endian order = std::endian::little;
    if (const auto bo = vtk.text("byte_order")) {
        if (*bo == "BigEndian") order = std::endian::big;
        else if (*bo != "LittleEndian") vtk.fail("byte_order", "expected LittleEndian or BigEndian, got " + io::quoted(*bo));
    }
    std::size_t word = 4;
    if (const auto ht = vtk.text("header_type")) {
        if (*ht == "UInt64") word = 8;
        else if (*ht != "UInt32") vtk.fail("header_type", "expected UInt32 or UInt64, got " + io::quoted(*ht));
    }
    bool compressed = false;
    if (const auto c = vtk.text("compressor"); c && !c->empty()) {
        if (*c != "vtkZLibDataCompressor")
            vtk.fail("compressor", io::quoted(*c) + " is not supported (volref reads vtkZLibDataCompressor)");
        compressed = true;
    }

    if (!doc.image) throw Error(where + ": no <ImageData> element");
    const Attributes image(*doc.image, where);
    Volume volume;
    glm::dvec3 origin(0.0), spacing(1.0);
    if (image.text("Origin")) {
        const auto o = image.numbers("Origin", 3);
        origin = {o[0], o[1], o[2]};
    }
    if (image.text("Spacing")) {
        const auto s = image.numbers("Spacing", 3);
        for (int a = 0; a < 3; ++a)
            if (!(s[std::size_t(a)] > 0.0)) image.fail("Spacing", "expected 3 numbers > 0, got " + io::quoted(*image.text("Spacing")));
        spacing = {s[0], s[1], s[2]};
    }
    if (image.text("Direction")) {
        const auto d = image.numbers("Direction", 9);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                if (d[std::size_t(3 * r + c)] != (r == c ? 1.0 : 0.0))
                    image.fail("Direction", "only the identity is supported (volref reads axis-aligned grids), got " +
                                                io::quoted(*image.text("Direction")));
    }
    if (doc.pieces.empty()) throw Error(where + ": no <Piece> in <ImageData>");
    if (doc.pieces.size() > 1)
        Attributes(doc.pieces[1], where).fail("", "several pieces are not supported (volref reads one)");
    const Attributes piece(doc.pieces[0], where);
    const std::string extent_key = piece.text("Extent") ? "Extent" : "WholeExtent";
    const Attributes& extent_owner = piece.text("Extent") ? piece : image;
    if (!extent_owner.text(extent_key)) piece.fail("", "missing attribute 'Extent'");
    const auto ext = extent(extent_owner, extent_key);
    for (int a = 0; a < 3; ++a) {
        volume.dims[std::size_t(a)] = ext[std::size_t(2 * a + 1)] - ext[std::size_t(2 * a)] + 1;
        volume.origin[a] = origin[a] + double(ext[std::size_t(2 * a)]) * spacing[a];
    }
    volume.spacing = spacing;
    const std::size_t count = checked_voxel_count(volume.dims, where, sizeof(double));

    // The scalar array: the one PointData's Scalars names, else the first.
    if (!doc.point_data || doc.arrays.empty())
        piece.fail("", "no <DataArray> in <PointData> (volref reads point data)");
    const Element* chosen = &doc.arrays.front();
    if (const std::string* name = doc.point_data->find("Scalars")) {
        chosen = nullptr;
        for (const Element& e : doc.arrays)
            if (const std::string* n = e.find("Name"); n && *n == *name) chosen = &e;
        if (!chosen)
            Attributes(*doc.point_data, where).fail("Scalars", "no DataArray is named " + io::quoted(*name));
    }
    const Attributes array(*chosen, where);
    const ScalarType type = array_type(array);
    if (const auto nc = array.text("NumberOfComponents"); nc && *nc != "1")
        array.fail("NumberOfComponents", io::quoted(*nc) + ": only 1 component is supported");
    const std::string format = array.text("format").value_or("ascii");
    const std::string array_where =
        where + ": line " + std::to_string(chosen->line) + ": DataArray " + io::quoted(array.text("Name").value_or(""));
    const std::size_t expected = count * scalar_type_size(type);
    if (format == "ascii") {
        io::store_samples(volume, type, io::decode_ascii_samples(chosen->text, type, count, where, chosen->line), where);
        return volume;
    }
    std::string samples;
    if (format == "binary") {
        std::string text;
        for (char c : chosen->text)
            if (!is_space(c)) text += c;
        BinarySource src(text, true, array_where);
        samples = binary_samples(src, expected, word, order, compressed, array_where);
    } else if (format == "appended") {
        if (!doc.appended || appended_start == std::string::npos)
            array.fail("format", "appended, but the file has no <AppendedData>");
        const auto offset_text = array.text("offset");
        if (!offset_text) array.fail("", "missing attribute 'offset' (format appended)");
        const auto offset = io::parse_number(*offset_text);
        if (!offset || *offset < 0 || std::floor(*offset) != *offset || *offset > 1e18)
            array.fail("offset", "expected an integer >= 0, got " + io::quoted(*offset_text));
        const std::string encoding = Attributes(*doc.appended, where).text("encoding").value_or("raw");
        if (encoding != "raw" && encoding != "base64")
            Attributes(*doc.appended, where).fail("encoding", "expected raw or base64, got " + io::quoted(encoding));
        const std::string_view all = std::string_view(file).substr(appended_start);
        const auto off = static_cast<std::size_t>(*offset);
        if (off > all.size())
            array.fail("offset", std::to_string(off) + " is past the end of the appended data (" +
                                     std::to_string(all.size()) + " bytes)");
        BinarySource src(all.substr(off), encoding == "base64", array_where);
        samples = binary_samples(src, expected, word, order, compressed, array_where);
    } else {
        array.fail("format", "expected ascii, binary or appended, got " + io::quoted(format));
    }
    io::store_sample_bytes(volume, type, order, samples, where);
    return volume;
}

}  // namespace volref
