// volref-mpi's work balance (--balance work; docs/conventions.md §14): the bricks cut where the
// samples balance, counted on the cell-balanced bricks first.
#pragma once
#include <vector>

#include "cli/mpi/Bricks.h"
#include "cli/mpi/Frame.h"

namespace volref::mpi {

// Every rank walks rays over the span it owns, as the render places the samples (the first volume's step
// and, for composite, its empty-space skipping: march() with the rank's macrocells), and adds their work
// to WorkBins (kWorkBins per axis of the lattice): for the adaptive integrator each sample of the rays of
// every kProbe-th pixel on both axes counts 1; for the fixed step the rays of every kProbeBlocks-th pixel
// block are taken as the render's SIMD packets and each packet step costs what add_packet_work (Bricks.h)
// says: a constant plus the distinct cache lines its lanes start on. The values are integers and are
// summed over the ranks (exact), so every rank cuts the same bricks, and the same ones on every run (the
// image's last bits depend on the cut, conventions §14: a cut from timings would not be reproducible).
// count_work: this rank's counts; balanced_bricks (every rank calls it: MPI_Allreduce) sums them and cuts.
WorkBins count_work(const Frame& f);
std::vector<Brick> balanced_bricks(const Frame& f, WorkBins mine);

}  // namespace volref::mpi
