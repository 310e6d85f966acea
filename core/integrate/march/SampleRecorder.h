// SampleRecorder: an observer of one ray's integration, sample by sample (`volref trace`,
// `volref explain ray`, `volref explain composite`).
//
// Integrator::integrate_traced runs the very loop that Integrator::integrate runs (the same
// template instantiated with a recorder), so the recorded samples are the rendered pixel's samples
// and the last row's accumulated value is the pixel. Rows come in the order the loop visits them:
// front to back, or from the far end for back-to-front compositing. Segments that empty-space
// skipping passes over are not visited, so they are not recorded.
//
// Per sample (segment [t0, t1], midpoint t, length d = t1 - t0):
//   value, gradient (when the scene computes one), classified colour c and opacity a (per unit
//   distance l), shaded colour and the shading terms (when shaded);
//   composite: tau_k = -(d / l) log1p(-a), alpha_k = -expm1(-tau_k) (1 for a = 1);
//     front to back: T_before = exp(-tau), T_after = exp(-(tau + tau_k)) (tau: the compensated sum of
//       the tau_j in front), accumulated C += T_before alpha_k c_k, A = 1 - T_after;
//     back to front: T_before and T_after are the transmittance of the part already composited
//       (behind this sample), before and after it: T_after = exp(-(tau + tau_k)), C = alpha_k c_k +
//       (1 - alpha_k) C, A = 1 - T_after;
//     a sample with a >= 1 makes T_after = 0 and A = 1; a sample with a <= 0 changes nothing;
//   mip / minip: `running` is the extremum so far, `accumulated` the pixel it gives ((a c, a) of the
//     classification at the extremum);
//   average / xray: `running` is I / L or gain I so far, `accumulated` (g, g, g, 1).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "transfer/Shader.h"

namespace volref {

// What the sample pipeline computed at one sample point (SamplePipeline::sample_detailed).
struct SampleDetail {
    glm::dvec3 position{0.0};
    double value = 0.0;
    bool has_gradient = false;          // the pipeline computed grad f at this sample
    glm::dvec3 gradient{0.0};           // world units
    bool classified = false;            // the classification was evaluated
    glm::dvec3 classified_color{0.0};   // not premultiplied
    double opacity = 0.0;               // per unit distance (0 for a non-finite value or colour)
    bool shaded = false;                // the shader ran (shaded scene, opacity > 0)
    ShadeTerms shading;                 // valid when shaded
    glm::dvec3 color{0.0};              // the colour the integrator used (shaded or classified)
};

struct SampleRecord {
    std::int64_t index = 0;             // 0, 1, ... in the order visited
    double t0 = 0.0, t1 = 0.0;          // the segment
    double t = 0.0;                     // its midpoint, where the sample is taken
    double length = 0.0;                // t1 - t0
    SampleDetail sample;
    // Composite only.
    bool composited = false;
    double tau = 0.0;                   // the segment's optical depth
    double alpha = 0.0;                 // corrected opacity over the segment
    double transmittance_before = 1.0, transmittance_after = 1.0;
    // mip/minip: the extremum so far; average/xray: the value so far; composite: unused (0).
    double running = 0.0;
    // average/xray: s(v), the transfer function's coordinate of the value (what is integrated).
    double coordinate = 0.0;
    glm::dvec4 accumulated{0.0};        // premultiplied RGBA after this sample
    // Placement "slices": the sampling surface k the sample lies on (0 the farthest); -1 otherwise.
    // `accumulated` is then the frame buffer as it holds the pixel after this fragment's blend.
    std::int64_t surface = -1;
    glm::dvec4 blend_exact{0.0};  // slices: the blend's result before the frame buffer stored it
};

class SampleRecorder {
public:
    virtual ~SampleRecorder() = default;
    virtual void record(const SampleRecord& r) = 0;
};

// Keeps every record.
class SampleList final : public SampleRecorder {
public:
    void record(const SampleRecord& r) override { rows.push_back(r); }
    std::vector<SampleRecord> rows;
};

// The integrators' loops are templates over one of these two policies: NoRecording compiles to the
// plain loop (Integrator::integrate), Recording adds the records (Integrator::integrate_traced).
struct NoRecording {
    static constexpr bool kOn = false;
};
struct Recording {
    static constexpr bool kOn = true;
    SampleRecorder& recorder;
    std::int64_t next = 0;
    // Starts the record of segment [t0, t1] (index, segment, midpoint, length).
    void begin(SampleRecord& r, double t0, double t1) {
        r.index = next++;
        r.t0 = t0;
        r.t1 = t1;
        r.t = 0.5 * (t0 + t1);
        r.length = t1 - t0;
    }
};

}  // namespace volref
