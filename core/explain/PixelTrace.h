// PixelTrace: one pixel of a prepared scene, sample by sample (`volref trace`, `volref explain ray`).
//
// The samples are recorded by the integrator's own loop (Integrator::integrate_traced,
// core/integrate/march/SampleRecorder.h), so the last sample's accumulated RGBA is the pixel that
// PreparedScene::render_pixel gives, bit for bit (and the rendered image's pixel, up to the SIMD
// path's documented rounding). Each sample is also located on the grid: the continuous index u of its
// position and the cell and local coordinates that reconstruction uses (VolumeSampler::locate on a
// Cartesian grid; on a beam-space grid the index of ShellGrid::continuous_index and the cell and
// fraction of ShellSampler's trilinear reconstruction, docs/shells.md section 3).
#pragma once
#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/march/SampleRecorder.h"
#include "geometry/RayIntervals.h"

namespace volref {

struct PreparedScene;

namespace explain {

struct GridLocation {
    glm::dvec3 index{0.0};               // continuous grid index u
    std::array<std::int64_t, 3> cell{};  // lower corner of the cell
    glm::dvec3 local{0.0};               // (p, q, r) in the cell
};

struct TracedSample {
    SampleRecord record;
    GridLocation grid;
    // where the sample lies, the same with empty-space skipping on or off: the interval
    // (index into PixelTrace::intervals: the last with t0 <= t) and the step from its entry,
    // segment = floor((t - t_entry) / h + kSegmentSlack) (kSegmentSlack = 1e-9, conventions section 4) (midpoints: the segment's index k; from the entry:
    // floor(first + k)). -1 for a sample before every interval.
    std::int64_t interval = -1, segment = -1;
};

struct PixelTrace {
    int x = 0, y = 0;
    Ray ray;
    std::vector<Interval> intervals;
    double step = 0.0;           // world units
    double unit_distance = 1.0;  // the classifier's opacity unit distance l
    Projection projection{};  // set from the scene
    CompositeOrder order = CompositeOrder::FrontToBack;
    bool has_gradient = false;   // the scene computes gradients (shading or classification)
    bool shaded = false;
    std::size_t lights = 0;
    bool skipping = false;       // empty-space skipping was on (skipped segments are not listed)
    bool slices = false;         // placement "slices": each sample's surface and its blend's rounding are listed
    std::vector<TracedSample> samples;
    PixelValue pixel;            // what the integrator returned
    std::string fault;           // why the mirrored program does not finish this ray (empty: it does)
};

// Throws volref::Error: a pixel outside the image ("--pixel: ..."), first-hit ("trace: first-hit is
// not supported yet").
PixelTrace trace_pixel(const PreparedScene& scene, int x, int y);

// The "X,Y" of --pixel, checked against the image: throws volref::Error naming --pixel.
std::array<int, 2> parse_pixel(const std::string& text, int width, int height);

// CSV: a header line, then one line per sample; columns that do not apply to the scene are left
// out, cells a sample did not compute are empty. trace_csv_header gives the header's names.
std::vector<std::string> trace_csv_header(const PixelTrace& trace);
void write_trace_csv(const PixelTrace& trace, std::ostream& out);
// JSON: the pixel, ray, intervals and every sample (docs/trace.md); non-finite numbers as strings.
std::string trace_json(const PixelTrace& trace, int indent = 2);

const char* projection_name(Projection p);

}  // namespace explain
}  // namespace volref
