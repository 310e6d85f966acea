#include "core/io/RawWriter.h"

#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include <zlib.h>

#include "core/Error.h"
#include "core/io/OutputFile.h"
#include "core/io/VoxelEncoding.h"

namespace fs = std::filesystem;

namespace volref {

namespace {

std::string num(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}


std::string voxel_name(const Volume& v, std::size_t n) {
    const auto nx = std::size_t(v.dims[0]), ny = std::size_t(v.dims[1]);
    return "(" + std::to_string(n % nx) + ", " + std::to_string((n / nx) % ny) + ", " + std::to_string(n / (nx * ny)) +
           ")";
}

std::string encode(const Volume& v, ScalarType type, const std::string& at) {
    const std::size_t size = scalar_type_size(type);
    std::string out(v.values.size() * size, '\0');
    for (std::size_t n = 0; n < v.values.size(); ++n)
        if (!encode_voxel(v.values[n], type, reinterpret_cast<unsigned char*>(&out[n * size])))
            throw Error(at + "value " + num(v.values[n]) + " at voxel " + voxel_name(v, n) + " is not " +
                        encodable_range(type));
    return out;
}

std::string gzip(const std::string& data, const std::string& at) {
    z_stream zs{};
    if (deflateInit2(&zs, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        throw Error(at + "cannot start gzip compression");
    std::string out;
    std::vector<unsigned char> buf(1 << 18);
    std::size_t pos = 0;
    int rc = Z_OK;
    do {
        const std::size_t piece = std::min<std::size_t>(data.size() - pos, std::size_t(1) << 30);
        zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data() + pos));
        zs.avail_in = uInt(piece);
        pos += piece;
        const int flush = pos == data.size() ? Z_FINISH : Z_NO_FLUSH;
        do {
            zs.next_out = buf.data();
            zs.avail_out = uInt(buf.size());
            rc = deflate(&zs, flush);
            if (rc == Z_STREAM_ERROR) {
                deflateEnd(&zs);
                throw Error(at + "gzip compression failed");
            }
            out.append(reinterpret_cast<const char*>(buf.data()), buf.size() - zs.avail_out);
        } while (zs.avail_out == 0);
    } while (rc != Z_STREAM_END);
    deflateEnd(&zs);
    return out;
}

void write_file(const fs::path& path, const std::string& bytes, const std::string& at) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "wb"), &std::fclose);
    if (!f) throw Error(at + "cannot create " + path.string() + ": " + std::strerror(errno));
    if (std::fwrite(bytes.data(), 1, bytes.size(), f.get()) != bytes.size() || std::fflush(f.get()) != 0)
        throw Error(at + "cannot write: " + std::strerror(errno));
    std::FILE* raw = f.release();
    if (std::fclose(raw) != 0) throw Error(at + "cannot write: " + std::strerror(errno));
}

}  // namespace

void write_raw(const Volume& volume, const fs::path& path, const RawWriteOptions& options) {
    const std::string at = path.string() + ": ";
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".raw")
        throw Error(at + "the output must be a .raw file (got " +
                    (path.extension().empty() ? std::string("no extension") : "'" + path.extension().string() + "'") + ")");
    check_output_folder(path);
    const std::size_t count = checked_voxel_count(volume.dims, path.string());
    if (volume.values.size() != count) throw Error(at + "the volume's value count does not match its dims");
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(volume.origin[a])) throw Error(at + "the volume's origin must be finite");
        if (!(std::isfinite(volume.spacing[a]) && volume.spacing[a] > 0.0))
            throw Error(at + "the volume's spacing must be finite and > 0");
    }
    std::string data = encode(volume, options.type, at);
    if (options.gzip) data = gzip(data, at);
    const std::string sidecar =
        "{\"dims\": [" + std::to_string(volume.dims[0]) + ", " + std::to_string(volume.dims[1]) + ", " +
        std::to_string(volume.dims[2]) + "], \"type\": \"" + scalar_type_name(options.type) +
        "\", \"endian\": \"little\", \"origin\": [" + num(volume.origin.x) + ", " + num(volume.origin.y) + ", " +
        num(volume.origin.z) + "], \"spacing\": [" + num(volume.spacing.x) + ", " + num(volume.spacing.y) + ", " +
        num(volume.spacing.z) + "], \"header_bytes\": 0, \"encoding\": \"" + (options.gzip ? "gzip" : "raw") + "\"}\n";

    fs::path sidecar_path = path;
    sidecar_path += ".json";
    const fs::path tmp_data = temporary_output_path(path);
    fs::path tmp_sidecar = tmp_data;
    tmp_sidecar += ".json";
    std::error_code ec;
    try {
        write_file(tmp_data, data, at);
        write_file(tmp_sidecar, sidecar, at);
        commit_output(tmp_data, path);
        fs::rename(tmp_sidecar, sidecar_path, ec);
        if (ec) {
            std::error_code ignored;
            fs::remove(path, ignored);
            throw Error(at + "cannot move the finished sidecar into place: " + ec.message());
        }
    } catch (...) {
        fs::remove(tmp_data, ec);
        fs::remove(tmp_sidecar, ec);
        throw;
    }
}

}  // namespace volref
