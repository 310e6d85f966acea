// AdaptiveIntegrator: the reference integrator of render.integrator "adaptive" (docs/accuracy.md).
//
// Each ray interval is cut where the integrand is not smooth, then each smooth piece is integrated by
// Gauss-Kronrod G7/K15 with recursive bisection until its error estimate fits its share of
// render.tolerance (core/Conventions.h, "Adaptive integration"). All in double.
//
// Cuts (pieces):
//   Cartesian trilinear: the cell faces (AdaptiveCellWalk.h); inside a cell the field is a cubic in t
//     (CellCubic.h); with a post-classified transfer function also every t where the cubic crosses a
//     row value of the colour or opacity function (the roots, isolated between the cubic's extrema and
//     bisected to rounding). Between cuts the value and the transfer function are then smooth, and so
//     is the integrand unless shading (max(N.L, 0) has kinks), gradient opacity (rows of |grad f|) or
//     Levoy's classification (tents) add kinks inside: those are found only by bisection.
//   Cartesian tricubic: the cell faces (the kernels' knots), and the rows' crossings found by sampling
//     each piece at kAdaptiveRowSamples + 1 points (a sign change of s - x_k, bisected to rounding).
//   Cartesian nearest: the faces of the nearest-neighbour regions (u = i + 1/2): the value is constant
//     between them.
//   Beam-space grids (shells): the fixed integrator's segment ends (render.step), the crossings of the
//     grid's coordinate surfaces (where the beam-space cell changes between kAdaptiveRowSamples + 1
//     samples of a piece, halved to rounding) and the rows' crossings found by sampling as for
//     tricubic (a weaker guarantee: a cell entered and left between two samples is not cut;
//     docs/accuracy.md).
//
// Composite (emission-absorption, conventions section 3 in continuous form): with
// sigma(t) = -log1p(-a(t)) / l, T(t) = exp(-tau(t)), tau(t) = integral of sigma up to t,
//   C = integral c(t) sigma(t) T(t) dt,   A = 1 - T(end) = -expm1(-tau_total).
// A rule on [a, b] gives Delta tau = integral of sigma (K15) and E = integral c sigma exp(-(tau(t) - tau(a)))
// (K15, with tau(t) - tau(a) at the nodes from the integration matrix, core/GaussKronrod.h), and the
// same by G7. A candidate [a', b'] with rule P and halves L, R has the estimate
//   e = |P - (L + R)| + |K15 - G7|_L + |K15 - G7|_R   (E of L + R = E_L + exp(-Delta tau_L) E_R),
// for the emission (e_E, max over channels) and the optical depth (e_tau), times kAdaptiveWeakSafety
// where kinks lie inside pieces. Each piece [a, b] between cuts is refined globally (AdaptiveComposite.h):
// the candidate with the largest e_E + K e_tau is split until T(a) sum (e_E + K e_tau) <= tolerance
// (b - a) / (ray length); then, front to back, C += T(a') E and tau += Delta tau for each candidate,
// both compensated sums (never a product of transmittances).
// A piece whose opacity is 1 at its midpoint and just inside both ends (and that is longer than
// kAdaptiveOpaqueMinDoubles doubles) is opaque: C += T c(start of the piece), A = 1, and the ray ends. The order (front to back, back to front) does not apply.
//
// Error (PixelValue::error, the "error" channel): to first order in the leaf estimates,
//   colour: sum_i T_i e_E,i + sum_i e_tau,i * max_ch C_after,i   (C_after,i: what is emitted behind leaf i,
//           which an error d in tau_i scales by exp(-d)),   alpha: T_end sum_i e_tau,i,
// the larger of the two, plus kRoundingErrorRelative (1 + max |channel|).
//
// average / xray: the integral of the transfer function's coordinate s(f(t)), K15 per leaf, error
// sum |K15 - G7| (times gain, or divided by the length for average). Cartesian trilinear: s is a cubic
// inside a cell, so G7 is already exact there.
// mip / minip (Cartesian trilinear or nearest): the maximum / minimum of the field over the ray, exact:
// per cell the cubic's values at the cell ends and at the roots of its derivative (nearest: each
// region's constant). Error: rounding only.
//
// Non-finite values (NaN, +-Inf voxels, read by a sample): the sample is transparent (no opacity, no
// emission) and contributes 0 to line integrals; mip/minip ignore it (docs/accuracy.md).
#pragma once
#include <vector>

#include "core/integrate/adaptive/AdaptiveComposite.h"
#include "core/integrate/adaptive/CellCubic.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/Integrator.h"

namespace volref {

class ShellGrid;
class TransferFunction;
class VolumeSampler;

class AdaptiveIntegrator final : public OneLoopIntegrator<AdaptiveIntegrator> {
public:
    // Throws volref::Error (naming render.integrator) for what it does not integrate.
    explicit AdaptiveIntegrator(const IntegrationContext& ctx);
    // Whole rays and spans (RayBatch, OneLoopIntegrator), every ray by its pieces; the error channel
    // always. Resumable for mip, minip, average and x-ray: the pieces whose midpoints a span owns. Not
    // the composite, whose state (AdaptiveComposite) volref-mpi hands on itself. There is no traced loop.
    void merge_spans(RayState& front, const RayState& back) const override;
    PixelValue finish(const Ray& ray, const std::vector<Interval>& intervals, const RayState& state) const override;

