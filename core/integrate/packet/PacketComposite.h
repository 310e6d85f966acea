// The SIMD path of front-to-back compositing (Google Highway, dispatched at run time to the best
// instruction set: AVX-512 = 8 rays per vector, AVX2 = 4, SSE4 = 2).
//
// Rays travel in structure-of-arrays packets; each lane walks its own intervals and segments (the
// placement of SamplePlacement.h), and a mask retires lanes whose ray has ended, become opaque or reached
// early termination. Every step is the scalar CompositeIntegrator's arithmetic in the same order:
// the position origin + t direction, the continuous index, Levoy's trilinear sum term by term, the
// piecewise-linear transfer function (first row with x > v), the optical depth
// -(d / l) log1p(-a), alpha = -expm1(-tau_k), C += (exp(-tau) alpha) c and the Neumaier sum of tau,
// all in double, without fused multiply-adds. The only difference is that exp, expm1 and log1p are
// Highway's vector versions (at most 1, 4 and 2 ulp from the correctly rounded value, against
// glibc's < 1 ulp), so a pixel differs from the scalar path by a few ulp of its exp/log terms:
// below 1e-13 absolute in tests, far inside the 1e-6 the reference contract allows. A lane's result
// does not depend on the other lanes, the packet size or the instruction set (AVX2 and AVX-512 use
// the same polynomials with the same fused operations inside them).
//
// Gradients (GradientField.h) follow the scalar scheme exactly: central or forward differences of
// the same trilinear field (with its one-sided differences at the domain boundary), or the trilinear
// interpolation of the cached per-voxel gradients. Gradient-magnitude opacity multiplies and clamps
// as TransferFunction::classify. Shading (Shader.h) repeats Shader::shade operation by operation
// (glm's dot = (x x' + y y') + z z', length = sqrt(dot), normalize = v (1 / sqrt(dot))), except
// that the specular power s^n is exp(n log s) with Highway's exp and log instead of std::pow: a
// relative difference of a few ulp times (1 + n |log s|), below 1e-13 absolute for colours <= 1.
//
// It serves composite, front to back, trilinear, post-classification by a transfer function (with
// or without gradient opacity), unshaded or shaded (Blinn-Phong, Phong, nodal; up to
// VolumeView::kMaxPacketLights lights) with central, forward or cached gradients. Everything else (back to
// front, tricubic or nearest, pre-classification, Levoy's classifiers, shells) takes the scalar
// path. Each lane walks its segments with ForwardSegmentWalk (SegmentWalk.h), so empty-space
// skipping passes over the same segments as in the scalar path.
//
// The fast profile (render.profile "fast", FastProfile.h) runs the same kernel on float lanes (twice
// as many rays per vector): positions, reconstruction, transfer function, gradients and shading in
// float, the tables and voxels as float copies where needed; compositing keeps the transmittance as
// a float product, Tr *= 1 - alpha with alpha = -expm1((d / l) log1p(-a)), C += Tr alpha c, and stops
// a ray once Tr <= kFastTransmittanceCutoff (termination.transmittance_at_most).
#pragma once
#include <vector>

#include "core/camera/Ray.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/packet/PacketRun.h"
#include "core/sample/VolumeView.h"
#include "geometry/RayIntervals.h"

namespace volref {

// Composites `count` (<= kMaxPacketRays) rays front to back into out[0 .. count): the volume `view`
// describes (VolumeView.h), with `run`'s step, termination, skipping and lanes. With `states`
// (march/RaySpan.h), instead resumes states[i] over the samples spans[i] owns and writes nothing to `out`.
void composite_packet(const VolumeView& view, const PacketRun& run, const Ray* rays, const std::vector<Interval>* intervals,
                      PixelValue* out, int count, const RaySpan* spans = nullptr, RayState* states = nullptr);

}  // namespace volref
