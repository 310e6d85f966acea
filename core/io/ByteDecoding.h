// Byte-level helpers shared by the volume readers (NRRD, raw, NIfTI, MetaImage, VTK legacy and XML,
// VolPack .den): reading a whole file, inflating gzip/zlib data, cutting the samples out of a data
// region, turning stored samples of any ScalarType and byte order into doubles (decode_samples; ascii
// text: decode_ascii_samples), and storing them in a Volume (store_samples, the one place a reader
// fills a Volume's values). Every failure is a volref::Error whose one-line message
// starts with the `where` it is given (the path of the file at fault).
#pragma once
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <sys/types.h>
#include <vector>

#include <zlib.h>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/grid/Volume.h"
#include "core/InputFile.h"

namespace volref::io {

static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big,
              "volref's readers assume a little- or big-endian host");

// `text` quoted for an error message: control and non-ASCII bytes escaped as \xNN so the message
// stays one line of plain text, and cut after `max_len` bytes.
inline std::string quoted(std::string_view text, std::size_t max_len = 64) {
    static const char* const kHex = "0123456789abcdef";
    std::string out = "'";
    for (std::size_t i = 0; i < text.size() && i < max_len; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c < 0x20 || c >= 0x7f) {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        } else {
            out += char(c);
        }
    }
    if (text.size() > max_len) out += "...";
    return out + "'";
}

using FileHandle = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

// `path` opened for reading; a directory, a missing or an unreadable file is an Error.
// A FIFO, a device or a socket is refused by type before it is opened (InputFile.h).
inline FileHandle open_for_reading(const std::filesystem::path& path) {
    check_input_file(path, path.string());
    FileHandle f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) throw Error(path.string() + ": cannot read file: " + std::strerror(errno));
    return f;
}

// read_file_bytes (the whole contents of a file): InputFile.h.

// The first `limit` bytes of the file at `path` (all of it when it is at most `limit` bytes long);
// `whole` tells whether that is the whole file.
inline std::string read_file_prefix(const std::filesystem::path& path, std::size_t limit, bool& whole) {
    FileHandle f = open_for_reading(path);
    std::string bytes(limit + 1, '\0');
    std::size_t got = 0;
    while (got < bytes.size()) {
        const std::size_t n = std::fread(bytes.data() + got, 1, bytes.size() - got, f.get());
        if (n == 0) break;
        got += n;
    }
    if (std::ferror(f.get())) throw Error(path.string() + ": cannot read file: " + std::strerror(errno));
    whole = got <= limit;
    bytes.resize(std::min(got, limit));
    return bytes;
}

// The result of inflate_stream: how many leading bytes were skipped, and the bytes kept after them.
struct Inflated {
    std::uint64_t skipped = 0;
    std::string data;
};

