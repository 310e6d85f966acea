#include "core/render/PixelBlocks.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace volref {

void parallel_for_tiles(const TileGrid& tiles, const std::function<void(const PixelRect&)>& f) {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tiles.count(), 1),
        [&](const tbb::blocked_range<int>& r) {
            for (int i = r.begin(); i != r.end(); ++i) f(tiles.tile(i));
        },
        tbb::simple_partitioner());
}

}  // namespace volref
