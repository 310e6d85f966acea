// explain ray: the worked example of one whole pixel: the camera's ray, its intervals, the sample
// placement, every sample (the engine of `volref trace`: PixelTrace.h, recorded by the integrator's
// own loop) and the pixel.
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "core/explain/Explain.h"
#include "core/explain/PixelTrace.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/render/PreparedScene.h"

namespace volref::explain {

namespace {
std::vector<double> v3(const glm::dvec3& c) { return {c.x, c.y, c.z}; }
const char* camera_name(CameraSpec::Type t) {
    switch (t) {
        case CameraSpec::Type::Perspective: return "perspective";
        case CameraSpec::Type::Orthographic: return "orthographic";
        case CameraSpec::Type::Matrices: return "matrices";
        default: return "default (perspective, framing the bounds)";
    }
}
}  // namespace

Explanation ray(const PreparedScene& scene, int x, int y) {
    const PixelTrace t = trace_pixel(scene, x, y);
    const Scene& s = scene.scene;
    Explanation e;
    e.topic = "ray";
    Section& cam = e.section("camera to film (core/camera/Camera.h)");
    cam.notes.push_back(std::string("camera: ") + camera_name(s.camera.type));
    add(cam, "image", {double(s.image.width), double(s.image.height)}, "W, H");
    add(cam, "pixel", {double(x), double(y)}, "x right, y down from the top-left corner");
    add(cam, "film point", {x + 0.5, y + 0.5}, "the pixel's centre");
    const glm::dvec2 n = scene.camera->ndc(x + 0.5, y + 0.5);
    add(cam, "(nx, ny)", {n.x, n.y}, "(2 (x + 0.5) / W - 1, 1 - 2 (y + 0.5) / H)");
    add(cam, "origin", v3(t.ray.origin), "the eye (perspective) or a point of the eye's plane");
    add(cam, "direction", v3(t.ray.direction), "unit length");

    Section& iv = e.section("intervals in the bounds and domain (t >= 0)");
    iv.columns = {"t0", "t1", "length", "segments"};
    for (const Interval& i : t.intervals)
        iv.rows.push_back({i.t0, i.t1, i.length(), double(segment_count(i, t.step))});
    if (t.intervals.empty()) iv.notes.push_back("none: the ray misses the volume; the pixel is (0, 0, 0, 0)");
    Section& pl = e.section("sample placement (core/integrate/march/SamplePlacement.h)");
    add(pl, "h", t.step, "step in world units");
    add(pl, "l", t.unit_distance, "opacity unit distance");
    pl.notes.push_back("n = max(1, ceil(L / h - 1e-9)) segments per interval, sampled at their midpoints,");
    pl.notes.push_back("each weighted by its own length (the last one ends at t1)");
    if (t.skipping) pl.notes.push_back("empty-space skipping is on: segments in empty macrocells are not listed (opacity 0)");

    const bool composite = is_composite(t.projection);
    std::string title = std::string("samples (") + projection_name(t.projection);
    if (composite) title += t.order == CompositeOrder::FrontToBack ? ", front to back)" : ", back to front: far end first)";
    else title += ")";
    Section& sm = e.section(title);
    sm.columns = {"sample", "t", "x", "y", "z", "value"};
    if (t.has_gradient) sm.columns.push_back("|grad f|");
    const bool line = is_line_integral(t.projection);
    if (line) sm.columns.push_back("s(v)");
    else sm.columns.insert(sm.columns.end(), {"c_r", "c_g", "c_b", "a"});
    if (composite) sm.columns.insert(sm.columns.end(), {"alpha", "T_before", "T_after"});
    else sm.columns.push_back("running");
    sm.columns.insert(sm.columns.end(), {"acc_r", "acc_g", "acc_b", "acc_a"});
    for (const TracedSample& ts : t.samples) {
        const SampleRecord& r = ts.record;
        const SampleDetail& d = r.sample;
        std::vector<double> row{double(r.index), r.t, d.position.x, d.position.y, d.position.z, d.value};
        if (t.has_gradient) row.push_back(d.has_gradient ? glm::length(d.gradient) : NAN);
        if (line) row.push_back(r.coordinate);
        else row.insert(row.end(), {d.color.r, d.color.g, d.color.b, d.opacity});
        if (composite) row.insert(row.end(), {r.alpha, r.transmittance_before, r.transmittance_after});
        else row.push_back(r.running);
        row.insert(row.end(), {r.accumulated.r, r.accumulated.g, r.accumulated.b, r.accumulated.a});
        sm.rows.push_back(std::move(row));
    }
    if (t.has_gradient) sm.notes.push_back("|grad f| nan: not computed at that sample (not needed there)");
    if (composite && t.shaded) sm.notes.push_back("c: the shaded colour (volref trace lists every shading term)");
    if (composite) sm.notes.push_back("acc: premultiplied (C, A) after the sample");

    Section& px = e.section("pixel");
    add(px, "RGBA", {t.pixel.rgba.r, t.pixel.rgba.g, t.pixel.rgba.b, t.pixel.rgba.a}, "premultiplied; = the last sample's acc");
    if (t.pixel.fault) px.notes.push_back("fault: " + t.fault);
    return e;
}

}  // namespace volref::explain
