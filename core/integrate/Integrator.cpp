#include "core/integrate/Integrator.h"

#include "core/Error.h"
#include "core/integrate/adaptive/AdaptiveIntegrator.h"
#include "core/integrate/fixed/CompositeIntegrator.h"
#include "core/integrate/fixed/ExtremumIntegrator.h"
#include "core/integrate/fixed/FirstHitIntegrator.h"
#include "core/integrate/fixed/LineIntegralIntegrator.h"

namespace volref {

void Integrator::not_resumable() {
    throw Error("render: this projection, integrator or profile cannot be integrated in spans (volref-mpi) yet");
}
void Integrator::not_traced() { throw Error("trace: this projection or integrator is not supported yet"); }

void Integrator::merge_spans(RayState&, const RayState&) const { not_resumable(); }
PixelValue Integrator::finish(const Ray&, const std::vector<Interval>&, const RayState&) const { not_resumable(); }

std::unique_ptr<Integrator> make_integrator(const IntegrationContext& ctx) {
    const RenderSpec& r = ctx.render;
    if (r.early_termination && (r.projection != Projection::Composite || r.order != CompositeOrder::FrontToBack))
        throw Error("render.early_termination: only the composite projection in front-to-back order terminates early");
    if (r.projection == Projection::FirstHit && !r.isovalue) throw Error("render.isovalue: required by projection first-hit");
    // Adaptive: one integrator for every projection but first-hit, which isolates its roots itself.
    if (r.integrator == IntegrationMethod::Adaptive && r.projection != Projection::FirstHit)
        return std::make_unique<AdaptiveIntegrator>(ctx);
    switch (r.projection) {
        case Projection::Composite: return std::make_unique<CompositeIntegrator>(ctx);
        case Projection::Mip: return std::make_unique<ExtremumIntegrator>(ctx, true);
        case Projection::Minip: return std::make_unique<ExtremumIntegrator>(ctx, false);
        case Projection::Average: return std::make_unique<LineIntegralIntegrator>(ctx, true);
        case Projection::Xray: return std::make_unique<LineIntegralIntegrator>(ctx, false);
        case Projection::FirstHit:
            if (!r.isovalue) throw Error("render.isovalue: required by projection first-hit");
            return std::make_unique<FirstHitIntegrator>(ctx);
    }
    throw Error("render.projection: unknown projection");
}

}  // namespace volref
