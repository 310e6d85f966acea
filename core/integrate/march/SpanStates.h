// The RayState layouts of the accumulators (march/RaySpan.h: resumable integration), each with its
// merge (a fresh part `back` behind `front`) and its pixel. One place per projection family, used by
// every integrator of that family (fixed step, packets, the several-volume mix, adaptive pieces).
#pragma once
#include <cmath>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/RaySpan.h"

namespace volref {

// Composite: v[0..7] FrontToBack<Scalar>'s state (optical depth and its compensation, colour and the
// colour's compensation), v[8] opaque (0 / 1).
namespace composite_state {

inline void save(const FrontToBack<Scalar>& acc, RayState& s) {
    bool opaque = false;
    acc.save(s.v, opaque);
    s.v[8] = opaque ? 1.0 : 0.0;
}
inline void load(FrontToBack<Scalar>& acc, const RayState& s) { acc.load(s.v, s.v[8] != 0.0); }

// A back-to-front part (its colour C, optical depth tau, opaque) as a state: C relative to the
// transmittance at its front, as FrontToBack's.
inline void save_part(const glm::dvec3& color, double tau, bool opaque, RayState& s) {
    s = RayState{};
    s.v[0] = tau;
    for (int i = 0; i < 3; ++i) s.v[2 + i] = color[i];
    s.v[8] = opaque ? 1.0 : 0.0;
    s.stopped = opaque ? 1.0 : 0.0;
}

// front over back: C = C_f + exp(-tau_f) C_b, tau = tau_f + tau_b (compensated), opaque as back.
inline void merge(RayState& front, const RayState& back) {
    if (front.stopped != 0.0) return;
    const double T = std::exp(-(front.v[0] + front.v[1]));
    for (int i = 0; i < 3; ++i) front.v[2 + i] += T * (back.v[2 + i] + back.v[5 + i]);
    compensated_add<Scalar>(front.v[0], front.v[1], back.v[0], true);
    front.v[1] += back.v[1];
    front.v[8] = back.v[8];
    front.stopped = back.stopped;
}

// The pixel (premultiplied C, A), as FrontToBack gives it.
inline glm::dvec4 rgba(const RayState& s) {
    FrontToBack<Scalar> acc;
    load(acc, s);
    return glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
}

}  // namespace composite_state

// The fast profile's composite (FrontToBack<SimdLanes<float>, Product>, packet/FastProfile.h): v[0] the
// transmittance T (a float), v[2..4] the colour (floats), v[8] opaque, v[9] 1 once the state holds a
// T (a fresh RayState, all zeros, stands for T = 1). Resumed in order, spans give the whole ray's
// floats bit for bit; merged, a part behind is put in double: C = C_f + T_f C_b, T = T_f T_b.
namespace product_state {

// State value k as the float lanes load it.
inline double load_value(const RayState& s, int k) { return k == 0 && s.v[9] == 0.0 ? 1.0 : s.v[k]; }

inline void merge(RayState& front, const RayState& back) {
    if (front.stopped != 0.0) return;
    const double Tf = load_value(front, 0), Tb = load_value(back, 0);
    for (int i = 0; i < 3; ++i) front.v[2 + i] = front.v[2 + i] + Tf * back.v[2 + i];
    front.v[0] = Tf * Tb;
    front.v[9] = 1.0;
    front.v[8] = back.v[8];
    front.stopped = back.stopped;
}

// The pixel as the float lanes give it: (C, A) with A = 1 where opaque, else 1 - T in float.
inline glm::dvec4 rgba(const RayState& s) {
    const double A = s.v[8] != 0.0 ? 1.0 : double(1.0f - float(load_value(s, 0)));
    return glm::dvec4(s.v[2], s.v[3], s.v[4], A);
}

}  // namespace product_state

// MIP / MinIP: v[0] the extremum, v[1] where, v[2] seen (0 / 1), v[3..6] the pixel there (classified by
// whoever holds the sample: the span that took it).
namespace extremum_state {

inline bool seen(const RayState& s) { return s.v[2] != 0.0; }
inline void save(double value, double where, const glm::dvec4& rgba, RayState& s) {
    s = RayState{};
    s.v[0] = value;
    s.v[1] = where;
    s.v[2] = 1.0;
    for (int i = 0; i < 4; ++i) s.v[3 + i] = rgba[i];
}
// The front's extremum unless the back's is strictly better (equal values: the first sample wins).
inline void merge(RayState& front, const RayState& back, bool maximum) {
    if (!seen(back)) return;
    if (!seen(front) || (maximum ? back.v[0] > front.v[0] : back.v[0] < front.v[0])) front = back;
}
inline glm::dvec4 rgba(const RayState& s) { return glm::dvec4(s.v[3], s.v[4], s.v[5], s.v[6]); }

}  // namespace extremum_state

// Average and x-ray: v[0..1] the line integral (compensated), v[2..3] the length (compensated), v[4] the
// adaptive integrator's error sum.
namespace line_state {

inline void save(const CompensatedSum& integral, const CompensatedSum& length, double error, RayState& s) {
    s = RayState{};
    s.v[0] = integral.sum();
    s.v[1] = integral.compensation();
    s.v[2] = length.sum();
    s.v[3] = length.compensation();
    s.v[4] = error;
}
inline CompensatedSum integral(const RayState& s) { return CompensatedSum(s.v[0], s.v[1]); }
inline CompensatedSum length(const RayState& s) { return CompensatedSum(s.v[2], s.v[3]); }
inline void merge(RayState& front, const RayState& back) {
    for (int k = 0; k < 4; k += 2) {
        compensated_add<Scalar>(front.v[k], front.v[k + 1], back.v[k], true);
        front.v[k + 1] += back.v[k + 1];
    }
    front.v[4] += back.v[4];
}

}  // namespace line_state

// First hit: v[0] hit (0 / 1), v[1] t of the hit, v[2..4] its colour; a hit stops the ray.
namespace hit_state {

inline bool hit(const RayState& s) { return s.v[0] != 0.0; }
inline void save(double t, const glm::dvec3& color, RayState& s) {
    s = RayState{};
    s.v[0] = 1.0;
    s.v[1] = t;
    for (int i = 0; i < 3; ++i) s.v[2 + i] = color[i];
    s.stopped = 1.0;
}
inline void merge(RayState& front, const RayState& back) {
    if (!hit(front)) front = back;
}

}  // namespace hit_state

}  // namespace volref
