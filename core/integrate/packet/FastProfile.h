// The fast profile (render.profile "fast"; conventions section 9): the reference profile's scene,
// sample placement and formulas, computed on float SIMD lanes (twice as many rays per vector as the
// reference's double lanes) with early termination at kFastTransmittanceCutoff. It exists for speed
// (docs/performance.md) and its error against the reference is measured there and bounded in tests:
// float rounding of positions, weights, tables and compositing (a few 1e-6) plus at most
// kFastTransmittanceCutoff from termination.
//
// It runs only where the SIMD packet kernels do (PacketComposite.h: composite front to back,
// Cartesian trilinear, a transfer function, post-classification; PacketExtremum.h: mip and minip on
// Cartesian trilinear grids), and every pixel goes through them (RenderOptions::simd does not apply);
// any other scene is an error naming render.profile, never a silent fallback to the reference.
//
// The float lanes read the view's `_float` members (VolumeView.h): the transfer-function rows (always
// copies), the voxels (the volume's own storage where it is a 32-bit-gathered type, else a copy: procedural
// fields, f64 files) and the cached gradient components, the copies held by VolumeViewStore.
#pragma once
#include <string>

#include "core/integrate/march/Accumulators.h"
#include "core/sample/VolumeView.h"

namespace volref {

// Fills view.grid_float (and, for the composite, view.rows_float and the float cached gradients) from the
// view's double members, the copies in `store` (memory checked). The voxels: the volume's own storage
// when it is a 32-bit-gathered type (f32, i32, u32, u16, i16, u8, i8) within 2^31 bytes on a
// little-endian host, else a float copy. Throws Error naming render.profile when even the copy would not
// fit 32-bit indices or a voxel is beyond float's range.
void describe_float_lanes(VolumeView& view, bool composite, VolumeViewStore& store);

// The fast profile's termination: `t` and a stop once the transmittance is at most kFastTransmittanceCutoff.
Termination fast_termination(Termination t);

// Pre-integrated segments (render.profile_options.preintegration = n > 0; transfer/PreIntegration.h):
// builds the table over the coordinates the volume's values can take and the transfer function's rows,
// for segments of `step`, into `store`, and points the view at it. Refuses (an error naming
// render.profile_options.preintegration) a shaded scene or gradient-magnitude opacity: the table
// integrates a(x) and c(x) of the value alone.
void make_preintegrated(VolumeView& view, double step, int n, VolumeViewStore& store);

// "render.profile: \"fast\" ...: <reason>; use \"reference\"" (the one-line error of a scene the
// fast path does not take).
[[noreturn]] void fast_profile_unavailable(const std::string& reason);

// The error of `volref trace` / `explain ray` on the fast profile (its packets are its only path).
[[noreturn]] void fast_profile_not_traced();

}  // namespace volref
