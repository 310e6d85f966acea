// volref-mpi's work balance (--balance work; docs/conventions.md §14): the bricks cut where the
// samples balance, counted on the cell-balanced bricks first.
#pragma once
#include <vector>

#include "cli/mpi/Bricks.h"
#include "cli/mpi/Frame.h"

namespace volref::mpi {

// Every rank walks the rays of every kProbe-th pixel on both axes over the span it owns, as the render
// places the samples (the first volume's step and, for composite, its empty-space skipping: march()
// with the rank's macrocells), and counts the samples in WorkBins (kWorkBins per axis of the lattice);
// the counts are summed over the ranks (exact: integers in doubles), so every rank cuts the same
// bricks, and the same ones on every run (the image's last bits depend on the cut, conventions §14: a
// cut from timings would not be reproducible). count_work: this rank's counts; balanced_bricks (every
// rank calls it: MPI_Allreduce) sums them and cuts.
WorkBins count_work(const Frame& f);
std::vector<Brick> balanced_bricks(const Frame& f, WorkBins mine);

}  // namespace volref::mpi