// Inflates a gzip or zlib stream, told apart by its header (zlib's inflateInit2 with 15 + 32).
// Concatenated gzip members are read one after the other, as gunzip does. The first `skip`
// decompressed bytes are discarded; then at most `keep_limit` bytes are kept and inflation stops, so
// a caller that asks for one byte more than it needs sees that the stream is too long without
// inflating all of it. A damaged stream (bad header, bad data, bad CRC, or compressed data that ends
// early) is an Error.
inline Inflated inflate_stream(std::string_view in, std::uint64_t skip, std::size_t keep_limit,
                               const std::string& where) {
    // zlib counts bytes in uInt, so large buffers are handed over in pieces of at most 1 GiB.
    constexpr std::size_t kPiece = std::size_t(1) << 30;
    z_stream zs{};
    if (inflateInit2(&zs, 15 + 32) != Z_OK) throw Error(where + ": cannot initialise zlib's inflate");
    std::unique_ptr<z_stream, int (*)(z_stream*)> guard(&zs, &inflateEnd);

    const auto* in_base = reinterpret_cast<const Bytef*>(in.data());
    zs.next_in = const_cast<Bytef*>(in_base);
    zs.avail_in = 0;
    Inflated out;
    std::size_t kept = 0;
    std::vector<Bytef> scratch(std::size_t(1) << 16);
    for (;;) {
        // Where this call's output goes: the scratch buffer while skipping, then `out.data`.
        const bool skipping = out.skipped < skip;
        Bytef* dst = nullptr;
        std::size_t room = 0;
        if (skipping) {
            dst = scratch.data();
            room = static_cast<std::size_t>(std::min<std::uint64_t>(scratch.size(), skip - out.skipped));
        } else {
            if (kept == keep_limit) break;
            if (kept == out.data.size())
                out.data.resize(std::min(keep_limit, std::max<std::size_t>(2 * kept, std::size_t(1) << 20)));
            dst = reinterpret_cast<Bytef*>(out.data.data()) + kept;
            room = std::min(kPiece, out.data.size() - kept);
        }
        zs.next_out = dst;
        zs.avail_out = static_cast<uInt>(room);
        const std::size_t in_pos = static_cast<std::size_t>(zs.next_in - in_base);
        if (zs.avail_in == 0) zs.avail_in = static_cast<uInt>(std::min(kPiece, in.size() - in_pos));

        throw_if_cancelled();  // SIGINT / SIGTERM while inflating (each piece)
        const int ret = inflate(&zs, Z_NO_FLUSH);
        const std::size_t produced = room - zs.avail_out;
        if (skipping)
            out.skipped += produced;
        else
            kept += produced;

        if (ret == Z_OK) continue;
        if (ret == Z_STREAM_END) {
            const std::size_t used = static_cast<std::size_t>(zs.next_in - in_base);
            if (used == in.size()) break;
            // Another gzip member (magic 1f 8b) may follow; anything else after the end is damage.
            if (in.size() - used >= 2 && static_cast<unsigned char>(in[used]) == 0x1f &&
                static_cast<unsigned char>(in[used + 1]) == 0x8b) {
                inflateReset(&zs);
                continue;
            }
            throw Error(where + ": corrupt gzip stream: " + std::to_string(in.size() - used) +
                        " bytes of trailing data after the end of the compressed stream");
        }
        if (ret == Z_BUF_ERROR && zs.avail_in == 0) {
            if (static_cast<std::size_t>(zs.next_in - in_base) == in.size())
                throw Error(where + ": corrupt gzip stream: the compressed data ends early");
            continue;  // the next piece of input is handed over at the top of the loop
        }
        if (ret == Z_MEM_ERROR) throw Error(where + ": out of memory while inflating gzip data");
        throw Error(where + ": corrupt gzip stream (zlib: " + (zs.msg ? zs.msg : zError(ret)) + ")");
    }
    out.data.resize(kept);
    return out;
}

// How the samples of a binary data region are stored.
enum class BinaryEncoding { Raw, Gzip };

// The message for data shorter than the dims and type need.
inline std::string truncated_message(const std::string& where, std::size_t expected, std::size_t found,
                                     const char* unit = "bytes") {
    return where + ": truncated: expected " + std::to_string(expected) + " " + unit + " of data, found " +
           std::to_string(found);
}

// The message for data longer than the dims and type need.
inline std::string too_long_message(const std::string& where, std::size_t expected, const std::string& found,
                                    const char* unit = "bytes") {
    return where + ": dims do not match the data size: expected " + std::to_string(expected) + " " + unit +
           " of data, found " + found;
}

