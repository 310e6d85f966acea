#include "core/integrate/ProfileIntegrator.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/integrate/Segments.h"
#include "transfer/OpacityCorrection.h"

namespace volref {

ProfileIntegrator::ProfileIntegrator(const IntegrationContext& ctx, const Profile& profile, const Volume& volume)
    : Integrator(ctx), p_(profile) {
    const std::string where = std::string("render.profile: \"") + p_.name + "\" ";
    const RenderSpec& r = ctx.render;
    if (r.projection == Projection::FirstHit) throw Error(where + "does not render the first-hit projection");
    if (r.integrator != IntegrationMethod::Fixed) throw Error(where + "needs render.integrator \"fixed\"");
    if (r.order != CompositeOrder::FrontToBack) throw Error(where + "composites front to back (render.order)");
    if (r.early_termination) throw Error(where + "has its own termination rule (remove render.early_termination)");
    if (!ctx.pipeline.cartesian_sampler()) throw Error(where + "needs a Cartesian grid (box or mesh bounds)");
    if (ctx.pipeline.preclassified()) throw Error(where + "classifies after interpolation (volume.classify \"post\")");
    if (ctx.pipeline.classifier().needs_gradient())
        throw Error(where + "needs a classification by value alone (no gradient opacity or Levoy classification)");
    domain_lo_ = volume.domain_min();
    domain_hi_ = volume.domain_max();
    offset_ = p_.gradient_offset_texture > 0.0 ? p_.gradient_offset_texture * (domain_hi_ - domain_lo_)
                                               : p_.gradient_offset * volume.spacing;
    const auto [vmin, vmax] = volume.value_range();
    lo_ = vmin;
    width_ = vmax - vmin;
    if (p_.table_entries > 1) {
        const int n = p_.table_entries;
        const Classifier& c = ctx.pipeline.classifier();
        const double l = c.unit_distance();
        table_.resize(std::size_t(n));
        table_alpha_.resize(std::size_t(n));
        for (int j = 0; j < n; ++j) {
            const double x = vmin + double(j) * (vmax - vmin) / double(n - 1);
            const Classified k = c.classify(x, 0.0);
            table_[std::size_t(j)] = glm::dvec4(k.color, k.opacity);
            // VTK corrects the table entries (not the interpolated opacity) for the sample distance.
            table_alpha_[std::size_t(j)] = alpha(k.opacity, ctx.step);
            (void)l;
        }
    }
}

double ProfileIntegrator::alpha(double a, double d) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    a = std::clamp(a, 0.0, 1.0);
    switch (p_.correction) {
        case Profile::Correction::Power: return a > p_.correction_floor ? opacity_for_length(a, d, l) : a;
        case Profile::Correction::None: return a;
        case Profile::Correction::Extinction: return -std::expm1(-a * d * p_.density_scale);
    }
    return a;
}

// A texture read clamps to the edge: positions past the domain read its boundary.
double ProfileIntegrator::value(const glm::dvec3& x) const {
    return ctx_.pipeline.sampler().value(glm::clamp(x, domain_lo_, domain_hi_));
}

ProfileIntegrator::Lookup ProfileIntegrator::lookup(double v, double d) const {
    Lookup out;
    if (table_.empty()) {
        const Classified k = ctx_.pipeline.classifier().classify(v, 0.0);
        out.color = k.color;
        out.opacity = k.opacity;
        out.alpha = alpha(k.opacity, d);
        return out;
    }
    // GL_LINEAR over N texels with CLAMP_TO_EDGE: texel position s N - 0.5.
    const int n = p_.table_entries;
    const double pos = std::clamp(normalised(v) * double(n) - 0.5, 0.0, double(n - 1));
    const int i = std::min(int(pos), n - 2);
    const double w = pos - double(i);
    const glm::dvec4 e = table_[std::size_t(i)] + w * (table_[std::size_t(i) + 1] - table_[std::size_t(i)]);
    out.color = glm::dvec3(e);
    out.opacity = e.a;
    out.alpha = table_alpha_[std::size_t(i)] + w * (table_alpha_[std::size_t(i) + 1] - table_alpha_[std::size_t(i)]);
    return out;
}

