#include "core/io/NiftiReader.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>

#include <nifti2_io.h>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"
#include "core/io/VolumeLayout.h"

namespace volref {

namespace {

// Entries of an axis-aligned matrix below this fraction of their column's largest are taken as 0
// (float quaternions and sforms carry rounding of about 1e-7).
constexpr double kOffAxisTolerance = 1e-6;

struct NiftiVersion {
    int version = 1;          // 1 or 2
    std::size_t header_size;  // 348 or 540
};

std::string hex_bytes(std::string_view s) { return io::quoted(s, 8); }

// Checks the first bytes of the header (decompressed for gzip): sizeof_hdr, length and magic.
NiftiVersion check_header_bytes(const std::filesystem::path& path, const std::string& where) {
    // The first 64 KiB of the file: plenty for 540 header bytes, even compressed.
    std::string file(std::size_t(1) << 16, '\0');
    {
        const io::FileHandle f = io::open_for_reading(path);
        file.resize(std::fread(file.data(), 1, file.size(), f.get()));
    }
    std::string prefix;
    if (file.size() >= 2 && static_cast<unsigned char>(file[0]) == 0x1f && static_cast<unsigned char>(file[1]) == 0x8b) {
        prefix = io::inflate_stream(file, 0, 540, where).data;
    } else {
        prefix = file.substr(0, std::min<std::size_t>(file.size(), 540));
    }
    if (prefix.size() < 4)
        throw Error(where + ": truncated header: expected 348 bytes (NIfTI-1) or 540 (NIfTI-2), found " +
                    std::to_string(prefix.size()));
    const auto le = io::load_value<std::int32_t>(prefix.data(), std::endian::native != std::endian::little);
    const auto be = io::load_value<std::int32_t>(prefix.data(), std::endian::native != std::endian::big);
    NiftiVersion v;
    if (le == 348 || be == 348) {
        v = {1, 348};
    } else if (le == 540 || be == 540) {
        v = {2, 540};
    } else {
        throw Error(where + ": not a NIfTI file: sizeof_hdr at byte 0 is " + std::to_string(le) +
                    " (expected 348 for NIfTI-1 or 540 for NIfTI-2, in either byte order)");
    }
    if (prefix.size() < v.header_size)
        throw Error(where + ": truncated header: expected " + std::to_string(v.header_size) + " bytes (NIfTI-" +
                    std::to_string(v.version) + "), found " + std::to_string(prefix.size()));
    if (v.version == 1) {
        const std::string_view magic = std::string_view(prefix).substr(344, 4);
        if (magic != std::string_view("n+1\0", 4) && magic != std::string_view("ni1\0", 4))
            throw Error(where + ": bad magic at byte 344: " + hex_bytes(magic) + " (expected 'n+1' or 'ni1')");
    } else {
        const std::string_view magic = std::string_view(prefix).substr(4, 8);
        if (magic != std::string_view("n+2\0\r\n\032\n", 8) && magic != std::string_view("ni2\0\r\n\032\n", 8))
            throw Error(where + ": bad magic at byte 4: " + hex_bytes(magic) +
                        " (expected 'n+2' or 'ni2' followed by \\0\\r\\n\\x1a\\n)");
    }
    return v;
}

// dim[0..7] and datatype as the header holds them (in native byte order).
struct RawFields {
    std::array<std::int64_t, 8> dim{};
    int datatype = 0;
    // As stored (nifti_clib replaces a pixdim of 0 by 1 and a vox_offset below the header by its end;
    // volref checks the values the file holds).
    std::array<double, 8> pixdim{};
    double vox_offset = 0.0, scl_slope = 0.0, scl_inter = 0.0;
    bool single_file = true;  // magic n+1 / n+2 (the image follows the header in the same file)
    int qform_code = 0;
    std::array<double, 6> quatern{};  // quatern_b, c, d, qoffset_x, y, z
};

RawFields read_raw_fields(const std::filesystem::path& path, const NiftiVersion& v, const std::string& where) {
    int nver = 0;
    void* raw = nifti_read_header(path.c_str(), &nver, 0);
    if (!raw) throw Error(where + ": nifti_clib could not read the NIfTI-" + std::to_string(v.version) + " header");
    std::unique_ptr<void, void (*)(void*)> guard(raw, &std::free);
    // nifti_read_header leaves the header in the file's byte order: swap it (nifti_clib's own swap)
    // when sizeof_hdr reads back wrong.
    const std::int32_t size_field = nver == 2 ? static_cast<const nifti_2_header*>(raw)->sizeof_hdr
                                              : static_cast<const nifti_1_header*>(raw)->sizeof_hdr;
    if (size_field != (nver == 2 ? 540 : 348)) swap_nifti_header(raw, nver);
    // The same field names in both versions (NIfTI-2 widens them to 64 bits).
    RawFields f;
    auto copy = [&f](const auto* h) {
        for (int i = 0; i < 8; ++i) f.dim[std::size_t(i)] = std::int64_t(h->dim[i]);
        f.datatype = h->datatype;
        for (int i = 0; i < 8; ++i) f.pixdim[std::size_t(i)] = double(h->pixdim[i]);
        f.vox_offset = double(h->vox_offset);
        f.scl_slope = double(h->scl_slope);
        f.scl_inter = double(h->scl_inter);
        f.single_file = h->magic[1] == '+';
        f.qform_code = h->qform_code;
        f.quatern = {double(h->quatern_b), double(h->quatern_c), double(h->quatern_d), double(h->qoffset_x),
                     double(h->qoffset_y), double(h->qoffset_z)};
    };
    if (nver == 2) copy(static_cast<const nifti_2_header*>(raw));
    else copy(static_cast<const nifti_1_header*>(raw));
    return f;
}

ScalarType scalar_type(int datatype, const NiftiVersion& v, const std::string& where) {
    switch (datatype) {
        case DT_UINT8: return ScalarType::U8;
        case DT_INT8: return ScalarType::I8;
        case DT_UINT16: return ScalarType::U16;
        case DT_INT16: return ScalarType::I16;
        case DT_UINT32: return ScalarType::U32;
        case DT_INT32: return ScalarType::I32;
        case DT_FLOAT32: return ScalarType::F32;
        case DT_FLOAT64: return ScalarType::F64;
        default: break;
    }
    const std::string at = where + ": datatype (byte " + (v.version == 1 ? "70" : "12") + ") ";
    const char* name = nifti_datatype_string(datatype);
    if (nifti_is_valid_datatype(datatype))
        throw Error(at + std::to_string(datatype) + " (" + name +
                    ") is not supported (volref reads UINT8, INT8, UINT16, INT16, UINT32, INT32, FLOAT32, FLOAT64)");
    throw Error(at + std::to_string(datatype) + " is not a NIfTI datatype");
}

struct ImageDeleter {
    void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

// Where voxel axis c goes: world axis `axis[c]`, flipped when `flip[c]`.
struct Orientation {
    std::array<int, 3> axis{0, 1, 2};
    std::array<bool, 3> flip{false, false, false};
    glm::dvec3 spacing{1.0};  // per voxel axis, > 0
    glm::dvec3 offset{0.0};   // world position of voxel (0, 0, 0)
    std::string source = "pixdim";
};

Orientation orientation(const nifti_image& nim, const std::array<double, 8>& raw_pixdim, int version,
                        const std::string& where) {
    Orientation o;
    const bool use_sform = nim.sform_code > 0;
    const bool use_qform = !use_sform && nim.qform_code > 0;
    for (int c = 0; c < 3; ++c) {
        const double p = raw_pixdim[std::size_t(c + 1)];  // as stored: nifti_clib reads 0 as 1
        if (!use_sform && !(std::isfinite(p) && p != 0.0)) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%g", p);
            throw Error(where + ": pixdim[" + std::to_string(c + 1) + "] (byte " +
                        std::to_string((version == 1 ? 76 + 4 * (c + 1) : 104 + 8 * (c + 1))) +
                        ") must be finite and non-zero, got " + buf);
        }
        o.spacing[c] = std::fabs(p);
    }
    if (!use_sform && !use_qform) return o;  // NIfTI's method 1: index times pixdim, no origin
    const nifti_dmat44& m = use_sform ? nim.sto_xyz : nim.qto_xyz;
    o.source = use_sform ? "sform" : "qform";
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(m.m[r][c]))
                throw Error(where + ": the " + o.source + " holds a non-finite number (" +
                            (use_sform ? std::string("srow_") + char('x' + r) + "[" + std::to_string(c) + "]"
                                       : std::string("quatern/qoffset")) + ")");
    std::array<bool, 3> taken{false, false, false};
    for (int c = 0; c < 3; ++c) {
        int best = 0;
        for (int r = 1; r < 3; ++r)
            if (std::fabs(m.m[r][c]) > std::fabs(m.m[best][c])) best = r;
        const double big = std::fabs(m.m[best][c]);
        bool aligned = std::isfinite(big) && big > 0.0 && !taken[std::size_t(best)];
        for (int r = 0; r < 3 && aligned; ++r)
            if (r != best && !(std::fabs(m.m[r][c]) <= kOffAxisTolerance * big)) aligned = false;
        if (!aligned) {
            std::string rows;
            for (int r = 0; r < 3; ++r) {
                char buf[160];
                std::snprintf(buf, sizeof buf, "%s[%g %g %g %g]", r ? " " : "", m.m[r][0], m.m[r][1], m.m[r][2],
                              m.m[r][3]);
                rows += buf;
            }
            throw Error(where + ": the " + o.source + " is oblique (voxel axis " + std::to_string(c) +
                        " is not along one world axis): " + rows +
                        "; volref reads axis-aligned grids only (resample the image first)");
        }
        taken[std::size_t(best)] = true;
        o.axis[std::size_t(c)] = best;
        o.flip[std::size_t(c)] = m.m[best][c] < 0.0;
        // The qform's rotation comes from float quaternions: its magnitude is pixdim's, exactly.
        o.spacing[c] = use_sform ? big : std::fabs(nim.pixdim[c + 1]);
    }
    for (int r = 0; r < 3; ++r) {
        o.offset[r] = m.m[r][3];
        if (!std::isfinite(o.offset[r])) throw Error(where + ": the " + o.source + " has a non-finite offset");
    }
    return o;
}

}  // namespace

