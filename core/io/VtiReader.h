// Reading VTK XML ImageData files (.vti) into a Volume. expat reads the XML (up to the start of
// <AppendedData>, whose raw bytes are not XML); volref reads the one scalar point-data array:
//   <VTKFile type="ImageData" byte_order="LittleEndian|BigEndian" header_type="UInt32|UInt64"
//            compressor="vtkZLibDataCompressor">           (compressor optional)
//     <ImageData WholeExtent="x0 x1 y0 y1 z0 z1" Origin="x y z" Spacing="sx sy sz">
//       <Piece Extent="...">                                 (exactly one piece)
//         <PointData Scalars="name">
//           <DataArray type="UInt8..Float64" Name="name" format="ascii|binary|appended" offset="N"/>
//   <AppendedData encoding="raw|base64"> _DATA </AppendedData>
// Binary data (inline base64 or appended) start with a header of header_type words: the byte count,
// or with compression [number of blocks, block size, last block size, compressed size of each block]
// followed by the zlib-compressed blocks (vtkZLibDataCompressor). In base64, a compression header is
// encoded on its own, then the blocks. Voxel (i, j, k) of the extent is at Origin + (i, j, k) * Spacing.
// docs/formats.md lists every error.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

Volume read_vti(const std::filesystem::path& path);

}  // namespace volref
