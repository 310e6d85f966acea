// volref-mpi's composites whose parts cannot be merged afterwards, handed from rank to rank in ray
// order instead (docs/conventions.md §14): the fixed step with early termination (Integrator::
// spans_in_order: a span depends on the opacity in front of it), and render.integrator "adaptive"
// (AdaptiveComposite's refinement depends on the transmittance in front, the largest colour seen and
// the rules left; its error sums run back to front). Every rank lists the pixels whose ray it owns a
// span of (the span's t0 is the key); the keys are all-gathered, giving each pixel's ranks in ray
// order; the j-th rank of each pixel continues that pixel's state over its span and sends it point to
// point to the next (Chain.cpp, hand_on: a pipeline over blocks of pixels).
#pragma once
#include <cstddef>
#include <vector>

#include "cli/mpi/Frame.h"
#include "cli/mpi/PartBuffer.h"

namespace volref::mpi {

// The chain's image-size arrays, made and first touched at set-up (fresh_chain), as the parts are
// (main.cpp fresh_parts), so that render_s is the chain and not their pages' first touch: the states
// handed on, collect's two (the final states this rank holds, their sum on rank 0), for the adaptive
// chain the error sums and their two, and rank 0's pixels. Each is written once per run.
struct ChainBuffers {
    PartBuffer state, held, summed;           // P x the state's doubles (summed: rank 0 only), all zero
    PartBuffer sums, sums_held, sums_summed;  // the adaptive chain's error sums, the same way
    PartBuffer pixels;                        // rank 0: P x Frame::channels()
};
ChainBuffers fresh_chain(const Frame& frame);

// The finished pixels (buffers.pixels, Frame::channels() doubles each) on rank 0, and the bytes this rank
// sent; false after an error (reported by rank 0 through any_error; every rank returns false).
bool chained_pixels(const Frame& frame, ChainBuffers& buffers, std::size_t& bytes_handed);

// Whether the scene's composite is chained (rather than merged from independent parts): the adaptive
// integrator's at any rank count, a fixed step's whose spans go in order (early termination, the fast
// profile) at two ranks or more; at one rank each pixel has one span from a fresh state, which the parts'
// path integrates as `volref render` does.
bool chained(const Frame& frame);

// The bytes the chain's fixed-size arrays take on this rank (--max-memory, checked before they are
// made): per pixel its key and every rank's (1 + ranks doubles), its place among the ranks (4 ints), and
// for each value handed on (the state; the adaptive chain's error sums too) the array, as much again
// received, as much sent and collect's copy (rank 0: and the sum, and the pixels). The adaptive
// chain's pieces and leaves, which depend on the field, are not counted.
std::size_t chain_bytes(const Frame& frame);

}  // namespace volref::mpi
