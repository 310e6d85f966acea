// Every numerical choice of the reference profile, in one place, each with its formula.
// docs/conventions.md states the same choices for users; change both together.
#pragma once

namespace volref::conventions {

// Sampling a ray interval [t0, t1] of length L with step h (conventions section 4):
//   n = max(1, ceil(L / h - kSegmentSlack)) segments; segment k < n-1 is [t0 + k h, t0 + (k+1) h],
//   the last is [t0 + (n-1) h, t1] (length L - (n-1) h, in (0, h (1 + kSegmentSlack)]).
// The slack absorbs a remainder shorter than kSegmentSlack * h that is only rounding of L / h
// (e.g. L = 0.3, h = 0.1), instead of creating a sliver segment.
inline constexpr double kSegmentSlack = 1e-9;

// Intervals shorter than this (world units) are dropped: a ray grazing a box edge or face has a
// chord of length 0 (or a rounding error of it) and contributes nothing.
inline constexpr double kMinIntervalLength = 0.0;

// First-hit: the crossing is bracketed between consecutive segment endpoints and refined by
// bisection until the bracket is at most kFirstHitRelativeTolerance * (t1 - t0) of the interval
// searched; the hit is the bracket's midpoint.
inline constexpr double kFirstHitRelativeTolerance = 1e-9;

// Bounding boxes are given to Embree enlarged by this fraction of their largest extent (plus the
// same absolute amount) so that float traversal never culls a ray the double-precision slab test
// would hit; the intervals themselves come from the double-precision test.
inline constexpr double kEmbreeBoundsPadding = 1e-5;

// Shading: a sample whose |grad f| <= kZeroGradientRelative * max(|min|, |max| of the data) /
// (smallest spacing) is unshaded (c_out = m): its normal is undefined. The scale is the data's
// magnitude, not its range, because reconstruction rounds at that magnitude: trilinear weights
// that sum to 1 - 2^-53 turn a constant field of 3 into 3 - 4e-16, a spurious gradient that this
// tolerance removes. An all-zero volume has tolerance 0 (and exactly zero gradients).
inline constexpr double kZeroGradientRelative = 1e-9;

// Empty-space skipping (composite projection; core/sample/MacrocellGrid.h): the cells of the volume
// are grouped into macrocells of kMacrocellSize^3 cells (fewer at the high ends of an axis), each
// holding the [min, max] of every voxel a sample inside it can read (its cells' corners, plus one
// voxel on each side for the tricubic kernels). A ray skips the segments whose midpoints lie in a
// macrocell the classification makes transparent; the image does not change. 8 keeps the grid small
// (1/512 of the cells) while skipping whole blocks of typical empty space.
inline constexpr int kMacrocellSize = 8;

// Gradient cache "auto" (opt-in): cache when the expected number of gradient evaluations per voxel,
//   e = pixels * (domain diagonal / step) * (fraction of voxels with opacity > 0) / voxels,
// exceeds this break-even: the cache's build time per voxel over the saving per evaluation, measured
// on a 256^3 volume along rays (docs/performance.md, "Gradients on a 256^3 volume": 1.0 to 2.6 for
// central differences with trilinear reconstruction). The estimate assumes every ray crosses the
// domain's diagonal, an upper bound, so the rule leans to caching for large images.
inline constexpr double kGradientCacheBreakEven = 2.0;

// Pixel (x, y) is sampled through its centre (x + 0.5, y + 0.5); row 0 is the top row.
inline constexpr double kPixelCentre = 0.5;

// Images are cut into square tiles of this many pixels for the thread pool; results do not depend
// on it (every pixel is computed independently).
inline constexpr int kTileSize = 16;

// 8-bit and 16-bit outputs: q = round(clamp(v, 0, 1) * (2^bits - 1)), round half away from zero.

}  // namespace volref::conventions
