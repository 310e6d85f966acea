// CompositeIntegrator's SIMD side: when the scene allows the packet path (PacketComposite.h), and
// what its packets run with beside the volume's description (PacketRun.h).
#include "core/integrate/fixed/CompositeIntegrator.h"

#include <algorithm>
#include <cmath>

#include "core/integrate/packet/FastProfile.h"

namespace volref {

CompositeIntegrator::CompositeIntegrator(const IntegrationContext& ctx)
    : OneLoopIntegrator(ctx), termination_(early_termination(ctx.render)) {
    const bool fast = ctx.lanes == IntegrationContext::Lanes::Float;
    packets_only_ = fast;
    // The spans resume in ray order where a ray can stop early (the termination the path applies).
    auto stops_early = [](const Termination& t) { return t.test_alpha_above || t.test_alpha_at_least || t.test_transmittance; };
    traits_.resumable = true;
    traits_.spans_in_order = stops_early(termination_);
    // Where the packet path does not apply the reference takes the scalar path; the fast profile has
    // no scalar path and says why (FastProfile.h).
    if (const char* reason = ctx.pipeline.view().packet_unavailable(true, ctx.render.order)) {
        if (fast) fast_profile_unavailable(reason);
        return;
    }
    PacketRun run;
    run.step = ctx.step;
    run.termination = fast ? fast_termination(termination_) : termination_;
    run.macrocells = ctx.macrocells;
    run.fast = fast;
    traits_.spans_in_order = stops_early(run.termination);
    packet_ = run;
}

CompositeIntegrator::~CompositeIntegrator() = default;

}  // namespace volref