// The `expected` bytes of samples within `region` (which `storage` may come to hold, for gzip).
// byte_skip counts the bytes before the samples: of the file region for raw data, of the decompressed
// data for gzip. byte_skip -1 (raw only) means the samples end the region, whatever precedes them.
// Otherwise the data must hold exactly byte_skip + expected bytes: fewer is "truncated", more means
// the dims do not match the data.
inline std::string_view sample_bytes(std::string_view region, BinaryEncoding encoding, std::int64_t byte_skip,
                                     std::size_t expected, std::string& storage, const std::string& where) {
    if (encoding == BinaryEncoding::Raw) {
        if (byte_skip == -1) {
            if (region.size() < expected) throw Error(truncated_message(where, expected, region.size()));
            return region.substr(region.size() - expected);
        }
        const auto skip = static_cast<std::uint64_t>(byte_skip);
        const std::size_t found = skip >= region.size() ? 0 : region.size() - static_cast<std::size_t>(skip);
        if (found < expected) throw Error(truncated_message(where, expected, found));
        if (found > expected) throw Error(too_long_message(where, expected, std::to_string(found)));
        return region.substr(static_cast<std::size_t>(skip));
    }
    if (byte_skip < 0) throw Error(where + ": byte skip -1 is only allowed with raw encoding");
    Inflated inflated = inflate_stream(region, static_cast<std::uint64_t>(byte_skip), expected + 1, where);
    if (inflated.data.size() < expected)
        throw Error(truncated_message(where, expected, inflated.data.size()) + " after inflating");
    if (inflated.data.size() > expected)
        throw Error(too_long_message(where, expected, "more after inflating"));
    storage = std::move(inflated.data);
    return storage;
}

// One stored value of type T at `p`, its bytes reversed first when `swap`.
template <typename T>
T load_value(const char* p, bool swap) {
    char buf[sizeof(T)];
    if (swap)
        std::reverse_copy(p, p + sizeof(T), buf);
    else
        std::memcpy(buf, p, sizeof(T));
    T value;
    std::memcpy(&value, buf, sizeof(T));
    return value;
}

template <typename T>
void decode_as(std::string_view bytes, bool swap, std::vector<double>& out) {
    const std::size_t n = bytes.size() / sizeof(T);
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = static_cast<double>(load_value<T>(bytes.data() + i * sizeof(T), swap));
}

// The samples in `bytes` (stored as `type` in byte order `order`) as doubles. Every supported type
// converts to double exactly; non-finite floats are kept as they are.
inline std::vector<double> decode_samples(std::string_view bytes, ScalarType type, std::endian order) {
    const bool swap = order != std::endian::native && scalar_type_size(type) > 1;
    std::vector<double> out;
    switch (type) {
        case ScalarType::U8: decode_as<std::uint8_t>(bytes, swap, out); break;
        case ScalarType::I8: decode_as<std::int8_t>(bytes, swap, out); break;
        case ScalarType::U16: decode_as<std::uint16_t>(bytes, swap, out); break;
        case ScalarType::I16: decode_as<std::int16_t>(bytes, swap, out); break;
        case ScalarType::U32: decode_as<std::uint32_t>(bytes, swap, out); break;
        case ScalarType::I32: decode_as<std::int32_t>(bytes, swap, out); break;
        case ScalarType::F32: decode_as<float>(bytes, swap, out); break;
        case ScalarType::F64: decode_as<double>(bytes, swap, out); break;
    }
    return out;
}

// A whole word as a number in the C locale: an optional sign, decimal or exponent notation, "nan" or
// "inf" (any case). nullopt for anything else, including numbers beyond double's range.
inline std::optional<double> parse_number(std::string_view s) {
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    if (s.empty() || s.front() == '+' || (s.size() > 1 && s[0] == '-' && s[1] == '+')) return std::nullopt;
    double value = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return value;
}

