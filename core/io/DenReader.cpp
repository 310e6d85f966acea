#include "core/io/DenReader.h"

#include <cstdint>
#include <string>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"

namespace volref {

namespace {

constexpr std::size_t kHeaderBytes = 62;

// The integer of type T at byte `offset` of `bytes` in byte order `order`.
template <typename T>
T header_value(const std::string& bytes, std::size_t offset, std::endian order) {
    return io::load_value<T>(bytes.data() + offset, order != std::endian::native);
}

}  // namespace

Volume read_den(const std::filesystem::path& path) {
    const std::string where = path.string();
    const std::string file = io::read_file_bytes(path);
    if (file.size() < 2)
        throw Error(where + ": not a VolPack .den file: " + std::to_string(file.size()) +
                    " bytes, too short for the map_version at byte 0");
    // map_version 1, in the byte order of the machine that wrote the file.
    const auto b0 = static_cast<unsigned char>(file[0]), b1 = static_cast<unsigned char>(file[1]);
    std::endian order;
    if (b0 == 1 && b1 == 0)
        order = std::endian::little;
    else if (b0 == 0 && b1 == 1)
        order = std::endian::big;
    else
        throw Error(where + ": not a VolPack .den file: map_version at byte 0 is " + io::quoted(file.substr(0, 2)) +
                    ", expected 1 (bytes 01 00 or 00 01)");
    if (file.size() < kHeaderBytes)
        throw Error(where + ": truncated header: expected " + std::to_string(kHeaderBytes) + " bytes, found " +
                    std::to_string(file.size()));

    Volume volume;
    for (int a = 0; a < 3; ++a) {
        const auto len = header_value<std::int16_t>(file, 50 + 2 * std::size_t(a), order);
        if (len < 1)
            throw Error(where + ": map_len[" + std::to_string(a) + "] at byte " + std::to_string(50 + 2 * a) +
                        " must be >= 1, got " + std::to_string(len));
        volume.dims[std::size_t(a)] = len;
    }
    const std::size_t count = checked_voxel_count(volume.dims, where, sizeof(double));
    const auto map_length = header_value<std::int32_t>(file, 58, order);
    if (map_length < 0 || std::size_t(map_length) != count)
        throw Error(where + ": map_length at byte 58 is " + std::to_string(map_length) + ", expected map_len " +
                    std::to_string(volume.dims[0]) + " x " + std::to_string(volume.dims[1]) + " x " +
                    std::to_string(volume.dims[2]) + " = " + std::to_string(count));
    std::string storage;
    const std::string_view bytes = io::sample_bytes(std::string_view(file).substr(kHeaderBytes),
                                                    io::BinaryEncoding::Raw, 0, count, storage, where);
    io::store_sample_bytes(volume, ScalarType::U8, order, bytes, where);
    return volume;
}

}  // namespace volref