glm::dvec3 ProfileIntegrator::gradient(const glm::dvec3& x) const {
    glm::dvec3 g(0.0);
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 e(0.0);
        e[a] = offset_[a];
        g[a] = p_.forward_gradient ? (value(x + e) - value(x)) / offset_[a]
                                   : (value(x + e) - value(x - e)) / (2.0 * offset_[a]);
    }
    return g;
}

template <class Fn>
void ProfileIntegrator::for_each_sample(const std::vector<Interval>& intervals, Fn&& fn) const {
    const double h = ctx_.step;
    if (p_.placement == Profile::Placement::Midpoints) {
        for_each_segment(intervals, h, [&](const Segment& s) { return fn(s.midpoint(), s.length()); });
        return;
    }
    for (const Interval& iv : intervals) {
        const double n = std::max(1.0, std::floor(iv.length() / h + 1.0 - p_.first));
        for (double k = 0.0; k < n; k += 1.0)
            if (!fn(iv.t0 + (p_.first + k) * h, h)) return;
    }
}

PixelValue ProfileIntegrator::integrate(const Ray& ray, const std::vector<Interval>& intervals) const {
    switch (ctx_.render.projection) {
        case Projection::Composite: return composite(ray, intervals);
        case Projection::Mip: return extremum(ray, intervals, true);
        case Projection::Minip: return extremum(ray, intervals, false);
        case Projection::Average: return line_integral(ray, intervals, true);
        case Projection::Xray: return line_integral(ray, intervals, false);
        case Projection::FirstHit: break;
    }
    return {};
}

PixelValue ProfileIntegrator::composite(const Ray& ray, const std::vector<Interval>& intervals) const {
    glm::dvec3 C(0.0);
    double A = 0.0;
    const Shader* shader = ctx_.pipeline.shader();
    for_each_sample(intervals, [&](double t, double d) {
        const glm::dvec3 x = ray.at(t);
        const double v = value(x);
        if (!std::isfinite(v)) return true;
        const Lookup k = lookup(v, d);
        if (!(k.alpha > 0.0)) return true;
        glm::dvec3 c = k.color;
        if (shader) {
            const glm::dvec3 g = gradient(x);
            c = shader->shade(c, p_.normal_along_gradient ? -g : g, -ray.direction, t);
            if (p_.clamp_shaded) c = glm::clamp(c, 0.0, 1.0);
        }
        C += (1.0 - A) * k.alpha * c;
        A += (1.0 - A) * k.alpha;
        return !(A > p_.terminate_above || A >= p_.terminate_at);
    });
    PixelValue out;
    out.rgba = glm::dvec4(C, A);
    return out;
}

PixelValue ProfileIntegrator::extremum(const Ray& ray, const std::vector<Interval>& intervals, bool maximum) const {
    bool any = false;
    double best = 0.0;
    for_each_sample(intervals, [&](double t, double) {
        const double v = value(ray.at(t));
        if (std::isfinite(v) && (!any || (maximum ? v > best : v < best))) best = v;
        any = any || std::isfinite(v);
        return true;
    });
    PixelValue out;
    if (any) {
        const Lookup k = lookup(best, ctx_.step);
        out.rgba = glm::dvec4(k.opacity * k.color, k.opacity);
    }
    return out;
}

PixelValue ProfileIntegrator::line_integral(const Ray& ray, const std::vector<Interval>& intervals, bool mean) const {
    double sum = 0.0, length = 0.0;
    const Classifier& c = ctx_.pipeline.classifier();
    for_each_sample(intervals, [&](double t, double d) {
        const double v = value(ray.at(t));
        if (!std::isfinite(v)) return true;
        if (mean && p_.average_opacity_weighted) {
            sum += lookup(v, d).opacity * normalised(v);
            length += 1.0;
        } else {
            sum += c.coordinate(v) * d;
            length += d;
        }
        return true;
    });
    PixelValue out;
    if (intervals.empty()) return out;
    const double g = mean ? (length > 0.0 ? sum / length : 0.0) : ctx_.render.gain * sum;
    out.rgba = glm::dvec4(g, g, g, 1.0);
    return out;
}

}  // namespace volref