// `count` samples written as text (numbers separated by white space) and stored as `type`: integer
// types need whole numbers within the type's range; f32 values are rounded to float, as a float file
// would hold them. Fewer numbers is "truncated", more is "dims do not match". `first_line` (when > 0)
// is the line of the file on which `text` starts, so that a bad number's message names its line.
inline std::vector<double> decode_ascii_samples(std::string_view text, ScalarType type, std::size_t count,
                                                const std::string& where, std::size_t first_line = 0) {
    std::vector<double> values;
    values.reserve(count);
    std::size_t line = first_line;
    const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; };
    std::size_t i = 0;
    while (i < text.size()) {
        while (i < text.size() && is_space(text[i])) {
            if (text[i] == '\n') ++line;
            ++i;
        }
        const std::size_t start = i;
        while (i < text.size() && !is_space(text[i])) ++i;
        if (i == start) break;
        if (values.size() == count) throw Error(too_long_message(where, count, "more", "values"));
        if (cancel_polled(std::int64_t(values.size()))) throw_if_cancelled();  // SIGINT / SIGTERM while reading
        const std::string_view word = text.substr(start, i - start);
        const std::string at = where + (first_line > 0 ? ": line " + std::to_string(line) : std::string()) +
                               ": ascii sample " + std::to_string(values.size()) + ": ";
        const auto v = parse_number(word);
        if (!v) throw Error(at + quoted(word) + " is not a number");
        double x = *v;
        if (scalar_type_is_integer(type)) {
            const auto [lo, hi] = scalar_type_range(type);
            if (!(x >= lo && x <= hi && std::floor(x) == x))
                throw Error(at + quoted(word) + " is not an integer in the range of " + scalar_type_name(type));
        } else if (type == ScalarType::F32) {
            if (std::isfinite(x) && std::fabs(x) > double(std::numeric_limits<float>::max()))
                throw Error(at + quoted(word) + " is out of the range of f32");
            x = double(float(x));
        }
        values.push_back(x);
    }
    if (values.size() < count) throw Error(truncated_message(where, count, values.size(), "values"));
    return values;
}

// Allocates the volume's storage for `type` (its dims must be set; the voxel count is checked against
// 2^38 bytes and the memory limit at the type's size) and records `type` as the file's type.
inline void allocate_samples(Volume& volume, ScalarType type, const std::string& where) {
    const std::size_t count = checked_voxel_count(volume.dims, where, scalar_type_size(type));
    volume.type = type;
    volume.values.allocate(type, count, false);
}

// Reverses the bytes of every sample in place when the file's byte order is not the host's.
inline void to_native_order(VoxelArray& values, std::endian order) {
    const std::size_t size = scalar_type_size(values.type());
    if (order == std::endian::native || size == 1) return;
    auto* p = static_cast<unsigned char*>(values.raw());
    const std::size_t n = values.size();
    for (std::size_t i = 0; i < n; ++i, p += size) std::reverse(p, p + size);
}

// The one place a reader fills a Volume's samples from decoded numbers (the ascii encodings):
// `values` (i fastest, each exactly representable in `type`, as decode_ascii_samples returns them)
// are stored in `type`, which becomes the file's type. A count that does not match the dims is a
// reader bug, reported as an Error.
inline void store_samples(Volume& volume, ScalarType type, const std::vector<double>& values, const std::string& where) {
    allocate_samples(volume, type, where);
    if (values.size() != volume.values.size())
        throw Error(where + ": internal error: " + std::to_string(values.size()) + " samples for " +
                    std::to_string(volume.values.size()) + " voxels");
    volume.values.visit_mutable([&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        for (std::size_t i = 0; i < values.size(); ++i) p[i] = T(values[i]);
    });
}

// Binary samples already in memory (`bytes`: exactly the dims' count of `type`, byte order `order`)
// copied into the volume's typed storage and put in the host's byte order.
inline void store_sample_bytes(Volume& volume, ScalarType type, std::endian order, std::string_view bytes,
                               const std::string& where) {
    allocate_samples(volume, type, where);
    if (bytes.size() != volume.values.bytes())
        throw Error(where + ": internal error: " + std::to_string(bytes.size()) + " bytes of samples for " +
                    std::to_string(volume.values.size()) + " voxels of " + scalar_type_name(type));
    if (!bytes.empty()) std::memcpy(volume.values.raw(), bytes.data(), bytes.size());
    to_native_order(volume.values, order);
}

