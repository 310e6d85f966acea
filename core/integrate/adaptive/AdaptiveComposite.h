// AdaptiveComposite: the adaptive emission-absorption integral of one medium along one ray
// (AdaptiveIntegrator.h states the rule, the acceptance test and the error; core/Conventions.h the
// constants). One volume (AdaptiveIntegrator::composite) and the mix of several volumes
// (MultiVolumeIntegrator, render.integrator "adaptive") call it with their own Medium:
//
//   struct Medium { void sample(double t, double& sigma, glm::dvec3& c) const; };
//
// giving the extinction sigma(t) >= 0 (finite) and the colour c(t) (emission c sigma). The caller cuts
// the ray into smooth pieces, calls integrate(a, b) for each piece front to back, opaque(c) for an
// opaque piece (the ray ends), and then result().
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/Cancellation.h"
#include "core/Conventions.h"
#include "core/integrate/Integrator.h"
#include "core/GaussKronrod.h"
#include "core/integrate/march/Accumulators.h"

namespace volref {

namespace adaptive_detail {
inline double max_abs(const glm::dvec3& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }
inline double max_abs(const glm::dvec4& v) { return std::max(max_abs(glm::dvec3(v)), std::fabs(v.w)); }
// kRoundingErrorRelative (1 + max |channel|): the error of a result exact up to rounding.
inline double rounding_bound(const glm::dvec4& rgba) {
    return conventions::kRoundingErrorRelative * (1.0 + max_abs(rgba));
}
// A leaf accepted by the composite, for its posterior error (AdaptiveComposite::error_sums).
struct Leaf {
    glm::dvec3 contribution;  // T(a) E
    double e_emission;        // T(a) e_E
    double e_tau;
};
}  // namespace adaptive_detail

template <class Medium>
class AdaptiveComposite {
public:
    // `tolerance`: render.tolerance; `safety`: 1, or kAdaptiveWeakSafety where kinks inside pieces are
    // not located; `total`: the length of all the ray's intervals (the budget is shared by length).
    AdaptiveComposite(const Medium& medium, double tolerance, double safety, double total)
        : medium_(medium), tolerance_(tolerance), safety_(safety), total_(total) {}

    double transmittance() const { return acc_.transmittance(); }

    // One smooth piece [a, b], behind everything integrated so far.
    void integrate(double a, double b) { integrate_piece(a, b); }

    // An opaque piece with colour c: C += T c, A = 1; nothing behind it counts.
    void opaque(const glm::dvec3& c) {
        opaque_colour_ = acc_.transmittance() * c;
        const double cc[3] = {c.r, c.g, c.b};
        acc_.add_opaque(cc);
        opaque_ = true;
    }
    bool is_opaque() const { return opaque_; }

    // The pixel and its error (AdaptiveIntegrator.h, "Error").
    PixelValue result() const {
        glm::dvec3 behind = opaque_colour_;
        double colour_err = 0.0, tau_err = 0.0;
        error_sums(leaves_, behind, colour_err, tau_err);
        return result_from(colour_err, tau_err);
    }

    using LeafRecord = adaptive_detail::Leaf;
    // Posterior error: leaf i's tau error scales everything emitted behind it. Adds the leaves' terms,
    // back to front, to colour_err and tau_err; `behind` is what is emitted behind the last leaf (the
    // opaque piece's T c, or 0), and on return behind the first.
    static void error_sums(const std::vector<LeafRecord>& leaves, glm::dvec3& behind, double& colour_err, double& tau_err) {
        using adaptive_detail::max_abs;
        for (auto it = leaves.rbegin(); it != leaves.rend(); ++it) {
            colour_err += it->e_emission + it->e_tau * max_abs(behind);
            tau_err += it->e_tau;
            behind += it->contribution;
        }
    }
    // The pixel, given the error sums over every leaf of the ray.
    PixelValue result_from(double colour_err, double tau_err) const {
        PixelValue out;
        const double T_end = opaque_ ? 0.0 : acc_.transmittance();
        out.rgba = glm::dvec4(acc_.color(0), acc_.color(1), acc_.color(2), acc_.alpha());
        // A piece accepted unresolved (the ray's rules spent) may be wrong by anything it and the pieces
        // behind it contribute: at most T K in each channel (T in front of it, K >= 1 the largest colour).
        out.error = std::max(colour_err, T_end * tau_err) + adaptive_detail::rounding_bound(out.rgba) +
                    unresolved_T_ * colour_bound_;
        return out;
    }
    const std::vector<LeafRecord>& leaves() const { return leaves_; }

