// A render as the convention search reads another renderer's image (tests of core/compare/ConventionSearch).
#pragma once
#include <cstddef>

#include "core/compare/ComparedImage.h"
#include "core/film/Image.h"

namespace volref::test {

// The R, G, B, A channels of `im` (premultiplied, as volref renders them) as a ComparedImage.
inline compare::ComparedImage compared_image(const Image& im) {
    compare::ComparedImage g;
    g.rgba = Image(im.width, im.height, {"R", "G", "B", "A"});
    for (std::size_t p = 0; p < std::size_t(im.width * im.height); ++p)
        for (std::size_t c = 0; c < 4; ++c) g.rgba.pixels[p * 4 + c] = im.pixels[p * im.channels.size() + c];
    return g;
}

}  // namespace volref::test
