// CompositeIntegrator's SIMD side: when the scene allows the packet path (PacketComposite.h), and
// the hand-over of packets to it.
#include "core/integrate/CompositeIntegrator.h"

#include <algorithm>
#include <cmath>

#include "core/sample/GradientField.h"
#include "transfer/Shader.h"
#include "transfer/TransferFunction.h"

namespace volref {

CompositeIntegrator::CompositeIntegrator(const IntegrationContext& ctx) : Integrator(ctx) {
    const SamplePipeline& p = ctx.pipeline;
    const auto* tf = dynamic_cast<const TransferFunction*>(&p.classifier());
    const VolumeSampler* sampler = p.cartesian_sampler();
    if (!tf || !sampler || p.preclassified() || sampler->interpolation() != Interpolation::Trilinear ||
        ctx.render.order != CompositeOrder::FrontToBack)
        return;
    const Volume& v = sampler->volume();
    // Non-finite voxels: the scalar path, whose pipeline makes them transparent (docs/accuracy.md).
    if (!all_finite(v.values)) return;
    PacketCompositeInputs in;
    if (tf->needs_gradient() || p.shaded()) {
        const auto* field = dynamic_cast<const GradientField*>(p.gradient_source());
        if (!field) return;
        if (field->cached_component(0)) {
            in.gradient = PacketCompositeInputs::Gradient::Cached;
            for (int a = 0; a < 3; ++a) in.cached_gradient[a] = field->cached_component(a)->values.data<double>();
        } else if (field->scheme() == GradientSpec::Scheme::Central) {
            in.gradient = PacketCompositeInputs::Gradient::Central;
        } else if (field->scheme() == GradientSpec::Scheme::Forward) {
            in.gradient = PacketCompositeInputs::Gradient::Forward;
        } else {
            return;
        }
        for (int a = 0; a < 3; ++a) {
            in.spacing[a] = v.spacing[a];
            in.domain_lo[a] = v.domain_min()[a];
            in.domain_hi[a] = v.domain_max()[a];
        }
    }
    if (tf->needs_gradient()) {
        in.gradient_opacity_x = tf->gradient_opacity_function().xs().data();
        in.gradient_opacity_y = tf->gradient_opacity_function().ys().front().data();
        in.gradient_opacity_rows = int(tf->gradient_opacity_function().xs().size());
    }
    if (const Shader* shader = p.shader()) {
        const ShadingSpec& s = shader->spec();
        if (shader->lights().size() > std::size_t(PacketCompositeInputs::kMaxPacketLights)) return;
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
    in.voxels = v.values.raw();
    in.voxel_type = v.values.type();
    for (int a = 0; a < 3; ++a) {
        in.dims[a] = v.dims[a];
        in.origin[a] = v.origin[a];
        in.inv_spacing[a] = 1.0 / v.spacing[a];
    }
    in.normalized = tf->normalized();
    in.lo = tf->window()[0];
    in.inv_width = tf->inverse_window_width();
    // std::array<double, N> rows are contiguous doubles (N per row).
    in.color_x = tf->color_function().xs().data();
    in.color_y = tf->color_function().ys().front().data();
    in.color_rows = int(tf->color_function().xs().size());
    in.opacity_x = tf->opacity_function().xs().data();
    in.opacity_y = tf->opacity_function().ys().front().data();
    in.opacity_rows = int(tf->opacity_function().xs().size());
    in.unit_distance = tf->unit_distance();
    in.step = ctx.step;
    in.terminate = ctx.render.early_termination.has_value();
    in.threshold = ctx.render.early_termination.value_or(1.0);
    in.macrocells = ctx.macrocells;
    packet_ = in;
}

void CompositeIntegrator::integrate_packet(const Ray* rays, const std::vector<Interval>* intervals, PixelValue* out,
                                           int count) const {
    if (packet_)
        composite_packet(*packet_, rays, intervals, out, count);
    else
        Integrator::integrate_packet(rays, intervals, out, count);
}

}  // namespace volref
