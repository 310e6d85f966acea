// CompositeIntegrator's SIMD side: when the scene allows the packet path (PacketComposite.h), and
// the hand-over of packets to it.
#include "core/integrate/fixed/CompositeIntegrator.h"

#include <algorithm>
#include <cmath>

#include "core/integrate/packet/FastProfile.h"
#include "core/integrate/packet/PacketGrid.h"
#include "core/sample/GradientField.h"
#include "core/sample/MacrocellGrid.h"
#include "transfer/Shader.h"
#include "transfer/TransferFunction.h"

namespace volref {

CompositeIntegrator::CompositeIntegrator(const IntegrationContext& ctx)
    : Integrator(ctx), termination_(early_termination(ctx.render)) {
    const SamplePipeline& p = ctx.pipeline;
    const bool fast = ctx.lanes == IntegrationContext::Lanes::Float;
    packets_only_ = fast;
    // The spans resume in ray order where a ray can stop early (the termination the path applies).
    auto stops_early = [](const Termination& t) { return t.test_alpha_above || t.test_alpha_at_least || t.test_transmittance; };
    traits_.resumable = true;
    traits_.spans_in_order = stops_early(termination_);
    // Where the packet path does not apply the reference takes the scalar path; the fast profile has
    // no scalar path and says why (FastProfile.h).
    auto unavailable = [&](const char* reason) {
        if (fast) fast_profile_unavailable(reason);
    };
    if (const char* reason = packet_path_unavailable(p, true, ctx.render.order)) {
        unavailable(reason);
        return;
    }
    const TransferFunction* tf = p.stages().transfer_function;
    const Volume& v = p.cartesian_sampler()->volume();
    PacketCompositeInputs in;
    const Volume* cached[3] = {nullptr, nullptr, nullptr};
    if (tf->needs_gradient() || p.shaded()) {
        const GradientField* field = p.stages().grid_gradient;
        if (!field) {
            unavailable("this volume's gradient is not a grid's");
            return;
        }
        if (field->cached_component(0)) {
            in.gradient = PacketCompositeInputs::Gradient::Cached;
            for (int a = 0; a < 3; ++a) {
                cached[a] = field->cached_component(a);
                in.tables_double.cached_gradient[a] = cached[a]->values.data<double>();
            }
        } else if (field->scheme() == GradientSpec::Scheme::Central) {
            in.gradient = PacketCompositeInputs::Gradient::Central;
        } else if (field->scheme() == GradientSpec::Scheme::Forward) {
            in.gradient = PacketCompositeInputs::Gradient::Forward;
        } else {
            unavailable("this volume's gradient scheme is not central or forward differences");
            return;
        }
        for (int a = 0; a < 3; ++a) {
            in.spacing[a] = v.spacing[a];
            in.domain_lo[a] = v.domain_min()[a];
            in.domain_hi[a] = v.domain_max()[a];
        }
    }
    if (tf->needs_gradient()) {
        in.tables_double.gradient_opacity_x = tf->gradient_opacity_function().xs().data();
        in.tables_double.gradient_opacity_y = tf->gradient_opacity_function().ys().front().data();
        in.gradient_opacity_rows = int(tf->gradient_opacity_function().xs().size());
    }
    if (const Shader* shader = p.shader()) {
        const ShadingSpec& s = shader->spec();
        if (shader->lights().size() > std::size_t(PacketCompositeInputs::kMaxPacketLights)) {
            unavailable("this scene has more than 8 lights");
            return;
        }
        in.shaded = true;
        in.phong = s.model == ShadingSpec::Model::Phong;
        in.two_sided = s.two_sided;
        in.ka = s.ka;
        in.kd = s.kd;
        in.ks = s.ks;
        in.n = s.n;
        in.kc = s.kc;
        in.kl = s.kl;
        in.zero_gradient_tolerance = shader->zero_gradient_tolerance();
        for (const LightSpec& light : shader->lights()) {
            PacketCompositeInputs::Light& l = in.lights[in.light_count++];
            l.headlight = light.type == LightSpec::Type::Headlight;
            for (int c = 0; c < 3; ++c) {
                l.direction[c] = light.direction[c];
                l.color[c] = light.color[c];
            }
        }
    }
    in.grid = PacketGrid::of(v);
    in.normalized = tf->normalized();
    in.lo = tf->window()[0];
    in.inv_width = tf->inverse_window_width();
    // std::array<double, N> rows are contiguous doubles (N per row).
    in.tables_double.color_x = tf->color_function().xs().data();
    in.tables_double.color_y = tf->color_function().ys().front().data();
    in.color_rows = int(tf->color_function().xs().size());
    in.tables_double.opacity_x = tf->opacity_function().xs().data();
    in.tables_double.opacity_y = tf->opacity_function().ys().front().data();
    in.opacity_rows = int(tf->opacity_function().xs().size());
    in.unit_distance = tf->unit_distance();
    in.step = ctx.step;
    in.termination = early_termination(ctx.render);
    in.macrocells = ctx.macrocells;
    if (in.macrocells) {  // skipping decided on the lanes (PacketKernels-inl.h, VectorSkip)
        // Per octant of directions and macrocell: the distance ahead, + where it is empty, - where not.
        skip_radius_ = in.macrocells->octant_radii();
        in.skip_radius = skip_radius_.data();
    }
    if (fast) {
        fast_copies_ = std::make_unique<FloatCopies>();
        make_fast(in, v, cached, *fast_copies_);
        if (ctx.render.profile_options.preintegration > 0)
            make_preintegrated(in, *tf, v, ctx.render.profile_options.preintegration, *fast_copies_);
    }
    traits_.spans_in_order = stops_early(in.termination);
    packet_ = in;
}

CompositeIntegrator::~CompositeIntegrator() = default;

}  // namespace volref