// A region of bytes read front to back: a string in memory, or a file from `offset` to its end
// (read in pieces, never whole). size() is the region's length.
class ByteSource {
public:
    explicit ByteSource(std::string_view memory) : memory_(memory), size_(memory.size()) {}
    ByteSource(const std::filesystem::path& path, std::uint64_t offset, const std::string& where)
        : file_(open_for_reading(path)), where_(where) {
        std::error_code ec;
        const std::uint64_t total = std::filesystem::file_size(path, ec);
        if (ec) throw Error(where + ": cannot read file: " + ec.message());
        size_ = offset >= total ? 0 : total - offset;
        base_ = std::min(offset, total);
        seek(base_);
    }
    std::uint64_t size() const { return size_; }
    std::uint64_t consumed() const { return pos_; }
    std::uint64_t remaining() const { return size_ - pos_; }
    // Skips n bytes (n <= remaining()).
    void skip(std::uint64_t n) {
        if (file_) seek(base_ + pos_ + n);
        pos_ += n;
    }
    // Reads up to n bytes into dst; returns how many (fewer only at the end of the region).
    std::size_t read(void* dst, std::size_t n) {
        n = std::size_t(std::min<std::uint64_t>(n, remaining()));
        if (n == 0) return 0;
        if (!file_) {
            std::memcpy(dst, memory_.data() + pos_, n);
        } else {
            std::size_t got = 0;
            while (got < n) {
                const std::size_t r = std::fread(static_cast<char*>(dst) + got, 1, n - got, file_.get());
                if (r == 0) {
                    if (std::ferror(file_.get())) throw Error(where_ + ": cannot read file: " + std::strerror(errno));
                    break;  // the file shrank while being read
                }
                got += r;
            }
            n = got;
        }
        pos_ += n;
        return n;
    }

private:
    void seek(std::uint64_t absolute) {
        if (fseeko(file_.get(), off_t(absolute), SEEK_SET) != 0)
            throw Error(where_ + ": cannot read file: " + std::strerror(errno));
    }
    std::string_view memory_;
    FileHandle file_{nullptr, &std::fclose};
    std::string where_;
    std::uint64_t size_ = 0, pos_ = 0, base_ = 0;
};

// Inflates the gzip or zlib stream read from `in` (as inflate_stream: concatenated gzip members,
// the same errors) straight into dst: the first `skip` decompressed bytes are discarded, the next
// `room` bytes go to dst. Returns how many bytes dst received, plus 1 when the stream holds more
// (so a return of room + 1 means the data is longer than room). Input is read in 256 KiB pieces.
inline std::size_t inflate_into(ByteSource& in, std::uint64_t skip, char* dst, std::size_t room, const std::string& where) {
    constexpr std::size_t kPiece = std::size_t(1) << 30;
    z_stream zs{};
    if (inflateInit2(&zs, 15 + 32) != Z_OK) throw Error(where + ": cannot initialise zlib's inflate");
    std::unique_ptr<z_stream, int (*)(z_stream*)> guard(&zs, &inflateEnd);
    std::vector<Bytef> input(std::size_t(1) << 18), scratch(std::size_t(1) << 16);
    std::uint64_t skipped = 0;
    std::size_t kept = 0;
    bool more = false;
    const auto refill = [&] {
        if (zs.avail_in == 0) {
            zs.next_in = input.data();
            zs.avail_in = static_cast<uInt>(in.read(input.data(), input.size()));
        }
    };
    for (;;) {
        Bytef* out = nullptr;
        std::size_t want = 0;
        const bool skipping = skipped < skip;
        if (skipping) {
            out = scratch.data();
            want = static_cast<std::size_t>(std::min<std::uint64_t>(scratch.size(), skip - skipped));
        } else if (kept < room) {
            out = reinterpret_cast<Bytef*>(dst) + kept;
            want = std::min(kPiece, room - kept);
        } else {
            out = scratch.data();  // one byte more tells "longer than room"
            want = 1;
        }
        zs.next_out = out;
        zs.avail_out = static_cast<uInt>(want);
        refill();
        throw_if_cancelled();  // SIGINT / SIGTERM while inflating (each piece)
        const int ret = inflate(&zs, Z_NO_FLUSH);
        const std::size_t produced = want - zs.avail_out;
        if (skipping)
            skipped += produced;
        else if (kept < room)
            kept += produced;
        else if (produced > 0)
            more = true;
        if (more) break;

        if (ret == Z_OK) continue;
        if (ret == Z_STREAM_END) {
            refill();
            if (zs.avail_in == 0) break;
            // Another gzip member (magic 1f 8b) may follow; anything else after the end is damage.
            if (zs.avail_in < 2 && in.remaining() > 0) {  // the magic straddles two pieces
                std::memmove(input.data(), zs.next_in, zs.avail_in);
                zs.next_in = input.data();
                zs.avail_in += static_cast<uInt>(in.read(input.data() + zs.avail_in, input.size() - zs.avail_in));
            }
            if (zs.avail_in >= 2 && zs.next_in[0] == 0x1f && zs.next_in[1] == 0x8b) {
                inflateReset(&zs);
                continue;
            }
            throw Error(where + ": corrupt gzip stream: " + std::to_string(zs.avail_in + in.remaining()) +
                        " bytes of trailing data after the end of the compressed stream");
        }
        if (ret == Z_BUF_ERROR && zs.avail_in == 0) {
            if (in.remaining() == 0) throw Error(where + ": corrupt gzip stream: the compressed data ends early");
            continue;  // the next piece of input is read at the top of the loop
        }
        if (ret == Z_MEM_ERROR) throw Error(where + ": out of memory while inflating gzip data");
        throw Error(where + ": corrupt gzip stream (zlib: " + (zs.msg ? zs.msg : zError(ret)) + ")");
    }
    return kept + (more ? 1 : 0);
}

