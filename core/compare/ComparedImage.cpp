#include "core/compare/ComparedImage.h"
#include "core/film/Background.h"

#include <algorithm>
#include <cstdint>

#include <OpenImageIO/imageio.h>

#include "core/Error.h"
#include "core/io/InputFile.h"

namespace volref::compare {

namespace {

int find_channel(const OIIO::ImageSpec& spec, const std::string& name) {
    for (int c = 0; c < spec.nchannels; ++c)
        if (spec.channel_name(c) == name) return c;
    return -1;
}

// Bits per sample of an integer image, 0 for floating point.
int integer_bits(const OIIO::ImageSpec& spec) {
    const OIIO::TypeDesc t = spec.format;
    if (t.basetype == OIIO::TypeDesc::FLOAT || t.basetype == OIIO::TypeDesc::HALF ||
        t.basetype == OIIO::TypeDesc::DOUBLE)
        return 0;
    return spec.get_int_attribute("oiio:BitsPerSample", int(t.size()) * 8);
}

}  // namespace

std::string ComparedImage::description() const {
    std::string s = std::to_string(rgba.width) + "x" + std::to_string(rgba.height) + ", ";
    s += bits > 0 ? std::to_string(bits) + "-bit" : std::string("float");
    s += unassociated ? ", unassociated alpha (premultiplied here)" : ", premultiplied";
    if (!error.empty()) s += ", error channel";
    return s;
}

ComparedImage read_compared_image(const std::filesystem::path& path, const std::optional<glm::dvec4>& background) {
    const std::string name = path.string();
    io::check_input_file(path, name);  // a FIFO or /dev/zero is refused before OpenImageIO opens it
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);  // give the stored values; we premultiply in double
    auto in = OIIO::ImageInput::open(name, &config);
    if (!in) {
        std::string why = OIIO::geterror();
        if (const auto nl = why.find('\n'); nl != std::string::npos) why.resize(nl);
        throw Error(name + ": cannot read the image" + (why.empty() ? std::string() : ": " + why));
    }
    const OIIO::ImageSpec spec = in->spec();
    const int w = spec.width, h = spec.height, n = spec.nchannels;
    const std::size_t count = std::size_t(w) * std::size_t(h) * std::size_t(n);
    std::vector<double> data(count);
    // 8- and 16-bit samples are read as stored and scaled here in double (v / (2^bits - 1)): OIIO's own
    // conversion to double goes through float (errors of 6e-8 on 8-bit values).
    const OIIO::TypeDesc native = spec.format;
    const bool small_int = native == OIIO::TypeDesc::UINT8 || native == OIIO::TypeDesc::UINT16;
    std::vector<std::uint16_t> words;
    std::vector<std::uint8_t> bytes;
    bool ok = false;
    if (native == OIIO::TypeDesc::UINT8) {
        bytes.resize(count);
        ok = in->read_image(0, 0, 0, n, native, bytes.data());
        for (std::size_t i = 0; ok && i < count; ++i) data[i] = double(bytes[i]) / 255.0;
    } else if (native == OIIO::TypeDesc::UINT16) {
        words.resize(count);
        ok = in->read_image(0, 0, 0, n, native, words.data());
        for (std::size_t i = 0; ok && i < count; ++i) data[i] = double(words[i]) / 65535.0;
    }
    if (!small_int) ok = in->read_image(0, 0, 0, n, OIIO::TypeDesc::DOUBLE, data.data());
    if (!ok) {
        std::string why = in->geterror();
        if (const auto nl = why.find('\n'); nl != std::string::npos) why.resize(nl);
        throw Error(name + ": cannot read the pixels: " + why);
    }
    in->close();

    int rgb[3] = {find_channel(spec, "R"), find_channel(spec, "G"), find_channel(spec, "B")};
    if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
        const int y = find_channel(spec, "Y");
        if (y < 0) throw Error(name + ": no R, G, B (or Y) channels to compare");
        rgb[0] = rgb[1] = rgb[2] = y;
    }
    const int a = find_channel(spec, "A");
    const int e = find_channel(spec, "error");
    const int fault = find_channel(spec, "fault");

    ComparedImage out;
    out.path = path;
    out.bits = integer_bits(spec);
    out.unassociated = a >= 0 && spec.get_int_attribute("oiio:UnassociatedAlpha", 0) != 0;
    out.rgba = Image(w, h, {"R", "G", "B", "A"});
    if (out.unassociated && out.bits > 0) out.stored.resize(std::size_t(w) * std::size_t(h) * 4);
    if (e >= 0) out.error.resize(std::size_t(w) * std::size_t(h));
    if (fault >= 0) out.fault.resize(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const double* px = &data[p * std::size_t(n)];
            const double alpha = a >= 0 ? px[a] : 1.0;
            double c[4] = {px[rgb[0]], px[rgb[1]], px[rgb[2]], alpha};
            if (!out.stored.empty())
                for (int k = 0; k < 4; ++k) out.stored[p * 4 + std::size_t(k)] = c[k];
            if (out.unassociated)
                for (int k = 0; k < 3; ++k) c[k] *= alpha;  // C = u a
            else if (background)  // composite an associated input
                composite_over_background(c, *background);
            for (int k = 0; k < 4; ++k) out.rgba.at(x, y, std::size_t(k)) = c[k];
            if (e >= 0) out.error[p] = px[e];
            if (fault >= 0) out.fault[p] = px[fault] != 0.0;
        }
    return out;
}

std::vector<std::array<int, 2>> exclude_faults(ComparedImage& a, ComparedImage& b) {
    std::vector<std::array<int, 2>> out;
    if (a.fault.empty() && b.fault.empty()) return out;
    const int w = std::min(a.rgba.width, b.rgba.width), h = std::min(a.rgba.height, b.rgba.height);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
            if (!((!a.fault.empty() && a.fault[p]) || (!b.fault.empty() && b.fault[p]))) continue;
            out.push_back({x, y});
            for (std::size_t c = 0; c < 4; ++c) a.rgba.at(x, y, c) = b.rgba.at(x, y, c) = 0.0;
            if (!a.error.empty()) a.error[p] = 0.0;
            if (!b.error.empty()) b.error[p] = 0.0;
        }
    return out;
}

}  // namespace volref::compare