    // volref-mpi (cli/mpi/): the state a ray carries from one rank's pieces to the next's, kStateSize
    // doubles: the accumulator (kAcc values), K, the rules left, the transmittance of the first
    // unresolved piece, opaque, and from kStateOpaqueColour on the opaque piece's T c (what lies behind
    // the last leaf, where the error's sums start). load() starts a new list of leaves (each rank keeps
    // its own).
    using Accumulator = FrontToBack<Scalar, TransmittanceRule::OpticalDepthSum, true>;
    static constexpr int kAcc = Accumulator::kStateValues;
    static constexpr int kStateOpaqueColour = kAcc + 4;
    static constexpr int kStateSize = kStateOpaqueColour + 3;
    void save(double* s) const {
        bool opaque = false;  // the accumulator's flag, which is opaque_
        acc_.save(s, opaque);
        s[kAcc] = colour_bound_;
        s[kAcc + 1] = double(rules_left_);
        s[kAcc + 2] = unresolved_T_;
        s[kAcc + 3] = opaque_ ? 1.0 : 0.0;
        for (int i = 0; i < 3; ++i) s[kStateOpaqueColour + i] = opaque_colour_[i];
    }
    void load(const double* s) {
        opaque_ = s[kAcc + 3] != 0.0;
        acc_.load(s, opaque_);
        colour_bound_ = s[kAcc];
        rules_left_ = long(s[kAcc + 1]);
        unresolved_T_ = s[kAcc + 2];
        opaque_colour_ = glm::dvec3(s[kStateOpaqueColour], s[kStateOpaqueColour + 1], s[kStateOpaqueColour + 2]);
        leaves_.clear();
    }

private:
    // One G7/K15 evaluation of [a, b]: the emission E (relative to T(a)) and Delta tau by both rules.
    struct Rule {
        glm::dvec3 ek{0.0}, eg{0.0};
        double tk = 0.0, tg = 0.0;
        double em_error() const { return adaptive_detail::max_abs(ek - eg); }
        double tau_error() const { return std::fabs(tk - tg); }
    };

    // False once the ray has spent its rules or a cancel was requested: open pieces are then accepted
    // with their estimates (conventions.h, kAdaptiveMaxRulesPerRay).
    bool may_refine() const { return rules_left_ > 0 && !cancel_requested(); }

    Rule evaluate(double a, double b) {
        namespace gk = gauss_kronrod;
        --rules_left_;
        const gk::Tables& g = gk::tables();
        const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
        double sigma[gk::kNodes];
        glm::dvec3 c[gk::kNodes];
        for (int i = 0; i < gk::kNodes; ++i) {
            medium_.sample(mid + half * g.x[std::size_t(i)], sigma[i], c[i]);
            colour_bound_ = std::max(colour_bound_, adaptive_detail::max_abs(c[i]));
        }
        Rule r;
        for (int i = 0; i < gk::kNodes; ++i) {
            r.tk += g.wk[std::size_t(i)] * sigma[i];
            if (sigma[i] == 0.0) continue;
            double tau_i = 0.0;
            for (int j = 0; j < gk::kNodes; ++j) tau_i += g.sk[std::size_t(i)][std::size_t(j)] * sigma[j];
            r.ek += (g.wk[std::size_t(i)] * sigma[i] * std::exp(-half * tau_i)) * c[i];
        }
        for (int q = 0; q < gk::kGaussNodes; ++q) {
            const int i = 2 * q + 1;
            r.tg += g.wg[std::size_t(q)] * sigma[i];
            if (sigma[i] == 0.0) continue;
            double tau_q = 0.0;
            for (int j = 0; j < gk::kGaussNodes; ++j) tau_q += g.sg[std::size_t(q)][std::size_t(j)] * sigma[2 * j + 1];
            r.eg += (g.wg[std::size_t(q)] * sigma[i] * std::exp(-half * tau_q)) * c[i];
        }
        r.tk *= half;
        r.tg *= half;
        r.ek *= half;
        r.eg *= half;
        return r;
    }

