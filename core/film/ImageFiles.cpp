// libvolref_image_files.so: OpenImageIO behind the two entry points of ImageFiles.h.
#include "core/film/ImageFiles.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

namespace {

using volref::image_files::ReadResult;
using volref::image_files::SampleKind;
using volref::image_files::WriteRequest;

// The first line of an OpenImageIO message.
std::string first_line(std::string why) {
    if (const auto nl = why.find('\n'); nl != std::string::npos) why.resize(nl);
    return why;
}

int fail(const std::string& message, char* error, std::size_t size) {
    volref::image_files::copy_message(message, error, size);
    return 1;
}

OIIO::TypeDesc type_of(SampleKind kind) {
    switch (kind) {
        case SampleKind::UInt8: return OIIO::TypeDesc::UINT8;
        case SampleKind::UInt16: return OIIO::TypeDesc::UINT16;
        case SampleKind::Float32: break;
    }
    return OIIO::TypeDesc::FLOAT;
}

// Bits per sample of an integer image, 0 for floating point.
int integer_bits(const OIIO::ImageSpec& spec) {
    const OIIO::TypeDesc t = spec.format;
    if (t.basetype == OIIO::TypeDesc::FLOAT || t.basetype == OIIO::TypeDesc::HALF || t.basetype == OIIO::TypeDesc::DOUBLE)
        return 0;
    return spec.get_int_attribute("oiio:BitsPerSample", int(t.size()) * 8);
}

}  // namespace

extern "C" int volref_image_files_version() { return volref::image_files::kInterfaceVersion; }

extern "C" int volref_image_files_write(const WriteRequest* rq, char* error, std::size_t size) {
    try {
        auto out = OIIO::ImageOutput::create(rq->path);
        if (!out) return fail("cannot create an image writer: " + first_line(OIIO::geterror()), error, size);
        OIIO::ImageSpec spec(rq->width, rq->height, rq->channels, type_of(rq->kind));
        spec.channelnames.assign(rq->channel_names, rq->channel_names + rq->channels);
        spec.alpha_channel = rq->alpha_channel;
        spec.z_channel = rq->z_channel;
        if (rq->unassociated_alpha) spec.attribute("oiio:UnassociatedAlpha", 1);
        if (rq->compression) spec.attribute("compression", rq->compression);
        // No clock in the file: OpenImageIO writes the current time (EXR capDate, TIFF DateTime) unless
        // DateTime is set, so two renders of one scene would differ in their bytes.
        spec.attribute("DateTime", "");
        if (!out->open(rq->path, spec) || !out->write_image(spec.format, rq->pixels) || !out->close())
            return fail("cannot write the image: " + first_line(out->geterror()), error, size);
        return 0;
    } catch (const std::exception& e) {
        return fail(std::string("cannot write the image: ") + e.what(), error, size);
    }
}

extern "C" int volref_image_files_read(const char* path, ReadResult* result, char* error, std::size_t size) {
    try {
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);  // give the stored values; the caller premultiplies in double
        auto in = OIIO::ImageInput::open(path, &config);
        if (!in) {
            const std::string why = first_line(OIIO::geterror());
            return fail("cannot read the image" + (why.empty() ? std::string() : ": " + why), error, size);
        }
        const OIIO::ImageSpec spec = in->spec();
        const int w = spec.width, h = spec.height, n = spec.nchannels;
        const std::size_t count = std::size_t(w) * std::size_t(h) * std::size_t(n);
        result->width = w;
        result->height = h;
        for (int c = 0; c < n; ++c) result->add_channel_name(result->owner, spec.channel_name(c).c_str());
        double* data = result->pixels(result->owner, count);
        const OIIO::TypeDesc native = spec.format;
        bool ok = false;
        if (native == OIIO::TypeDesc::UINT8) {
            std::vector<std::uint8_t> bytes(count);
            ok = in->read_image(0, 0, 0, n, native, bytes.data());
            for (std::size_t i = 0; ok && i < count; ++i) data[i] = double(bytes[i]) / 255.0;
        } else if (native == OIIO::TypeDesc::UINT16) {
            std::vector<std::uint16_t> words(count);
            ok = in->read_image(0, 0, 0, n, native, words.data());
            for (std::size_t i = 0; ok && i < count; ++i) data[i] = double(words[i]) / 65535.0;
        } else {
            ok = in->read_image(0, 0, 0, n, OIIO::TypeDesc::DOUBLE, data);
        }
        if (!ok) return fail("cannot read the pixels: " + first_line(in->geterror()), error, size);
        in->close();
        result->bits = integer_bits(spec);
        result->unassociated_alpha = spec.get_int_attribute("oiio:UnassociatedAlpha", 0) != 0 ? 1 : 0;
        return 0;
    } catch (const std::exception& e) {
        return fail(std::string("cannot read the image: ") + e.what(), error, size);
    }
}
