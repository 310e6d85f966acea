#include "cli/mpi/BrickReader.h"

#include <cstdio>

#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/io/ByteDecoding.h"
#include "core/io/NiftiReader.h"
#include "core/io/VolumeReader.h"

namespace volref::mpi {

VolumeLayout read_volume_header(const std::filesystem::path& path, const std::string& format) {
    VolumeLayout h = volume_layout(path, format);
    if (!h.not_direct.empty())
        throw Error(path.string() +
                    ": volref-mpi reads bricks as sub-boxes of uncompressed samples stored in the volume's axis order; "
                    "this file has " + h.not_direct + " (rewrite it with `volref convert " + path.filename().string() +
                    " OUT.raw`)");
    // Every rank checks that the data file holds the volume, as `volref render` does, not only
    // its own brick: a short file, or one longer than the dims say (NIfTI aside: bytes after its image are
    // ignored, docs/formats.md), is an error on every rank.
    const std::uint64_t size = io::check_input_file(h.data, h.data_where);
    const std::uint64_t voxels = std::uint64_t(h.dims[0]) * std::uint64_t(h.dims[1]) * std::uint64_t(h.dims[2]);
    const std::uint64_t need = voxels * std::uint64_t(scalar_type_size(h.type));
    const std::uint64_t found = size < h.offset ? 0 : size - h.offset;
    if (found < need) throw Error(io::truncated_message(h.data_where, std::size_t(need), std::size_t(found)));
    if (found > need && volume_format(path, format) != "nifti")
        throw Error(io::too_long_message(h.data_where, std::size_t(need), std::to_string(found)));
    return h;
}

Volume read_brick(const VolumeLayout& h, const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& dims) {
    const std::string& where = h.data_where;
    const std::string name = h.data.string();
    Volume v;
    v.dims = dims;
    v.origin = h.origin + glm::dvec3(double(lo[0]), double(lo[1]), double(lo[2])) * h.spacing;
    v.spacing = h.spacing;
    if (h.scaled)  // the stored samples and their f64 values, both held while scaling
        check_memory(checked_voxel_count(dims, where, sizeof(double)) * (sizeof(double) + scalar_type_size(h.type)),
                     where + " (this rank's brick, scaled by scl_slope)");
    io::allocate_samples(v, h.type, where + " (this rank's brick)");  // checks the memory limit first
    const std::size_t size = scalar_type_size(h.type);
    const std::size_t row = std::size_t(dims[0]) * size;
    std::FILE* file = std::fopen(name.c_str(), "rb");
    if (!file) throw Error(where + ": cannot open the file");
    auto* out = static_cast<unsigned char*>(v.values.raw());
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j) {
            const std::int64_t gk = lo[2] + k, gj = lo[1] + j;
            const std::uint64_t offset =
                h.offset + (std::uint64_t(gk * h.dims[1] + gj) * std::uint64_t(h.dims[0]) + std::uint64_t(lo[0])) * size;
            if (fseeko(file, off_t(offset), SEEK_SET) != 0 || std::fread(out, 1, row, file) != row) {
                std::fclose(file);
                throw Error(where + ": the file ends before this rank's brick (voxels (" + std::to_string(lo[0]) + ".." +
                            std::to_string(lo[0] + dims[0] - 1) + ", " + std::to_string(gj) + ", " + std::to_string(gk) +
                            ") at byte " + std::to_string(offset) + ")");
            }
            out += row;
        }
    std::fclose(file);
    io::to_native_order(v.values, h.endian);
    if (h.scaled) scale_samples(v, h.slope, h.inter);  // as read_nifti (the memory was checked above)
    return v;
}

}  // namespace volref::mpi
