// The accumulators of the ray-marching core: one per projection family, each written once over a
// lane type L (core/Lanes.h: ScalarLanes<double> for the scalar paths, SimdLanes<double> and
// SimdLanes<float> for the packet path and the fast profile). Every integrator and every profile
// composites, takes extrema and sums line integrals through these classes; the formulas below are
// the only copies in the renderer (conventions sections 3, 5, 6 and 9).
//
//   opacity correction   tau_k = -(d / l) log1p(-a),  alpha_k = -expm1(-tau_k)   (sample_opacity, with
//                        transfer/OpacityCorrection-inl.h's optical_depth and segment_alpha)
//   front to back        C += (T alpha_k) c_k, T by the transmittance rule           (FrontToBack)
//   back to front        C = alpha_k c_k + (1 - alpha_k) C  (Over), or seed 001's
//                        sum += (col - sum) w on R, G, B, A (Lerp)                    (BackToFront)
//   extremum             the first largest (MIP) or smallest (MinIP) finite value     (Extremum)
//   line integral        sum_k x_k and sum_k d_k (average = their ratio; x-ray = gain times the sum)
//                                                                                      (LineIntegral)
//   Neumaier summation   t = s + x; c += |s| >= |x| ? (s - t) + x : (x - t) + s; s = t (compensated_add)
#pragma once
#include "core/Lanes.h"
#include "transfer/OpacityCorrection.h"

namespace volref {

// How front-to-back compositing keeps the transmittance T in front of the next sample.
enum class TransmittanceRule {
    OpticalDepthSum,  // the reference: tau = the compensated sum of the tau_k, T = exp(-tau), A = -expm1(-tau)
    Product,          // the fast profile: T *= 1 - alpha_k in the lane type, A = 1 - T
    OpacitySum,       // GPU shaders (mirror profiles): A += (1 - A) alpha_k, T = 1 - A
};

// When a front-to-back ray stops (besides an opaque sample): once A > alpha_above (early termination;
// VTK's GPU shader: 1 - 1/255), A >= alpha_at_least (a textbook shader: 1), or T <= transmittance_at_most
// with T the transmittance rule's own (the fast profile's cutoff; custom profiles). A rule that is off is
// never tested.
struct Termination {
    bool test_alpha_above = false;
    double alpha_above = 1.0;
    bool test_alpha_at_least = false;
    double alpha_at_least = 1.0;
    bool test_transmittance = false;
    double transmittance_at_most = 0.0;
};

// How back-to-front compositing combines a sample with what lies behind it.
enum class BackToFrontRule {
    Over,  // the reference: C = alpha c + (1 - alpha) C (an opaque sample: C = c), A = -expm1(-sum tau)
    Lerp,  // seed 001 (cuda-curvilinear): sum = lerp(sum, (c, a), w) = sum + (col - sum) w on R, G, B, A
};

// Average and x-ray: sum_k x_k (x_k = s(v_k) d_k, or the profile's own weights) and sum_k d_k, each
// in a Sum (CompensatedSum for the reference; PlainSum for a GPU shader's plain accumulator).
template <class Sum>
class LineIntegral {
public:
    void add(double x, double length) {
        integral_.add(x);
        length_.add(length);
    }
    LineIntegral() = default;
    LineIntegral(const Sum& integral, const Sum& length) : integral_(integral), length_(length) {}
    const Sum& integral_sum() const { return integral_; }
    const Sum& length_sum() const { return length_; }
    double integral() const { return integral_.value(); }
    double length() const { return length_.value(); }
    double mean() const { return integral_.value() / length_.value(); }

private:
    Sum integral_, length_;
};

// A plain running sum (a shader's accumulator), beside CompensatedSum.
class PlainSum {
public:
    void add(double x) { s_ += x; }
    double value() const { return s_; }

private:
    double s_ = 0.0;
};

// The templates, in namespace volref for the scalar lanes (the SIMD kernels include the same file
// inside each Highway target's namespace: packet/PacketKernels-inl.h).
#include "core/integrate/march/Accumulators-inl.h"

}  // namespace volref
