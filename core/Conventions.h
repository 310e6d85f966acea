// Every numerical choice of the reference profile, in one place, each with its formula.
// docs/conventions.md states the same choices for users; change both together.
#pragma once
#include <cstddef>
#include <cstdint>

namespace volref::conventions {

// Sampling a ray interval [t0, t1] of length L with step h (conventions section 4):
//   n = max(1, ceil(L / h - kSegmentSlack)) segments; segment k < n-1 is [t0 + k h, t0 + (k+1) h],
//   the last is [t0 + (n-1) h, t1] (length L - (n-1) h, in (0, h (1 + kSegmentSlack)]).
// The slack absorbs a remainder shorter than kSegmentSlack * h that is only rounding of L / h
// (e.g. L = 0.3, h = 0.1), instead of creating a sliver segment.
inline constexpr double kSegmentSlack = 1e-9;
// A slicer's level count (core/integrate/profiles/Slices.cpp, conventions section 9,
// "Slice-order renderers"): with spacing s over the range's extent E, n = floor(E / s - o + kSliceSlack) + 1
// levels (o = 0 or 1/2, `first`); with a period, n = ceil(E / D - kSliceSlack). The slack keeps a ratio
// that is an integer up to rounding from gaining or losing a level.
inline constexpr double kSliceSlack = 1e-9;

// Pre-integrated segments (render.profile_options.preintegration; transfer/PreIntegration.h): the table
// has 2 to kPreIntegrationMaxIntervals intervals per axis.
inline constexpr int kPreIntegrationMaxIntervals = 2048;

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

// The fast profile (render.profile "fast", core/integrate/packet/FastProfile.h) stops a ray once its
// transmittance Tr is at most this: what it leaves out is at most Tr times the brightest colour
// behind, 2^-10 < 0.5 / 255, below half a step of an 8-bit image.
inline constexpr double kFastTransmittanceCutoff = 0x1p-10;

// Images are cut into square tiles of this many pixels for the thread pool; results do not depend
// on it (every pixel is computed independently). The side is halved, down to kMinTileSize (one 4 x 4
// packet block), while the image has fewer than kTilesPerThread tiles per thread: tiles of very
// different cost (the adaptive integrator's) then balance over many cores (bench/tile_balance:
// 128 x 128 adaptive, 64 tiles of 16 give 16 workers 13.0x, 256 of 8 15.5x).
// 32: on an Intel Xeon the fast profile's benchmark frame 2-3% faster than with 16 at one
// thread and two (neighbouring blocks' voxels still in cache), the reference's the same (docs/performance.md,
// "Tiles of 32"); on an AMD EPYC 8 to 64 were within 2% (docs/performance.md, "Tile size").
inline constexpr int kTileSize = 32;
inline constexpr int kMinTileSize = 4;
inline constexpr int kTilesPerThread = 16;

// 8-bit and 16-bit outputs: q = round(clamp(v, 0, 1) * (2^bits - 1)), round half away from zero.

// ---- Adaptive integration (render.integrator "adaptive"; core/integrate/Adaptive*.h, docs/accuracy.md) ----
// The default render.tolerance: absolute error per channel (R, G, B, A) of a pixel.
inline constexpr double kAdaptiveDefaultTolerance = 1e-6;
// Each smooth piece [a, b] (between two cuts) is integrated by Gauss-Kronrod G7/K15, globally adaptive
// inside the piece (QUADPACK's QAG): its candidate sub-intervals, each with an error estimate e
// (below, kAdaptiveWeakSafety: emission error plus the colour bound times the optical depth's error),
// are split largest estimate first until T(a) sum e is at most
//   tolerance * (b - a) / (total length of the ray's intervals)   (the budget is shared by length;
// a test per sub-interval never holds beside an integrable singularity of sigma),
// a candidate whose e is at most kAdaptiveRoundoffRelative * |K15| (rounding, QUADPACK's test), or that
// is kAdaptiveMaxDepth bisections deep, is not split again (the estimate is still reported: 2^-48 of a
// piece is below any length the double t of a ray resolves for pieces up to 2^48 ulps long).
inline constexpr int kAdaptiveMaxDepth = 48;
// Work per ray is bounded (an opacity reaching 1 on a cell face would otherwise make the bisection run
// for minutes and grow without bound): a ray evaluates at most kAdaptiveMaxRulesPerRay G7/K15 rules (15
// samples each). Once they are spent, every piece still open is accepted with the estimate it has
// (the halves against their rule), so the pixel's error channel reports what was not resolved instead
// of claiming the tolerance; the ray also stops refining once a cancel is requested (SIGINT/SIGTERM),
// so a render answers it within one tile. 2^14 rules are about 250,000 samples, far more than a smooth
// ray needs at the default tolerance; rays that spend them report error >= T K (T in front of the first
// piece left unresolved, K >= 1 the largest colour), a bound on what the rest of the ray may change.
inline constexpr long kAdaptiveMaxRulesPerRay = 1L << 14;
inline constexpr double kAdaptiveRoundoffRelative = 50.0 * 2.220446049250313e-16;  // 50 eps
// Opacities are clamped to 1 - 2^-53 inside a piece so that sigma = -log1p(-a) / l stays finite at an
// isolated point where a reaches 1 (a ramp ending at 1, a value touching a row with a = 1): the
// integral changes only where a > 1 - 2^-53, a set of length ~ 2^-53 of the ramp. A piece is opaque
// (the ray ends there, T = 0 behind it) when its opacity is 1 at its midpoint and at
// a + kAdaptiveOpaqueColourOffset (b - a) and b - kAdaptiveOpaqueColourOffset (b - a): between two
// cuts the transfer function is linear in s, so that is opacity 1 on the whole piece, not at one point
// (with the midpoint alone, a tent of opacity 1 at a value reached on a grid plane would make every ray
// crossing the plane opaque). A piece with kAdaptiveOpaqueMinDoubles or fewer doubles inside it is never opaque:
// its ends are two cuts that coincide in exact arithmetic (a face and a row's root, found to rounding).
inline constexpr double kAdaptiveMaxOpacity = 1.0 - 0x1p-53;
inline constexpr int kAdaptiveOpaqueMinDoubles = 4;
// Where kinks of the classification are not cuts (kAdaptiveWeakSafety below), a run of opacity 1 may
// start inside a piece; it is found by sampling the piece at kAdaptiveRowSamples + 1 points, bisected
// to rounding, and must also hold at t_s + kAdaptiveOpaqueColourOffset (b - a) (AdaptiveIntegrator::
// opaque_from): the clamped sigma would otherwise spread the opaque colour over 1/36.7 of a unit length.
// The colour of an opaque piece [a, b] is c(a+), read at a + kAdaptiveOpaqueColourOffset (b - a): just
// inside the piece, so that a jump of the transfer function at a (a root found to rounding) is on
// the piece's side.
inline constexpr double kAdaptiveOpaqueColourOffset = 1e-9;
// Where the field along a piece is not a cubic (tricubic cells, beam-space grids), transfer-function
// rows are located by sampling the piece at this many + 1 equally spaced points (a crossing is a sign
// change of s - x_k between neighbours, then bisected to rounding). 8 intervals per cell resolve the
// up to 9 roots of a tricubic cell's degree-9 polynomial when they are not closer than 1/8 cell.
inline constexpr int kAdaptiveRowSamples = 8;
// Each accepted pair of halves [a, m], [m, b] is checked against the rule on [a, b]: the estimate is
// |K15[a, b] - (K15[a, m] + K15[m, b])| + |K15 - G7| of each half (a rule against its halves catches
// what both rules of one evaluation miss). Where kinks of the integrand lie inside pieces (shading,
// gradient opacity, Levoy's classification, tricubic and beam-space pieces, nearest), that estimate
// is multiplied by this safety factor, for acceptance and in the error channel: the halving estimate
// assumes the rule's error falls by 2^(order) per halving, a kink's only by 4 (measured: without the
// factor, up to 1.7 x underestimates on the reference scenes; tests/unit/test_adaptive.cpp).
inline constexpr double kAdaptiveWeakSafety = 10.0;
// Projections whose adaptive result is exact up to rounding (mip/minip: the cubic's extrema; first
// hit: the cubic's first root) report error = kRoundingErrorRelative * (1 + max |channel|): a bound
// on the rounding of reconstruction and classification (a few dozen operations of relative 2^-53).
inline constexpr double kRoundingErrorRelative = 1e-13;

// Step doubling (volref render --error with the fixed integrator): the image I_h is rendered again at
// h / 2; for a method of order 2, I_h - I = c h^2 + O(h^3) gives I_h - I ~ (4 / 3) (I_h - I_{h/2}).
// The error channel is kStepDoublingSafety * (4 / 3) * max over R, G, B, A of |I_h - I_{h/2}|; the
// safety factor covers pixels not yet in the asymptotic range (c varies with h where segment ends move
// across cell faces and transfer-function breakpoints), measured in tests/unit/test_adaptive.cpp.
inline constexpr double kStepDoublingSafety = 5.0;
// ... and the difference used is the largest over the pixel's (2 r + 1)^2 neighbourhood, r = this:
// where the difference vanishes or shrinks by accident (a chord shorter than h / 2 has one segment at
// both steps; the error constant changes sign between h and h / 2 as segment ends cross cell faces),
// the neighbours' rays cross the same cells and are not all in that accident.
inline constexpr int kStepDoublingNeighbourhood = 1;

// JSON documents (scene files, sidecars, --set values, --shell) nest at most this many arrays and
// objects; deeper input is an error naming the outermost path (its nesting would otherwise exhaust the
// stack of the code that walks the document).
inline constexpr int kMaxJsonDepth = 256;

// Extreme numbers (docs/robustness.md): every number a JSON document gives volref, and every
// spacing and origin a volume header gives, is 0 or has a magnitude in [kMinMagnitude, kMaxMagnitude].
// Within it a product or quotient of two such numbers (a ray parameter, a length over a step, a squared
// distance) stays a finite, normal double, so the arithmetic of a render is exact where it is all
// finite doubles; a number beyond it is refused with one line naming its key, not rendered as NaN.
inline constexpr double kMaxMagnitude = 1e100;
inline constexpr double kMinMagnitude = 1e-100;
// The samples one ray may take in one volume at the fixed step, counted before any ray is cast as the
// diagonal of the volume's world bounding box over the step; a smaller step is refused (render.step).
inline constexpr double kMaxSamplesPerRay = 0x1p32;
// Memory accounted per sample of `volref trace` (the record, plus its CSV or JSON text) and per triangle
// of a tessellated shell (the mesh, its vertex map, Embree's BVH and the float copies), checked against
// --max-memory before they are made; a set of tetrahedra (geometry/TetrahedralMesh.h) counts 4 triangles
// per tetrahedron (its faces: the face table, then at most that many boundary triangles).
inline constexpr std::size_t kTraceBytesPerSampleOutput = 1024;
inline constexpr std::size_t kMeshBytesPerTriangle = 256;
// Tetrahedral bounds (volume.bounds type "tetrahedra", geometry/TetrahedralMesh.h): a tetrahedron
// (a, b, c, d) is degenerate, and an error, when
//   |det(b - a, c - a, d - a)| <= kTetrahedronDegenerateRelative * l^3,  l its longest edge
// (det = 6 x its signed volume; det / l^3 is a shape measure, 1 / sqrt(2) for the regular tetrahedron,
// 0 for a flat one). Rounding of det is a few eps l^3 when the coordinates are within about 1000 l of
// each other, far below 1e-12 l^3, so a tetrahedron refused is flat to about 12 digits and one kept is
// not flat by rounding. The sign of det only orients it (VTK files hold either orientation).
inline constexpr double kTetrahedronDegenerateRelative = 1e-12;
// SIGINT / SIGTERM are polled every this many samples inside a ray's march and every piece a reader
// decodes (core/Cancellation.h), so that even a single ray of 2^32 samples stops within milliseconds.
inline constexpr std::int64_t kCancellationPollSamples = 4096;

}  // namespace volref::conventions
