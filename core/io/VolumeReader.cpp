#include "core/io/VolumeReader.h"

#include <string>

#include "core/Error.h"
#include "core/io/ByteDecoding.h"
#include "core/io/NrrdReader.h"
#include "core/io/RawReader.h"

namespace volref {

namespace {

// The format named by a file's extension (compared without case): .nrrd and .nhdr are NRRD, .raw is
// raw samples with a JSON sidecar.
std::string format_from_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    if (ext == ".nrrd" || ext == ".nhdr") return "nrrd";
    if (ext == ".raw") return "raw";
    const std::string found = ext.empty() ? "no extension" : "the extension " + io::quoted(ext);
    throw Error(path.string() + ": cannot tell the volume format from " + found +
                " (supported: .nrrd, .nhdr, .raw; or name the format: nrrd or raw)");
}

}  // namespace

Volume read_volume(const std::filesystem::path& path, const std::string& format) {
    const std::string chosen = format.empty() ? format_from_extension(path) : format;
    if (chosen == "nrrd") return read_nrrd(path);
    if (chosen == "raw") return read_raw_volume(path);
    throw Error(path.string() + ": unknown volume format " + io::quoted(format) + " (expected nrrd or raw)");
}

}  // namespace volref
