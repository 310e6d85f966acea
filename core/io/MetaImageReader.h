// Reading MetaImage files (ITK's MetaIO format) into a Volume: a text header of `Key = Value` lines,
// either detached (.mhd, ElementDataFile names the data file) or inline (.mha, ElementDataFile = LOCAL,
// the data right after that line). Keys read: NDims (1..3), DimSize, ElementType (MET_UCHAR, MET_CHAR,
// MET_USHORT, MET_SHORT, MET_UINT, MET_INT, MET_FLOAT, MET_DOUBLE), ElementSpacing, Offset (or
// Position / Origin), BinaryData, BinaryDataByteOrderMSB (or ElementByteOrderMSB), CompressedData
// (a zlib stream), CompressedDataSize, HeaderSize, ElementNumberOfChannels (1), TransformMatrix (or
// Rotation / Orientation: identity only), ElementDataFile (last). docs/formats.md lists every error.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

Volume read_metaimage(const std::filesystem::path& path);

}  // namespace volref