    // A candidate leaf [a, b]: its rule P and its halves' rules L, R, with the estimate of the pair
    //   e = |P - (L + R)| + |K15 - G7|_L + |K15 - G7|_R   (emission with R behind L:
    // E = E_L + exp(-Delta tau_L) E_R; and optical depth), times the safety factor. Comparing a rule
    // with its halves catches what both rules of one evaluation miss together (a narrow feature
    // between nodes, an unlocated kink).
    struct Candidate {
        double a, b;
        Rule L, R;
        glm::dvec3 E;
        double e_e, e_t;
        int depth;
        bool final;  // not split further: at rounding, or no double between a and b, or kAdaptiveMaxDepth
    };
    Candidate candidate(double a, double b, int depth, const Rule& P) {
        using adaptive_detail::max_abs;
        const double m = 0.5 * (a + b);
        Candidate c{a, b, P, Rule{}, P.ek, safety_ * P.em_error(), safety_ * P.tau_error(), depth, true};
        if (!(m > a && m < b) || depth >= conventions::kAdaptiveMaxDepth) return c;  // P alone (L = P, R = 0)
        c.L = evaluate(a, m);
        c.R = evaluate(m, b);
        c.E = c.L.ek + std::exp(-c.L.tk) * c.R.ek;
        c.e_e = safety_ * (max_abs(P.ek - c.E) + c.L.em_error() + c.R.em_error());
        c.e_t = safety_ * (std::fabs(P.tk - (c.L.tk + c.R.tk)) + c.L.tau_error() + c.R.tau_error());
        const double roundoff = conventions::kAdaptiveRoundoffRelative * (max_abs(c.E) + colour_bound_ * (c.L.tk + c.R.tk));
        c.final = c.e_e + colour_bound_ * c.e_t <= roundoff;
        return c;
    }

    // The piece [a, b] (globally adaptive, as QUADPACK's QAG, inside the piece): its candidates'
    // estimates add up, T(a) sum (e_E + K e_tau) against the piece's share of the tolerance,
    //   T(a) sum_i (e_E,i + K e_tau,i) <= tolerance (b - a) / (total length);
    // while it does not fit, the candidate with the largest estimate is split into its halves (each a
    // candidate with its own halves). A local test per candidate (its own share of the length) never
    // holds beside an integrable singularity of sigma (opacity reaching 1 at a point: the rule's error
    // on [t*, t* + d] is proportional to d, like the share), the sum does: the estimates there halve
    // with d. When the ray's rules are spent (or a cancel is requested) the open candidates are kept
    // with their estimates and the piece counts as unresolved (result()).
    void integrate_piece(double a, double b) {
        using adaptive_detail::max_abs;
        const double T0 = acc_.transmittance();
        const double budget = tolerance_ * (b - a) / total_;
        // The candidates live in a vector kept by the ray (cleared, its capacity reused): one allocation
        // per ray rather than several per piece; many threads allocating at once share the allocator.
        std::vector<Candidate>& open = open_;
        open.clear();
        open.push_back(candidate(a, b, 0, evaluate(a, b)));
        for (;;) {
            double sum = 0.0, worst = -1.0;
            std::size_t at = 0;
            for (std::size_t i = 0; i < open.size(); ++i) {
                const double e = open[i].e_e + colour_bound_ * open[i].e_t;
                sum += e;
                if (!open[i].final && e > worst) {
                    worst = e;
                    at = i;
                }
            }
            if (T0 * sum <= budget || worst < 0.0) break;
            if (!may_refine()) {  // unresolved: everything from here on is uncertain (see result())
                unresolved_T_ = std::max(unresolved_T_, T0);
                break;
            }
            const Candidate c = open[at];
            const double m = 0.5 * (c.a + c.b);
            open[at] = candidate(c.a, m, c.depth + 1, c.L);
            open.push_back(candidate(m, c.b, c.depth + 1, c.R));
        }
        std::sort(open.begin(), open.end(), [](const Candidate& x, const Candidate& y) { return x.a < y.a; });
        for (const Candidate& c : open) commit(acc_.transmittance(), c.E, c.L.tk, c.R.tk, c.e_e, c.e_t);
    }

    void commit(double T, const glm::dvec3& E, double dtau0, double dtau1, double e_e, double e_t) {
        const double e[3] = {E.r, E.g, E.b};
        acc_.add_emission(e, dtau0, dtau1);
        leaves_.push_back({T * E, T * e_e, e_t});
    }

    const Medium& medium_;
    double tolerance_, safety_, total_;
    // The pieces composite front to back with compensated colour sums (march/Accumulators.h).
    Accumulator acc_;
    double colour_bound_ = 1.0;  // K: the largest colour seen (at least 1), for the tau part of the budget
    std::vector<LeafRecord> leaves_;
    std::vector<Candidate> open_;  // integrate_piece's candidates (scratch)
    long rules_left_ = conventions::kAdaptiveMaxRulesPerRay;  // work bound of the ray
    double unresolved_T_ = 0.0;  // the transmittance in front of the first piece accepted unresolved
    bool opaque_ = false;
    glm::dvec3 opaque_colour_{0.0};
};

}  // namespace volref
