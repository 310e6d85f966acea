// How the packet kernels read f32 voxels' x-neighbour pairs f(i, j, k), f(i + 1, j, k)
// (PacketKernels-inl.h, PacketTrilinearT::corners): one 64-bit load per lane, the lanes' pairs joined into
// vectors (Loads), or 64-bit gathers, one per half vector of float lanes and one per vector of double lanes
// (Gathers). The same values either way: a speed choice that changes no bit (conventions section 12).
// Auto, the default: Gathers on Intel CPUs, Loads on others. Measured (the EPYC's case in docs/performance.md,
// "What did not help"): on an Intel Xeon with AVX-512 the gathers made the reference's benchmark frame 7% and
// the fast profile's 3.5% faster; on an AMD EPYC the loads measured 18% faster than 32-bit gathers and 25%
// faster than these 64-bit gathers.
#pragma once

namespace volref {

enum class PairFetch { Auto, Loads, Gathers };

// Process-wide (tests render with each in turn). The environment variable VOLREF_PAIR_FETCH = loads or
// gathers decides Auto (benchmarks: an A/B without a rebuild); any other value is an error naming it.
void set_pair_fetch(PairFetch how);
// Whether the kernels gather pairs now (Auto resolved once per process; throws volref::Error for a bad
// VOLREF_PAIR_FETCH).
bool pair_fetch_gathers();

}  // namespace volref
