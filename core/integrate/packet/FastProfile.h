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
// FloatCopies holds what the float kernels read and the scene does not already hold as 32-bit
// values: the transfer-function rows (always), the voxels when they are f64 (procedural fields,
// f64 files), and the cached gradient components.
#pragma once
#include <string>
#include <vector>

#include "core/grid/Volume.h"
#include "core/integrate/packet/PacketComposite.h"
#include "transfer/PreIntegration.h"

namespace volref {

struct FloatCopies {
    std::vector<float> voxels;                      // empty when the volume's own storage serves
    std::vector<float> color_x, color_y, opacity_x, opacity_y, gradient_opacity_x, gradient_opacity_y;
    std::vector<float> cached_gradient[3];
    PreIntegrationTable preintegration;  // render.profile_options.preintegration
};

// The voxels the float kernels gather: the volume's own storage when it is a 32-bit-gathered type
// (f32, i32, u32, u16, i16, u8, i8) within 2^31 bytes on a little-endian host, else a float copy in
// `copies` (memory checked). Sets *data and *type. Throws Error naming render.profile when even the
// copy would not fit 32-bit indices.
void fast_voxels(const Volume& volume, FloatCopies& copies, const void** data, ScalarType* type);

// Fills in.tables_float (and the float voxels and cached gradients) from the double inputs; sets
// in.fast and the transmittance cutoff of in.termination. `cached` are the cached gradient components (Cached) or null.
void make_fast(PacketCompositeInputs& in, const Volume& volume, const Volume* const cached[3], FloatCopies& copies);

// Pre-integrated segments (render.profile_options.preintegration = n > 0; transfer/PreIntegration.h):
// builds the table over the coordinates the volume's values can take and the transfer function's rows,
// for segments of the render's step, into `copies`, and points `in` at it. Refuses (an error naming
// render.profile_options.preintegration) a shaded scene or gradient-magnitude opacity: the table
// integrates a(x) and c(x) of the value alone.
void make_preintegrated(PacketCompositeInputs& in, const TransferFunction& tf, const Volume& volume, int n, FloatCopies& copies);

// "render.profile: \"fast\" ...: <reason>; use \"reference\"" (the one-line error of a scene the
// fast path does not take).
[[noreturn]] void fast_profile_unavailable(const std::string& reason);

// The error of `volref trace` / `explain ray` on the fast profile (its packets are its only path).
[[noreturn]] void fast_profile_not_traced();

}  // namespace volref
