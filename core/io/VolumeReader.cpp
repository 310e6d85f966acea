#include "core/io/VolumeReader.h"

#include <cstdio>
#include <cmath>
#include <algorithm>
#include <string>

#include "core/Error.h"
#include "core/InputFile.h"
#include "core/Conventions.h"
#include "core/io/ByteDecoding.h"
#include "core/io/DenReader.h"
#include "core/io/MetaImageReader.h"
#include "core/io/NiftiReader.h"
#include "core/io/NrrdReader.h"
#include "core/io/RawReader.h"
#include "core/io/VolumeLayout.h"
#include "core/io/VtiReader.h"
#include "core/io/VtkLegacyReader.h"

namespace volref {

namespace {

constexpr const char* kFormats = "nrrd, raw, nifti, metaimage, vtk, vti or den";

std::string lower(std::string s) {
    for (char& c : s)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return s;
}

// The format named by a file's extension (compared without case).
std::string format_from_extension(const std::filesystem::path& path) {
    const std::string name = lower(path.filename().string());
    const auto ends_with = [&](const char* suffix) {
        const std::string s(suffix);
        return name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
    };
    if (ends_with(".nii.gz")) return "nifti";
    const std::string ext = lower(path.extension().string());
    if (ext == ".nrrd" || ext == ".nhdr") return "nrrd";
    if (ext == ".raw") return "raw";
    if (ext == ".nii" || ext == ".hdr") return "nifti";
    if (ext == ".mhd" || ext == ".mha") return "metaimage";
    if (ext == ".vtk") return "vtk";
    if (ext == ".vti") return "vti";
    if (ext == ".den") return "den";
    const std::string found = ext.empty() ? "no extension" : "the extension " + io::quoted(ext);
    throw Error(path.string() + ": cannot tell the volume format from " + found +
                " (supported: .nrrd, .nhdr, .raw, .nii, .nii.gz, .hdr, .mhd, .mha, .vtk, .vti, .den; or name the "
                "format: " + kFormats + ")");
}

}  // namespace

std::string volume_format(const std::filesystem::path& path, const std::string& format) {
    if (format.empty()) return format_from_extension(path);
    for (const char* known : {"nrrd", "raw", "nifti", "metaimage", "vtk", "vti", "den"})
        if (format == known) return format;
    throw Error(path.string() + ": unknown volume format " + io::quoted(format) + " (expected " + kFormats + ")");
}

namespace {

Volume read_by_format(const std::filesystem::path& path, const std::string& chosen) {
    if (chosen == "nrrd") return read_nrrd(path);
    if (chosen == "raw") return read_raw_volume(path);
    if (chosen == "nifti") return read_nifti(path);
    if (chosen == "metaimage") return read_metaimage(path);
    if (chosen == "vtk") return read_vtk_legacy(path);
    if (chosen == "vti") return read_vti(path);
    return read_den(path);
}

}  // namespace

Volume read_volume(const std::filesystem::path& path, const std::string& format) {
    io::check_input_file(path, path.string());  // a FIFO or a device: refused by type, before its name is read
    const std::string chosen = volume_format(path, format);
    Volume v = read_by_format(path, chosen);
    // The grid a header describes lies within volref's number range (conventions::kMaxMagnitude),
    // like every number of a scene file, so that no ray parameter or position overflows.
    // the header fields that give them, by format, for the message
    const char* spacing_field = chosen == "nrrd" ? "space directions / spacings" : chosen == "metaimage" ? "ElementSpacing"
                              : chosen == "nifti" ? "pixdim / sform / qform" : chosen == "vtk" ? "SPACING"
                              : chosen == "vti" ? "Spacing" : chosen == "raw" ? "the sidecar's spacing" : "the header's spacing";
    const char* origin_field = chosen == "nrrd" ? "space origin" : chosen == "metaimage" ? "Offset / Origin / Position"
                             : chosen == "nifti" ? "sform / qform offset" : chosen == "vtk" ? "ORIGIN"
                             : chosen == "vti" ? "Origin" : chosen == "raw" ? "the sidecar's origin" : "the header's origin";
    char buf[64];
    for (int a = 0; a < 3; ++a) {
        const double s = v.spacing[a], o = v.origin[a];
        if (!(s >= conventions::kMinMagnitude && s <= conventions::kMaxMagnitude)) {
            std::snprintf(buf, sizeof buf, "%.6g", s);
            throw Error(path.string() + ": " + spacing_field + ": axis " + std::to_string(a) + " has a spacing of " + buf +
                        ", beyond volref's range (a magnitude in [1e-100, 1e100])");
        }
        if (!(std::fabs(o) <= conventions::kMaxMagnitude)) {
            std::snprintf(buf, sizeof buf, "%.6g", o);
            throw Error(path.string() + ": " + origin_field + ": axis " + std::to_string(a) + " has an origin of " + buf +
                        ", beyond volref's range (|x| <= 1e100)");
        }
        const double extent = s * double(std::max<std::int64_t>(v.dims[std::size_t(a)] - 1, 1));
        if (!(std::fabs(o) + extent <= conventions::kMaxMagnitude)) {
            std::snprintf(buf, sizeof buf, "%.6g", std::fabs(o) + extent);
            throw Error(path.string() + ": " + spacing_field + ", " + origin_field + ": the grid reaches " + std::string(buf) +
                        " along axis " + std::to_string(a) + ", beyond volref's range (|x| <= 1e100)");
        }
    }
    return v;
}

std::uint64_t trailing_samples_offset(const VolumeLayout& layout, std::uint64_t base, std::uint64_t bytes) {
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(layout.data, ec);
    if (ec) throw Error(layout.data_where + ": cannot read the file's size");
    if (size < base + bytes) throw Error(io::truncated_message(layout.data_where, bytes, size - std::min(size, base)));
    return size - bytes;
}

VolumeLayout volume_layout(const std::filesystem::path& path, const std::string& format) {
    const std::string chosen = volume_format(path, format);
    if (chosen == "nrrd") return nrrd_layout(path);
    if (chosen == "raw") return raw_layout(path);
    if (chosen == "nifti") return nifti_layout(path);
    if (chosen == "metaimage") return metaimage_layout(path);
    throw Error(path.string() + ": the " + chosen +
                " format has no sub-box reader (nrrd, raw, nifti and metaimage do; convert with `volref convert`)");
}

}  // namespace volref