namespace {

// The header and what it says about the image bytes, shared by read_nifti and nifti_layout.
struct ParsedNifti {
    ScalarType type = ScalarType::U8;
    std::array<std::int64_t, 3> file_dims{1, 1, 1};
    std::size_t count = 0;
    Orientation o;
    std::filesystem::path image_path;
    std::uint64_t offset = 0;
    std::endian order = std::endian::little;
    double slope = 0.0, inter = 0.0;
};

// `limited`: the whole volume is about to be read (its size is checked against the memory limit).
ParsedNifti parse_nifti(const std::filesystem::path& path, bool limited) {
    const std::string where = path.string();
    io::open_for_reading(path);
    static std::once_flag quiet;
    std::call_once(quiet, [] { nifti_set_debug_level(0); });  // volref reports errors itself

    const NiftiVersion version = check_header_bytes(path, where);
    const RawFields raw = read_raw_fields(path, version, where);
    const std::string dim_at = version.version == 1 ? "byte 40" : "byte 16";
    const std::int64_t ndim = raw.dim[0];
    if (ndim < 1 || ndim > 7)
        throw Error(where + ": dim[0] (" + dim_at + ") must be 1 to 7, got " + std::to_string(ndim));
    for (std::int64_t i = 1; i <= ndim; ++i)
        if (raw.dim[std::size_t(i)] < 1)
            throw Error(where + ": dim[" + std::to_string(i) + "] must be >= 1, got " +
                        std::to_string(raw.dim[std::size_t(i)]));
    for (std::int64_t i = 4; i <= ndim; ++i)
        if (raw.dim[std::size_t(i)] > 1)
            throw Error(where + ": dim[" + std::to_string(i) + "] is " + std::to_string(raw.dim[std::size_t(i)]) +
                        ": images of more than 3 dimensions (time series, vectors) are not supported");
    ParsedNifti p;
    p.type = scalar_type(raw.datatype, version, where);

    std::unique_ptr<nifti_image, ImageDeleter> nim(nifti_image_read(path.c_str(), 0));
    if (!nim) throw Error(where + ": nifti_clib could not read the header (see nifti_tool -check_hdr)");
    p.file_dims = {raw.dim[1], ndim >= 2 ? raw.dim[2] : 1, ndim >= 3 ? raw.dim[3] : 1};
    p.count = limited ? checked_voxel_count(p.file_dims, where, scalar_type_size(p.type))
                      : checked_voxel_count_unlimited(p.file_dims, where, scalar_type_size(p.type));
    if (raw.qform_code > 0)  // nifti_clib turns a NaN quaternion into some rotation: refuse it as stored
        for (std::size_t i = 0; i < 6; ++i)
            if (!std::isfinite(raw.quatern[i])) {
                static const char* const kNames[6] = {"quatern_b", "quatern_c", "quatern_d", "qoffset_x", "qoffset_y", "qoffset_z"};
                const int byte = (version.version == 1 ? 256 : 352) + int(i) * (version.version == 1 ? 4 : 8);
                throw Error(where + ": " + kNames[i] + " (byte " + std::to_string(byte) +
                            ") must be a finite number (the qform is in use: qform_code > 0)");
            }
    p.o = orientation(*nim, raw.pixdim, version.version, where);

    // The image bytes: in the same file after vox_offset (.nii), or in the .img file. vox_offset as
    // stored (nifti_clib moves one inside the header to the header's end): a whole number >= 0, in a
    // single file not inside the header, and within the image file.
    p.image_path = nim->iname ? std::filesystem::path(nim->iname) : path;
    const std::string vox_at = where + ": vox_offset (byte " + (version.version == 1 ? "108" : "168") + ") ";
    char vox_text[64];
    std::snprintf(vox_text, sizeof vox_text, "%.17g", raw.vox_offset);
    if (!(std::isfinite(raw.vox_offset) && raw.vox_offset >= 0.0 && raw.vox_offset == std::floor(raw.vox_offset)))
        throw Error(vox_at + "must be a whole number >= 0, got " + vox_text);
    if (raw.single_file && raw.vox_offset < double(version.header_size))
        throw Error(vox_at + "is " + vox_text + ": inside the " + std::to_string(version.header_size) +
                    "-byte header (the image must follow it)");
    if (raw.vox_offset > 0x1p62) throw Error(vox_at + "is " + vox_text + ": beyond any file");
    p.offset = static_cast<std::uint64_t>(raw.vox_offset);
    // nifti_clib's MSB_FIRST (2) is defined only inside the library.
    p.order = nim->byteorder == 2 ? std::endian::big : std::endian::little;
    p.slope = raw.scl_slope;  // as stored: nifti_clib drops a non-finite slope silently
    p.inter = raw.scl_inter;
    const std::string scl_at = version.version == 1 ? "112" : "176", inter_at = version.version == 1 ? "116" : "184";
    if (!std::isfinite(p.slope))
        throw Error(where + ": scl_slope (byte " + scl_at + ") must be a finite number (0: no scaling), got " + std::to_string(p.slope));
    if (p.slope != 0.0 && !std::isfinite(p.inter))
        throw Error(where + ": scl_inter (byte " + inter_at + ") must be a finite number, got " + std::to_string(p.inter));
    return p;
}

// Scaling: value = slope * stored + inter, when slope is set and not the identity (f64 values).
bool scales(double slope, double inter) {
    return std::isfinite(slope) && slope != 0.0 && std::isfinite(inter) && (slope != 1.0 || inter != 0.0);
}

}  // namespace

