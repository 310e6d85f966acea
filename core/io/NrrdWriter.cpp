#include "core/io/NrrdWriter.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>

#include <zlib.h>

#include "core/Error.h"
#include "core/io/OutputFile.h"
#include "core/io/VoxelEncoding.h"

namespace fs = std::filesystem;

namespace volref {

namespace {

// The shortest text that reads back as x.
std::string num(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// NRRD key/value escaping: backslash and newline.
std::string escape_value(const std::string& v) {
    std::string out;
    for (char c : v) {
        if (c == '\\') out += "\\\\";
        else if (c == '\n') out += "\\n";
        else out += c;
    }
    return out;
}

struct FileCloser {
    void operator()(std::FILE* f) const {
        if (f) std::fclose(f);
    }
};

// Writes bytes to the temporary file, through zlib for gzip. Throws Error naming `path` on failure.
class Sink {
public:
    Sink(std::FILE* file, bool gzip, const fs::path& path) : file_(file), gzip_(gzip), path_(path) {
        if (gzip_) {
            std::memset(&zs_, 0, sizeof zs_);
            if (deflateInit2(&zs_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
                throw Error(path_.string() + ": cannot start gzip compression");
            active_ = true;
            out_.resize(1 << 18);
        }
    }
    ~Sink() {
        if (active_) deflateEnd(&zs_);
    }
    Sink(const Sink&) = delete;
    Sink& operator=(const Sink&) = delete;

    void write(const unsigned char* data, std::size_t size) {
        if (!gzip_) {
            raw(data, size);
            return;
        }
        zs_.next_in = const_cast<unsigned char*>(data);
        zs_.avail_in = uInt(size);  // callers pass chunks well below 4 GiB
        pump(Z_NO_FLUSH);
    }
    void finish() {
        if (!gzip_) return;
        zs_.next_in = nullptr;
        zs_.avail_in = 0;
        pump(Z_FINISH);
        deflateEnd(&zs_);
        active_ = false;
    }

private:
    void raw(const unsigned char* data, std::size_t size) {
        if (size && std::fwrite(data, 1, size, file_) != size)
            throw Error(path_.string() + ": cannot write: " + std::strerror(errno));
    }
    void pump(int flush) {
        for (;;) {
            zs_.next_out = out_.data();
            zs_.avail_out = uInt(out_.size());
            const int rc = deflate(&zs_, flush);
            if (rc == Z_STREAM_ERROR) throw Error(path_.string() + ": gzip compression failed");
            raw(out_.data(), out_.size() - zs_.avail_out);
            if (flush == Z_FINISH ? rc == Z_STREAM_END : (zs_.avail_in == 0 && zs_.avail_out != 0)) return;
        }
    }
    std::FILE* file_;
    bool gzip_;
    const fs::path& path_;
    z_stream zs_;
    bool active_ = false;
    std::vector<unsigned char> out_;
};

template <class T>
void store_little_endian(T value, unsigned char* out) {
    static_assert(sizeof(T) == 4 || sizeof(T) == 8);
    using U = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
    U bits;
    std::memcpy(&bits, &value, sizeof bits);
    for (std::size_t b = 0; b < sizeof(U); ++b) out[b] = static_cast<unsigned char>(bits >> (8 * b));
}

void check_volume(const Volume& v, const fs::path& path) {
    const std::string at = path.string() + ": ";
    for (int a = 0; a < 3; ++a)
        if (v.dims[std::size_t(a)] < 1)
            throw Error(at + "cannot write a volume with dims " + std::to_string(v.dims[0]) + " x " +
                        std::to_string(v.dims[1]) + " x " + std::to_string(v.dims[2]));
    const std::size_t count = checked_voxel_count(v.dims, path.string());
    if (v.values.size() != count)
        throw Error(at + "the volume has " + std::to_string(v.values.size()) + " values for dims " +
                    std::to_string(v.dims[0]) + " x " + std::to_string(v.dims[1]) + " x " + std::to_string(v.dims[2]));
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(v.origin[a])) throw Error(at + "the volume's origin must be finite");
        if (!(std::isfinite(v.spacing[a]) && v.spacing[a] > 0.0))
            throw Error(at + "the volume's spacing must be finite and > 0");
    }
}

// NRRD's name of each storage type (the names NrrdReader reads).
const char* nrrd_type_name(ScalarType t) {
    switch (t) {
        case ScalarType::U8: return "uchar";
        case ScalarType::I8: return "signed char";
        case ScalarType::U16: return "ushort";
        case ScalarType::I16: return "short";
        case ScalarType::U32: return "uint";
        case ScalarType::I32: return "int";
        case ScalarType::F32: return "float";
        case ScalarType::F64: return "double";
    }
    return "double";
}

std::string header(const Volume& v, const NrrdWriteOptions& o) {
    std::string h = "NRRD0004\n";
    for (const std::string& c : o.comments) {
        std::string line = c;
        std::replace(line.begin(), line.end(), '\n', ' ');
        std::replace(line.begin(), line.end(), '\r', ' ');
        h += "# " + line + "\n";
    }
    h += std::string("type: ") + nrrd_type_name(o.type) + "\n";
    h += "dimension: 3\n";
    h += "space dimension: 3\n";
    h += "sizes: " + std::to_string(v.dims[0]) + " " + std::to_string(v.dims[1]) + " " + std::to_string(v.dims[2]) + "\n";
    h += "space directions: (" + num(v.spacing.x) + ",0,0) (0," + num(v.spacing.y) + ",0) (0,0," + num(v.spacing.z) +
         ")\n";
    h += "kinds: domain domain domain\n";
    if (scalar_type_size(o.type) > 1) h += "endian: little\n";  // one-byte types have no byte order
    h += std::string("encoding: ") + (o.encoding == NrrdWriteOptions::Encoding::Gzip ? "gzip" : "raw") + "\n";
    h += "space origin: (" + num(v.origin.x) + "," + num(v.origin.y) + "," + num(v.origin.z) + ")\n";
    for (const auto& [key, value] : o.key_values) h += key + ":=" + escape_value(value) + "\n";
    h += "\n";
    return h;
}

}  // namespace

void check_nrrd_output_path(const fs::path& path) {
    if (lower(path.extension().string()) != ".nrrd")
        throw Error(path.string() + ": the output must be a .nrrd file (got " +
                    (path.extension().empty() ? std::string("no extension") : "'" + path.extension().string() + "'") +
                    ")");
    check_output_folder(path);
}

void write_nrrd(const Volume& volume, const fs::path& path, const NrrdWriteOptions& options) {
    check_nrrd_output_path(path);
    check_volume(volume, path);
    const std::string at = path.string() + ": ";
    for (const auto& [key, value] : options.key_values) {
        if (key.empty() || key.find(":=") != std::string::npos || key.find('\n') != std::string::npos ||
            key.find('\r') != std::string::npos || key.front() == '#')
            throw Error(at + "invalid NRRD key '" + key + "'");
    }
    // Every value must be representable in the type (checked before anything is written).
    for (std::size_t n = 0; n < volume.values.size(); ++n) {
        unsigned char scratch[8];
        const double x = volume.values[n];
        if (!encode_voxel(x, options.type, scratch)) {
            const auto nx = std::size_t(volume.dims[0]), ny = std::size_t(volume.dims[1]);
            throw Error(at + "value " + num(x) + " at voxel (" + std::to_string(n % nx) + ", " +
                        std::to_string((n / nx) % ny) + ", " + std::to_string(n / (nx * ny)) + ") is not " +
                        encodable_range(options.type) + (options.type == ScalarType::F32 ? " (write f64)" : ""));
        }
    }

    const fs::path tmp = temporary_output_path(path);
    std::error_code ec;
    try {
        std::unique_ptr<std::FILE, FileCloser> file(std::fopen(tmp.c_str(), "wb"));
        if (!file) throw Error(at + "cannot create " + tmp.string() + ": " + std::strerror(errno));
        const std::string head = header(volume, options);
        if (std::fwrite(head.data(), 1, head.size(), file.get()) != head.size())
            throw Error(at + "cannot write: " + std::strerror(errno));
        {
            Sink sink(file.get(), options.encoding == NrrdWriteOptions::Encoding::Gzip, path);
            constexpr std::size_t kChunk = 1 << 16;  // values per chunk
            const std::size_t size = scalar_type_size(options.type);
            std::vector<unsigned char> bytes(kChunk * size);
            for (std::size_t start = 0; start < volume.values.size(); start += kChunk) {
                const std::size_t count = std::min(kChunk, volume.values.size() - start);
                for (std::size_t n = 0; n < count; ++n)
                    encode_voxel(volume.values[start + n], options.type, &bytes[n * size]);  // checked above
                sink.write(bytes.data(), count * size);
            }
            sink.finish();
        }
        std::FILE* f = file.release();
        if (std::fflush(f) != 0 || std::ferror(f)) {
            const int err = errno;
            std::fclose(f);
            throw Error(at + "cannot write: " + std::strerror(err));
        }
        if (std::fclose(f) != 0) throw Error(at + "cannot write: " + std::strerror(errno));
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
    commit_output(tmp, path);
}

}  // namespace volref