    // The cut points of one interval (t0, ..., t1), increasing: the pieces described above.
    void cuts(const Ray& ray, const Interval& iv, std::vector<double>& out) const;
    // The same cuts where `span` (march/RaySpan.h) can own pieces: those the span owns are the whole
    // interval's, the others may be missing or cut short (span_part). Empty when the span is far from iv.
    void cuts(const Ray& ray, const Interval& iv, std::vector<double>& out, const RaySpan& span) const;

    // What the composite reads, also used by the several-volume mix (MultiVolumeIntegrator):
    // sigma(t) = -log1p(-min(a, kAdaptiveMaxOpacity)) / l and c(t), 0 and 0 where not finite;
    void medium(const Ray& ray, double t, double& sigma, glm::dvec3& c) const;
    // is the piece [a, b] opaque (opacity 1 on all of it; conventions.h, kAdaptiveMaxOpacity)?
    bool opaque_piece(const Ray& ray, double a, double b) const;
    // where the piece [a, b] becomes opaque for good: a when opaque_piece; where kinks inside pieces
    // are not cut, the entry of a run of opacity 1 found by sampling (conventions.h); else +infinity;
    double opaque_from(const Ray& ray, double a, double b) const;
    // an opaque piece's colour, c(a+) (kAdaptiveOpaqueColourOffset);
    glm::dvec3 opaque_colour(const Ray& ray, double a, double b) const;
    // does the piece lie in an empty macrocell (every sample of it has opacity 0)?
    bool empty_piece(const Ray& ray, double a, double b) const;
    // 1, or kAdaptiveWeakSafety where kinks of the integrand lie inside pieces.
    double safety() const;

    // The composite of one volume: its medium, and one piece [a, b] between two cuts added to `st`
    // (skipped when empty; cut where it becomes opaque). composite() calls it for every piece front to
    // back; volref-mpi for the pieces a rank owns, continuing the state of the ranks in front.
    struct OneVolume {
        const AdaptiveIntegrator* self;
        const Ray* ray;
        void sample(double t, double& sigma, glm::dvec3& c) const { self->medium(*ray, t, sigma, c); }
    };
    using Composite = AdaptiveComposite<OneVolume>;
    void composite_piece(const Ray& ray, double a, double b, Composite& st) const;

    // mip / minip: the pieces of an interval (cell faces; nearest: the regions' faces), and one piece's
    // candidates (its ends in its own cell and the cubic's extrema; nearest: its midpoint) added to acc.
    void extremum_cuts(const Ray& ray, const Interval& iv, std::vector<double>& out) const;
    void extremum_piece(const Ray& ray, double ta, double tb, Extremum<Scalar>& acc) const;
    // average / xray: the sums along the ray (the integral, its error estimate, the rules left), and one
    // piece [a, b] between two cuts added to them with the accepted error `per_length` per unit length.
    struct LineSums {
        CompensatedSum integral;
        double error = 0.0;
        long rules_left = conventions::kAdaptiveMaxRulesPerRay;
    };
    void line_piece(const Ray& ray, double a, double b, double per_length, LineSums& sums) const;
    // The ray's length L (compensated sum of its intervals') and the accepted error per unit length:
    // tolerance (average, pixel I / L) or tolerance / (gain L) (xray, pixel gain I; 0 when L = 0).
    static double line_length(const std::vector<Interval>& intervals);
    double line_budget(double length) const;

private:
    friend class OneLoopIntegrator<AdaptiveIntegrator>;
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, NoRecording& rec) const;
    void integrate_span_impl(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, RayState& state) const;
    PixelValue composite(const Ray& ray, const std::vector<Interval>& intervals) const;
    PixelValue line_integral(const Ray& ray, const std::vector<Interval>& intervals) const;
    PixelValue extremum(const Ray& ray, const std::vector<Interval>& intervals) const;
    void line_over(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span, LineSums& st) const;
    PixelValue line_pixel(const std::vector<Interval>& intervals, const CompensatedSum& integral, double error) const;
    void extremum_over(const Ray& ray, const std::vector<Interval>& intervals, const RaySpan& span,
                       Extremum<Scalar>& acc) const;
    glm::dvec4 extremum_rgba(const Ray& ray, double t) const;
    // The rows' crossings inside each piece of `out` where the field is not a cubic, found by sampling.
    void sampled_row_cuts(const Ray& ray, std::vector<double>& out) const;
    Interval span_part(const Ray& ray, const Interval& iv, const RaySpan& span) const;
    // Beam space: the crossings of the grid's coordinate surfaces inside each piece, found by sampling.
    void sampled_shell_cuts(const Ray& ray, std::vector<double>& out) const;

    Accumulation kind_;                   // accumulation(render.projection)
    bool maximum_ = false;                // Extremum: mip (else minip)
    bool mean_ = false;                   // LineIntegral: average (else xray)
    const VolumeSampler* cartesian_ = nullptr;
    const ShellGrid* shell_grid_ = nullptr;  // beam-space grid (shell bounds), else null
    double cut_offset_ = 0.0;             // 0: cell faces; 0.5: nearest regions
    bool cut_cells_ = false;              // Cartesian: cut at grid planes
    bool cubic_ = false;                  // Cartesian trilinear: cubic per cell
    bool weak_ = false;                   // composite: kinks inside pieces (kAdaptiveWeakSafety applies)
    const TransferFunction* rows_ = nullptr;  // post-classified transfer function (not nearest): cut at its rows
    std::vector<double> row_values_;      // its distinct row values (the function's coordinate), sorted
};

}  // namespace volref