// Reads the volume's binary samples (its dims set; `type` in byte order `order`) from `in` straight
// into its typed storage, with sample_bytes' rules and messages: byte_skip counts the bytes before
// the samples (of the region for raw data, of the decompressed data for gzip); -1 (raw only) means
// the samples end the region. Raw data must hold exactly byte_skip + the samples' bytes, gzip data
// must inflate to exactly that. No second copy of the data is made: the peak is the volume itself
// (plus 320 KiB of buffers for gzip).
inline void read_samples(Volume& volume, ScalarType type, std::endian order, ByteSource& in, BinaryEncoding encoding,
                         std::int64_t byte_skip, const std::string& where) {
    const std::size_t expected = checked_voxel_count(volume.dims, where, scalar_type_size(type)) * scalar_type_size(type);
    if (encoding == BinaryEncoding::Raw) {
        const std::uint64_t size = in.size();
        if (byte_skip == -1) {
            if (size < expected) throw Error(truncated_message(where, expected, std::size_t(size)));
            in.skip(size - expected);
        } else {
            const auto skip = static_cast<std::uint64_t>(byte_skip);
            const std::uint64_t found = skip >= size ? 0 : size - skip;
            if (found < expected) throw Error(truncated_message(where, expected, std::size_t(found)));
            if (found > expected) throw Error(too_long_message(where, expected, std::to_string(found)));
            in.skip(skip);
        }
        allocate_samples(volume, type, where);
        const std::size_t got = in.read(volume.values.raw(), expected);
        if (got < expected) throw Error(truncated_message(where, expected, got));
    } else {
        if (byte_skip < 0) throw Error(where + ": byte skip -1 is only allowed with raw encoding");
        allocate_samples(volume, type, where);
        const std::size_t got =
            inflate_into(in, static_cast<std::uint64_t>(byte_skip), static_cast<char*>(volume.values.raw()), expected, where);
        if (got < expected) throw Error(truncated_message(where, expected, got) + " after inflating");
        if (got > expected) throw Error(too_long_message(where, expected, "more after inflating"));
    }
    to_native_order(volume.values, order);
}

}  // namespace volref::io
