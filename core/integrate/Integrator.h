// Integrator: turns one ray's intervals into one pixel. One implementation per projection
// (conventions section 6); they share the sample placement of Segments.h and the optical model of
// transfer/OpacityCorrection.h.
#pragma once
#include <limits>
#include <memory>
#include <vector>

#include <glm/vec4.hpp>

#include "core/camera/Ray.h"
#include "core/integrate/SamplePipeline.h"
#include "core/scene/Scene.h"
#include "geometry/RayIntervals.h"

namespace volref {

struct PixelValue {
    glm::dvec4 rgba{0.0};  // premultiplied
    double depth = std::numeric_limits<double>::infinity();  // first-hit: distance of the hit (Z)
};

// What every integrator reads: the sample pipeline, the step in world units, the render settings.
struct IntegrationContext {
    const SamplePipeline& pipeline;
    double step;  // world units, > 0
    const RenderSpec& render;
    double field(const Ray& ray, double t) const { return pipeline.value(ray, t); }
};

class Integrator {
public:
    explicit Integrator(const IntegrationContext& ctx) : ctx_(ctx) {}
    virtual ~Integrator() = default;
    // `intervals` are sorted and disjoint; an empty list gives the background (all zero, depth inf).
    virtual PixelValue integrate(const Ray& ray, const std::vector<Interval>& intervals) const = 0;
    // The extra channels this projection writes (e.g. "Z" for first-hit).
    virtual bool writes_depth() const { return false; }

protected:
    const IntegrationContext& ctx_;
};

std::unique_ptr<Integrator> make_integrator(const IntegrationContext& ctx);

}  // namespace volref
