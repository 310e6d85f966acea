// The order in which an image's pixels are walked: tiles of a side T (TileGrid; render_scene and
// volref-mpi's parts take one task each: parallel_for_tiles), each tile cut into blocks of
// kPixelBlockWidth x kPixelBlockHeight pixels (for_each_block), the blocks in row order and each
// block's pixels in row order. A block is one call to the integrator: on 16-lane float vectors two
// 4 x 4 packets, whose steps the composite kernel interleaves (PacketComposite.cpp); on 8-lane double
// vectors four 4 x 2 packets. Neighbouring rays read neighbouring voxels; each pixel's value does not
// depend on its tile, block or packet (lanes are independent). Measured in docs/performance.md.
// render_scene, volref-mpi's integrate_parts, its chain's blocks and its work count walk the image
// through these, so all four take the same blocks in the same order.
#pragma once
#include <algorithm>
#include <functional>

namespace volref {

inline constexpr int kPixelBlockWidth = 4;
inline constexpr int kPixelBlockHeight = 8;
inline constexpr int kPixelBlockPixels = kPixelBlockWidth * kPixelBlockHeight;

// The pixels [x0, x1) x [y0, y1) of an image.
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// One block's pixels (x[i], y[i]), i < count, in row order.
struct PixelBlock {
    int count = 0;
    int x[kPixelBlockPixels], y[kPixelBlockPixels];
};

// f(block) for the blocks of `rect`: kPixelBlockWidth x kPixelBlockHeight pixels from the rectangle's
// corner (fewer at its far edges), in row order. `stride` > 1 takes every stride-th block on both
// axes (a sample of the image's blocks, as the full walk cuts them).
template <class F>
void for_each_block(const PixelRect& rect, F&& f, int stride = 1) {
    PixelBlock b;
    for (int by = rect.y0; by < rect.y1; by += kPixelBlockHeight * stride)
        for (int bx = rect.x0; bx < rect.x1; bx += kPixelBlockWidth * stride) {
            const int x_end = std::min(bx + kPixelBlockWidth, rect.x1), y_end = std::min(by + kPixelBlockHeight, rect.y1);
            b.count = 0;
            for (int y = by; y < y_end; ++y)
                for (int x = bx; x < x_end; ++x) {
                    b.x[b.count] = x;
                    b.y[b.count] = y;
                    ++b.count;
                }
            f(static_cast<const PixelBlock&>(b));
        }
}

// A width x height image cut into tiles of side `side` (fewer pixels at the right and bottom edges),
// numbered in row order.
struct TileGrid {
    TileGrid(int width, int height, int side)
        : width(width), height(height), side(side), columns((width + side - 1) / side), rows((height + side - 1) / side) {}
    int count() const { return columns * rows; }
    PixelRect tile(int i) const {
        const int x0 = (i % columns) * side, y0 = (i / columns) * side;
        return {x0, y0, std::min(x0 + side, width), std::min(y0 + side, height)};
    }
    int width, height, side, columns, rows;
};

// f(tile) for every tile, one task each (grain 1, simple_partitioner): a free thread takes the next
// tile, so an expensive tile never waits behind others in a chunk (conventions section 12, the tile
// side). Run it inside the caller's task arena (its thread count). Defined in PixelBlocks.cpp, so that
// this header (public through Renderer.h) asks nothing of TBB's headers or library of its users.
void parallel_for_tiles(const TileGrid& tiles, const std::function<void(const PixelRect&)>& f);

}  // namespace volref
