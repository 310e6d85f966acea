// Reading volume files: one entry point, the format from the extension or given explicitly.
//   .nrrd, .nhdr      nrrd       NRRD (attached or detached header; raw, gzip or ascii; every scalar type)
//   .raw              raw        raw samples described by a JSON sidecar PATH.json
//   .nii, .nii.gz     nifti      NIfTI-1 and NIfTI-2 through nifti_clib (also .hdr + .img pairs)
//   .mhd, .mha        metaimage  MetaImage (detached .mhd + data file, or inline .mha; zlib compressed)
//   .vtk              vtk        VTK legacy STRUCTURED_POINTS (ASCII or big-endian BINARY)
//   .vti              vti        VTK XML ImageData (ascii, base64 inline, raw or base64 appended; zlib)
//   .den              den        VolPack density files (u8)
// docs/formats.md says what each reader accepts. Errors are volref::Error with a one-line message that
// starts with the file's path.
#pragma once
#include <filesystem>
#include <string>

#include "core/grid/Volume.h"

namespace volref {

// format: "" (from the extension) or one of the names above.
Volume read_volume(const std::filesystem::path& path, const std::string& format = "");

// The format read_volume uses for `path` (`format` when given, checked, else from the extension);
// an unknown format or extension is an Error.
std::string volume_format(const std::filesystem::path& path, const std::string& format = "");

}  // namespace volref