VolumeLayout nifti_layout(const std::filesystem::path& path) {
    const std::string where = path.string();
    const ParsedNifti p = parse_nifti(path, false);
    VolumeLayout out;
    out.dims = p.file_dims;
    out.type = p.type;
    out.endian = p.order;
    out.data = p.image_path;
    out.data_where = p.image_path == path ? where : p.image_path.string() + " (image file of " + where + ")";
    out.offset = p.offset;
    out.scaled = scales(p.slope, p.inter);
    out.slope = p.slope;
    out.inter = p.inter;
    const bool identity = p.o.axis == std::array<int, 3>{0, 1, 2} && !p.o.flip[0] && !p.o.flip[1] && !p.o.flip[2];
    for (int a = 0; a < 3; ++a) {
        out.spacing[a] = p.o.spacing[a];
        out.origin[a] = p.o.offset[a];
    }
    if (nifti_is_gzfile(p.image_path.c_str())) out.not_direct = "gzip compression";
    else if (!identity) out.not_direct = "a flipped or permuted orientation (the " + p.o.source + ")";
    return out;
}

void scale_samples(Volume& volume, double slope, double inter) {
    const std::size_t count = volume.values.size();
    VoxelArray scaled(ScalarType::F64, count);
    double* out = scaled.data<double>();
    volume.values.visit([&](const auto* p) {
        for (std::size_t i = 0; i < count; ++i) out[i] = slope * double(p[i]) + inter;
    });
    volume.values = std::move(scaled);
    volume.type = ScalarType::F64;
}

