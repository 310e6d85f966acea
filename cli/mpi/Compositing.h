// How volref-mpi combines the ranks' parts of every pixel into the image (docs/conventions.md §14):
// direct send (every rank's parts to rank 0, merged there in ray order) or binary swap (log2 N rounds of
// exchanging and merging half the pixels with a partner, then the finished pixels gathered on rank 0).
// Parts merge by their slot's rule (Frame::merge, march/RaySpan.h), front to back by their keys.
#pragma once
#include <cstddef>
#include <vector>

#include "cli/mpi/Frame.h"

namespace volref::mpi {

struct Traffic {
    std::size_t sent = 0, received = 0;  // bytes, this rank, this frame
};

// `part` holds this rank's parts (pixels x slots x kPart doubles; binary swap merges into it). On rank 0,
// `image` receives every pixel (Frame::channels() doubles each); elsewhere it is not touched.
void direct_send(const Frame& frame, const PartBuffer& part, double* image, Traffic& traffic);
void binary_swap(const Frame& frame, PartBuffer& part, double* image, Traffic& traffic);

}  // namespace volref::mpi
