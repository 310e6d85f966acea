#include "core/integrate/Integrator.h"

#include "core/Error.h"
#include "core/integrate/adaptive/AdaptiveIntegrator.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/fixed/ExtremumIntegrator.h"
#include "core/integrate/fixed/FirstHitIntegrator.h"
#include "core/integrate/fixed/LineIntegralIntegrator.h"
#include "core/integrate/packet/FastProfile.h"

namespace volref {

void Integrator::not_resumable() {
    throw Error("render: this projection, integrator or profile cannot be integrated in spans (volref-mpi) yet");
}
void Integrator::not_traced() { throw Error("trace: this projection or integrator is not supported yet"); }
void Integrator::packets_not_traced() { fast_profile_not_traced(); }

void Integrator::merge_spans(RayState&, const RayState&) const { not_resumable(); }
PixelValue Integrator::finish(const Ray&, const std::vector<Interval>&, const RayState&) const { not_resumable(); }

std::unique_ptr<Integrator> make_integrator(const IntegrationContext& ctx) {
    const RenderSpec& r = ctx.render;
    if (r.early_termination && (!is_composite(r.projection) || r.order != CompositeOrder::FrontToBack))
        throw Error("render.early_termination: only the composite projection in front-to-back order terminates early");
    if (is_first_hit(r.projection) && !r.isovalue) throw Error("render.isovalue: required by projection first-hit");
    // Adaptive: one integrator for every projection but first-hit, which isolates its roots itself.
    if (r.integrator == IntegrationMethod::Adaptive && !is_first_hit(r.projection))
        return std::make_unique<AdaptiveIntegrator>(ctx);
    const Projection p = r.projection;
    switch (accumulation(p)) {
        case Accumulation::Composite: return std::make_unique<CompositeIntegrator>(ctx);
        case Accumulation::Extremum: return std::make_unique<ExtremumIntegrator>(ctx, takes_maximum(p));
        case Accumulation::LineIntegral: return std::make_unique<LineIntegralIntegrator>(ctx, takes_mean(p));
        case Accumulation::FirstHit: return std::make_unique<FirstHitIntegrator>(ctx);
    }
    throw Error("render.projection: unknown projection");
}

}  // namespace volref