Volume read_nifti(const std::filesystem::path& path) {
    const std::string where = path.string();
    const ParsedNifti p = parse_nifti(path, true);
    const ScalarType type = p.type;
    const std::array<std::int64_t, 3>& file_dims = p.file_dims;
    const std::size_t count = p.count;
    const Orientation& o = p.o;
    const std::filesystem::path& image_path = p.image_path;
    const std::uint64_t offset = p.offset;
    const std::size_t expected = count * scalar_type_size(type);
    // Errors in a separate .img file start with its path and end with "(image file of HEADER)".
    const std::string at = image_path.string();
    const std::endian order = p.order;
    // The stored samples, in the file's type and voxel order, read in pieces straight into memory.
    Volume stored;
    stored.dims = file_dims;
    try {
        if (nifti_is_gzfile(image_path.c_str())) {
            io::ByteSource source(image_path, 0, at);
            io::allocate_samples(stored, type, at);
            const std::size_t got = io::inflate_into(source, offset, static_cast<char*>(stored.values.raw()), expected, at);
            if (got < expected)
                throw Error(io::truncated_message(at, expected, got) + " after inflating (from vox_offset " +
                            std::to_string(offset) + ")");
        } else {
            io::ByteSource source(image_path, offset, at);
            const std::size_t found = std::size_t(source.size());
            if (found < expected)
                throw Error(io::truncated_message(at, expected, found) + " (from vox_offset " + std::to_string(offset) +
                            ")");
            io::allocate_samples(stored, type, at);
            const std::size_t got = source.read(stored.values.raw(), expected);
            if (got < expected) throw Error(io::truncated_message(at, expected, got));
        }
    } catch (const Error& e) {
        if (image_path == path) throw;
        throw Error(std::string(e.what()) + " (image file of " + where + ")");
    }
    io::to_native_order(stored.values, order);

    // Scaling: value = slope * stored + inter, when slope is set and not the identity (f64 values).
    const double slope = p.slope, inter = p.inter;
    if (scales(slope, inter)) {
        checked_voxel_count(file_dims, where + ": scaled by scl_slope", sizeof(double));
        scale_samples(stored, slope, inter);
    }

    // Reorder so that volume axis a is world axis a, increasing.
    Volume volume;
    std::array<int, 3> voxel_axis{};  // voxel_axis[world axis] = voxel axis
    for (int c = 0; c < 3; ++c) voxel_axis[std::size_t(o.axis[std::size_t(c)])] = c;
    for (int a = 0; a < 3; ++a) {
        const int c = voxel_axis[std::size_t(a)];
        const std::int64_t n = file_dims[std::size_t(c)];
        volume.dims[std::size_t(a)] = n;
        volume.spacing[a] = o.spacing[c];
        volume.origin[a] = o.offset[a] - (o.flip[std::size_t(c)] ? o.spacing[c] * double(n - 1) : 0.0);
    }
    const bool identity = voxel_axis == std::array<int, 3>{0, 1, 2} && !o.flip[0] && !o.flip[1] && !o.flip[2];
    volume.type = stored.type;
    if (identity) {
        volume.values = std::move(stored.values);
        return volume;
    }
    // A second array in the same type: the peak while reordering is twice the volume.
    volume.values.allocate(stored.values.type(), count, false);
    const std::array<std::int64_t, 3> stride{1, file_dims[0], file_dims[0] * file_dims[1]};
    stored.values.visit([&](const auto* in) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(in)>>;
        T* values = volume.values.template data<T>();
        std::size_t out = 0;
        for (std::int64_t k = 0; k < volume.dims[2]; ++k)
            for (std::int64_t j = 0; j < volume.dims[1]; ++j)
                for (std::int64_t i = 0; i < volume.dims[0]; ++i) {
                    const std::array<std::int64_t, 3> n{i, j, k};
                    std::int64_t src = 0;
                    for (int a = 0; a < 3; ++a) {
                        const int c = voxel_axis[std::size_t(a)];
                        const std::int64_t idx = o.flip[std::size_t(c)] ? volume.dims[std::size_t(a)] - 1 - n[std::size_t(a)]
                                                                        : n[std::size_t(a)];
                        src += idx * stride[std::size_t(c)];
                    }
                    values[out++] = in[std::size_t(src)];
                }
    });
    return volume;
}

}  // namespace volref
