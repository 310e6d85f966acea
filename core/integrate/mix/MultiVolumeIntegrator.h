// MultiVolumeIntegrator: one pixel of a scene with several volumes (scene key `volumes`;
// conventions section 6, "Several volumes"). Each volume k gives its own ray r_k (the world ray, or
// its local ray when the volume is transformed: the same t) and its own intervals I_k (bounds AND
// domain AND clip planes AND crop).
//
// composite (the media mix): the union of every I_k's end points cuts the ray into pieces on which
// the set of volumes present is constant; each piece is cut into segments of the scene's step h (the
// smallest of the volumes' steps) exactly as SamplePlacement.h cuts an interval, and sampled at the
// midpoints. At a midpoint every present volume k gives (a_k, c_k) through its own pipeline; its
// optical depth over the segment is tau_k = -(d / l_k) log1p(-a_k) (transfer/OpacityCorrection.h), the
// extinctions add, tau = sum tau_k, and the emitted colour is the extinction-weighted mix
// c = sum tau_k c_k / tau (c = c_k when one volume is present). The terms are summed in a canonical
// order (sorted by tau_k, then colour), so the listing order of the volumes changes no bit. A sample
// with a_k = 1 is opaque: alpha = 1 and c = the mean of the opaque samples' colours (sorted).
// Compositing then is the single-volume one (front to back with T = exp(-tau) and a compensated
// optical depth, or back to front), with early termination as render.early_termination says.
//
// composite with render.integrator "adaptive": the same mix in continuous form, sigma(t) = sum_k
// sigma_k(t), emission sum_k sigma_k(t) c_k(t) (terms in the same canonical order), integrated by
// AdaptiveComposite over the pieces cut at every present volume's cuts (AdaptiveIntegrator::cuts: its
// cell faces and transfer-function rows; the clip planes and crop faces are already interval ends):
// between them every term is smooth, so the sum is. A piece where some present volume is opaque
// (AdaptiveIntegrator::opaque_piece) is opaque with the mean of those volumes' colours c_k(a+) (sorted),
// as in the fixed mix. The estimate's safety factor is the largest of the volumes'.
//
// mip / minip: each volume's own projection (its transfer function at its extremum), then the
// per-channel maximum / minimum of the premultiplied RGBA over the volumes the ray meets (OpenGL's
// GL_MAX / GL_MIN blending of one image per volume). average: the length-weighted mean over all the
// volumes, sum_k L_k avg_k / sum_k L_k (L_k the length of I_k). x-ray: the sum of the volumes' line
// integrals. first-hit: the nearest hit over all volumes (ties: the smaller RGBA, lexicographically).
#pragma once
#include <memory>
#include <vector>

#include "core/camera/Ray.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/scene/Scene.h"
#include "geometry/RayIntervals.h"

namespace volref {

class AdaptiveIntegrator;
template <class Medium>
class AdaptiveComposite;

class MultiVolumeIntegrator {
public:
    struct Member {
        const SamplePipeline* pipeline;
        const Integrator* integrator;  // the volume's own integrator (projections other than composite)
        const IntegrationContext* context;  // what the adaptive mix builds its per-volume parts from
    };
    // `step`: the composite mix's step (world units).
    // Throws volref::Error where render.integrator "adaptive" cannot integrate a volume.
    MultiVolumeIntegrator(std::vector<Member> volumes, const RenderSpec& render, double step);
    ~MultiVolumeIntegrator();

    // Composite only: the mix along the ray; rays[k], intervals[k] are volume k's.
    PixelValue composite(const Ray* rays, const std::vector<Interval>* intervals) const;
    // Composite with the fixed step, resumable (march/RaySpan.h): `state` (composite_state,
    // SpanStates.h) continued over the mixed segments `span` owns; composite() is the whole ray's.
    void composite_span(const Ray* rays, const std::vector<Interval>* intervals, const RaySpan& span, RayState& state) const;
    // True with early termination: the spans must then be resumed in ray order, not merged.
    bool composite_spans_in_order() const;
    // Other projections: the volumes' own pixels values[k] (from their integrators) combined.
    PixelValue combine(const PixelValue* values, const std::vector<Interval>* intervals) const;

    // The pieces of the union of the volumes' intervals (intervals[k], k < n), front to back: the
    // union's end points cut the ray, and each piece lists the volumes present on all of it.
    struct Piece {
        Interval span;
        std::vector<int> present;
    };
    static std::vector<Piece> pieces(const std::vector<Interval>* intervals, std::size_t n);

    // The mix of the volumes `present` at segment s (composite; fixed step): its optical depth and
    // extinction-weighted colour, or opaque with the mean colour of the opaque samples. composite_span
    // adds these front to back (the whole ray's for composite(), a rank's span for volref-mpi).
    struct MixedSegment {
        double tau = 0.0;
        glm::dvec3 color{0.0};
        bool opaque = false;
    };
    struct MixTerm {
        double tau;
        glm::dvec3 c;
        bool operator<(const MixTerm& o) const;
    };
    struct MixScratch {
        std::vector<MixTerm> terms, opaque_terms;
    };
    MixedSegment mix(const Ray* rays, const std::vector<int>& present, const Segment& s, MixScratch& scratch) const;

    // render.integrator "adaptive", composite: the mixed medium (sigma = sum sigma_k, emission
    // sum sigma_k c_k over the volumes `present`, in canonical order), the sub-pieces of a piece (every
    // present volume's adaptive cuts, merged), and one sub-piece [a, b] added to `st` (skipped when
    // every present volume is empty there; cut where one becomes opaque). adaptive_composite() calls
    // these front to back; volref-mpi for the sub-pieces a rank owns (cli/mpi/). Set `present` of the
    // medium `st` reads to the piece's before adaptive_piece.
    struct AdaptiveMix {
        const std::vector<std::unique_ptr<AdaptiveIntegrator>>* parts;
        const Ray* rays;
        const std::vector<int>* present = nullptr;
        mutable std::vector<MixTerm> terms;
        void sample(double t, double& sigma, glm::dvec3& c) const;
    };
    AdaptiveMix adaptive_mix(const Ray* rays) const { return AdaptiveMix{&adaptive_, rays, nullptr, {}}; }
    double adaptive_safety() const;
    void adaptive_cuts(const Ray* rays, const Piece& p, std::vector<double>& all, std::vector<double>& scratch) const;
    void adaptive_piece(const Ray* rays, const std::vector<int>& present, double a, double b,
                        AdaptiveComposite<AdaptiveMix>& st, std::vector<MixTerm>& opaque_scratch) const;

    std::size_t size() const { return volumes_.size(); }
    const Member& member(std::size_t k) const { return volumes_[k]; }
    double step() const { return step_; }

private:
    PixelValue adaptive_composite(const Ray* rays, const std::vector<Interval>* intervals) const;

    std::vector<Member> volumes_;
    // render.integrator "adaptive", composite: each volume's cuts, medium and opaque test.
    std::vector<std::unique_ptr<AdaptiveIntegrator>> adaptive_;
    const RenderSpec& render_;
    double step_;
};

}  // namespace volref
