// An image read for comparison (any format OpenImageIO reads), brought to the one convention
// `volref compare` compares in: linear premultiplied (associated) RGBA in double.
//
//   - Colour channels are found by name: R, G, B (or a single Y, used for all three); A if present,
//     else alpha = 1 (opaque). Any other channel is ignored, except `error` and `fault` (kept, see below).
//   - Unassociated alpha (PNG, TIFF as volref writes them: colour divided by alpha) is converted to
//     premultiplied, C = u a, in double, from the stored values (OIIO is asked not to premultiply).
//     Associated inputs (EXR) are taken as they are.
//   - `background` (optional, RGBA not premultiplied): composites every associated input over it,
//     C' = C + (1 - A) bg_a bg_rgb, A' = A + (1 - A) bg_a, as volref does before writing PNG/TIFF;
//     unassociated inputs are taken as composited already. Use it to compare a volref EXR with a PNG
//     written over a non-transparent image.background.
//   - Integer inputs remember their bit depth: their quantisation enters the tolerance (Tolerance.h).
#pragma once
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "core/film/Image.h"

namespace volref::compare {

struct ComparedImage {
    std::filesystem::path path;
    Image rgba;                      // channels R, G, B, A: premultiplied, linear
    std::vector<double> error;       // the file's `error` channel (width * height), empty if none
    std::vector<char> fault;         // the file's `fault` channel != 0 (width * height: the rays a mirrored
                                     // program does not finish), empty if none
    int bits = 0;                    // bits per integer sample (8 for PNG), 0 for floating point
    bool unassociated = false;       // the file stored colour divided by alpha
    std::vector<double> stored;      // unassociated integer inputs: the stored (unassociated) R, G, B, A
                                     // before premultiplying (for the quantisation bound); else empty
    std::string description() const; // e.g. "64x64, 8-bit, unassociated alpha (premultiplied here)"
};

// The pixels where either input's `fault` channel is set (a mirrored program does not finish the
// ray), as (x, y); each is set to 0 in both images (RGBA and `error`), so that the metrics, the tolerance
// test and --fit leave it out.
std::vector<std::array<int, 2>> exclude_faults(ComparedImage& a, ComparedImage& b);

// Reads `path`; throws volref::Error naming the file when it cannot be read or has no R, G, B (or Y).
ComparedImage read_compared_image(const std::filesystem::path& path,
                                  const std::optional<glm::dvec4>& background = std::nullopt);

}  // namespace volref::compare
