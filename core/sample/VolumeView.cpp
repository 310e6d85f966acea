#include "core/sample/VolumeView.h"

#include "core/sample/GradientField.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/VolumeSampler.h"
#include "transfer/Shader.h"
#include "transfer/TransferFunction.h"

namespace volref {

GridView GridView::of(const Volume& v) {
    GridView g;
    g.voxels = v.values.raw();
    g.voxel_type = v.values.type();
    for (int a = 0; a < 3; ++a) {
        g.dims[a] = v.dims[a];
        g.origin[a] = v.origin[a];
        g.inv_spacing[a] = 1.0 / v.spacing[a];
    }
    return g;
}

const char* VolumeView::packet_unavailable(bool composite, CompositeOrder order) const {
    if (composite && !transfer_function) return "this volume is classified otherwise";
    if (!cartesian) return "this volume is not on a Cartesian grid";
    if (composite && preclassified) return "this volume is pre-classified";
    if (interpolation != Interpolation::Trilinear) return "this volume is not trilinear";
    if (composite && order != CompositeOrder::FrontToBack) return "this scene composites back to front";
    if (!finite_voxels()) return "this volume has non-finite voxels";
    return composite ? composite_unavailable : nullptr;
}

bool VolumeView::finite_voxels() const {
    if (finite_ < 0) finite_ = all_finite(volume->values) ? 1 : 0;
    return finite_ == 1;
}

VolumeView describe_volume(const Volume& volume, const VolumeSampler* cartesian, const ShellGrid* shell_grid,
                           const TransferFunction* tf, const GradientField* grid_gradient, const Shader* shader,
                           bool preclassified) {
    VolumeView v;
    v.volume = &volume;
    v.cartesian = cartesian;
    v.shell_grid = shell_grid;
    v.transfer_function = tf;
    v.grid_gradient = grid_gradient;
    v.shader = shader;
    v.preclassified = preclassified;
    if (cartesian) {
        v.interpolation = cartesian->interpolation();
        v.grid = GridView::of(volume);
        v.grid_float = v.grid;
    }
    if (!tf || !cartesian) return v;
    // The gradient, when shading or gradient-magnitude opacity reads it: the grid's scheme.
    if (tf->needs_gradient() || shader) {
        if (!grid_gradient) {
            v.composite_unavailable = "this volume's gradient is not a grid's";
        } else if (grid_gradient->cached_component(0)) {
            v.gradient = VolumeView::Gradient::Cached;
            for (int a = 0; a < 3; ++a) v.rows.cached_gradient[a] = grid_gradient->cached_component(a)->values.data<double>();
        } else if (grid_gradient->scheme() == GradientSpec::Scheme::Central) {
            v.gradient = VolumeView::Gradient::Central;
        } else if (grid_gradient->scheme() == GradientSpec::Scheme::Forward) {
            v.gradient = VolumeView::Gradient::Forward;
        } else {
            v.composite_unavailable = "this volume's gradient scheme is not central or forward differences";
        }
        for (int a = 0; a < 3; ++a) {
            v.spacing[a] = volume.spacing[a];
            v.domain_lo[a] = volume.domain_min()[a];
            v.domain_hi[a] = volume.domain_max()[a];
        }
    }
    if (tf->needs_gradient()) {
        v.rows.gradient_opacity_x = tf->gradient_opacity_function().xs().data();
        v.rows.gradient_opacity_y = tf->gradient_opacity_function().ys().front().data();
        v.gradient_opacity_rows = int(tf->gradient_opacity_function().xs().size());
    }
    if (shader) {
        const ShadingSpec& s = shader->spec();
        if (shader->lights().size() > std::size_t(VolumeView::kMaxPacketLights)) {
            if (!v.composite_unavailable) v.composite_unavailable = "this scene has more than 8 lights";
        } else {
            v.shaded = true;
            v.phong = s.model == ShadingSpec::Model::Phong;
            v.two_sided = s.two_sided;
            v.ka = s.ka;
            v.kd = s.kd;
            v.ks = s.ks;
            v.n = s.n;
            v.kc = s.kc;
            v.kl = s.kl;
            v.zero_gradient_tolerance = shader->zero_gradient_tolerance();
            for (const LightSpec& light : shader->lights()) {
                VolumeView::Light& l = v.lights[v.light_count++];
                l.headlight = light.type == LightSpec::Type::Headlight;
                for (int c = 0; c < 3; ++c) {
                    l.direction[c] = light.direction[c];
                    l.color[c] = light.color[c];
                }
            }
        }
    }
    v.normalized = tf->normalized();
    v.lo = tf->window()[0];
    v.inv_width = tf->inverse_window_width();
    // std::array<double, N> rows are contiguous doubles (N per row).
    v.rows.color_x = tf->color_function().xs().data();
    v.rows.color_y = tf->color_function().ys().front().data();
    v.color_rows = int(tf->color_function().xs().size());
    v.rows.opacity_x = tf->opacity_function().xs().data();
    v.rows.opacity_y = tf->opacity_function().ys().front().data();
    v.opacity_rows = int(tf->opacity_function().xs().size());
    v.unit_distance = tf->unit_distance();
    return v;
}

void describe_skipping(VolumeView& view, const MacrocellGrid& macrocells, VolumeViewStore& store) {
    store.skip_radius = macrocells.octant_radii();
    view.skip_radius = store.skip_radius.data();
}

}  // namespace volref
