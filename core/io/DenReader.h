// Reading VolPack density files (.den, from Levoy's group's VolPack; libvolpack1-dev's examples/denfile.c)
// into a Volume. The file is a 62-byte header of 16-bit and 32-bit integers, then u8 samples, x fastest:
//   byte  0  map_version  int16 = 1 (its byte order gives the header's: 01 00 little, 00 01 big)
//   byte  2  orig_min[3], orig_max[3], orig_len[3]   int16 each (ignored)
//   byte 20  extr_min[3], extr_max[3], extr_len[3]   int16 each (ignored)
//   byte 38  map_min[3], map_max[3]                  int16 each (ignored)
//   byte 50  map_len[3]                              int16: the dims (each >= 1)
//   byte 56  map_warps                               int16 (ignored)
//   byte 58  map_length                              int32 = map_len[0] * map_len[1] * map_len[2]
//   byte 62  map_length u8 samples
// The format has no spacing or origin: the volume gets spacing 1 and origin 0. docs/formats.md.
#pragma once
#include <filesystem>

#include "core/grid/Volume.h"

namespace volref {

Volume read_den(const std::filesystem::path& path);

}  // namespace volref
