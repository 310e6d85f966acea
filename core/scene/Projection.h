// Projection: what a ray's samples become (render.projection; conventions sections 5 and 6), and the
// questions code outside the integrators asks of one. Which accumulator a projection feeds
// (core/integrate/march/Accumulators.h) is decided here once: the integrators' factories dispatch on
// the projection itself; everything else (set-up, skipping, tracing, volref-mpi, compare) asks
// accumulation() or one of the predicates below, so a new projection of an existing kind is one line
// here, one in SceneNames.h and its integrator.
#pragma once

namespace volref {

enum class Projection { Composite, Mip, Minip, Average, FirstHit, Xray };

enum class Accumulation {
    Composite,     // emission-absorption: colour and opacity, front to back or back to front
    Extremum,      // the largest (mip) or smallest (minip) value along the ray, and its depth
    LineIntegral,  // the mean (average) or the integral (xray) of the values along the ray
    FirstHit,      // the first crossing of render.isovalue, and its depth
};

constexpr Accumulation accumulation(Projection p) {
    switch (p) {
        case Projection::Composite: return Accumulation::Composite;
        case Projection::Mip:
        case Projection::Minip: return Accumulation::Extremum;
        case Projection::Average:
        case Projection::Xray: return Accumulation::LineIntegral;
        case Projection::FirstHit: return Accumulation::FirstHit;
    }
    return Accumulation::Composite;
}

constexpr bool is_composite(Projection p) { return accumulation(p) == Accumulation::Composite; }
constexpr bool is_extremum(Projection p) { return accumulation(p) == Accumulation::Extremum; }
constexpr bool is_line_integral(Projection p) { return accumulation(p) == Accumulation::LineIntegral; }
constexpr bool is_first_hit(Projection p) { return accumulation(p) == Accumulation::FirstHit; }
// Whether a volume's "shading" lights its samples: the composite's colours and the first hit's
// surface. The others accumulate values, not colours.
constexpr bool shades_samples(Projection p) { return is_composite(p) || is_first_hit(p); }
// An extremum's direction: mip keeps the largest value, minip the smallest.
constexpr bool takes_maximum(Projection p) { return p == Projection::Mip; }
// A line integral's normalisation: average divides by the length, xray multiplies by render.gain.
constexpr bool takes_mean(Projection p) { return p == Projection::Average; }

}  // namespace volref
