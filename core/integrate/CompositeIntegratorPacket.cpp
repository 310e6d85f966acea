// CompositeIntegrator's SIMD side: when the scene allows the packet path (PacketComposite.h), and
// the hand-over of packets to it.
#include "core/integrate/CompositeIntegrator.h"
#include "transfer/TransferFunction.h"

namespace volref {

CompositeIntegrator::CompositeIntegrator(const IntegrationContext& ctx) : Integrator(ctx) {
    const SamplePipeline& p = ctx.pipeline;
    const auto* tf = dynamic_cast<const TransferFunction*>(&p.classifier());
    const VolumeSampler* sampler = p.cartesian_sampler();
    if (!tf || !sampler || tf->needs_gradient() || p.shaded() || p.preclassified() ||
        sampler->interpolation() != Interpolation::Trilinear || ctx.render.order != CompositeOrder::FrontToBack)
        return;
    const Volume& v = sampler->volume();
    PacketCompositeInputs in;
    in.voxels = v.values.data();
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
