#include "core/integrate/profiles/ProfileIntegrator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/integrate/march/Accumulators.h"
#include "geometry/ShellCoordinates.h"
#include "transfer/OpacityCorrection.h"

namespace volref {

void check_profile_applies(const Profile& p, const SamplePipeline& pipeline, const RenderSpec& r) {
    const std::string where = std::string("render.profile: \"") + p.name + "\" ";
    if (r.projection == Projection::FirstHit) throw Error(where + "does not render the first-hit projection");
    if (r.integrator != IntegrationMethod::Fixed) throw Error(where + "needs render.integrator \"fixed\"");
    if (r.order != CompositeOrder::FrontToBack)
        throw Error(where + "composites in its own order (remove render.order \"back-to-front\")");
    if (r.early_termination) throw Error(where + "has its own termination rule (remove render.early_termination)");
    if (!pipeline.cartesian_sampler() && p.grids == Profile::Grids::Cartesian)
        throw Error(where + "needs a Cartesian grid (box or mesh bounds)");
    if (p.grids == Profile::Grids::CartesianAndShells && pipeline.shaded() && r.projection == Projection::Composite)
        throw Error(where + "does not shade (remove volume.shading)");
    if (pipeline.preclassified()) throw Error(where + "classifies after interpolation (volume.classify \"post\")");
    if (pipeline.classifier().needs_gradient())
        throw Error(where + "needs a classification by value alone (no gradient opacity or Levoy classification)");
}

ProfileIntegrator::ProfileIntegrator(const IntegrationContext& ctx, const Profile& profile, const Volume& volume)
    : OneLoopIntegrator(ctx), p_(profile) {
    check_profile_applies(p_, ctx.pipeline, ctx.render);
    if (p_.renderer != Profile::Renderer::RayCaster)
        throw Error(std::string("render.profile: \"") + p_.name + "\" is an image-space renderer, not a ray integrator");
    const VolumeSampler* cartesian = ctx.pipeline.cartesian_sampler();
    const double inf = std::numeric_limits<double>::infinity();
    domain_lo_ = cartesian ? volume.domain_min() : glm::dvec3(-inf);  // shells: the intervals stay inside
    domain_hi_ = cartesian ? volume.domain_max() : glm::dvec3(inf);
    step_ = ctx.step;
    if (p_.seed_shell_reads && !cartesian) {
        shell_ = ctx.pipeline.stages().shell_grid;
        volume_ = &volume;
        if (!shell_) throw Error(std::string("render.profile: \"") + p_.name + "\" needs the shell's grid");
    }
    if (p_.voxel_length == Profile::VoxelLength::ExtentOverSamples && ctx.render.step_units == StepUnits::Voxel) {
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (cartesian ? volume.spacing[a] < volume.spacing[axis] : volume.dims[a] > volume.dims[axis]) axis = a;
        const double n = double(volume.dims[std::size_t(axis)]);
        if (n > 1.0) step_ = ctx.step * (n - 1.0) / n;
    }
    offset_ = p_.gradient_offset_texture > 0.0 ? p_.gradient_offset_texture * (domain_hi_ - domain_lo_)
                                               : p_.gradient_offset * volume.spacing;
    const auto [vmin, vmax] = volume.value_range();
    lo_ = vmin;
    width_ = vmax - vmin;
    if (p_.table_entries > 1) {
        const int n = p_.table_entries;
        const Classifier& c = ctx.pipeline.classifier();
        table_.resize(std::size_t(n));
        table_alpha_.resize(std::size_t(n));
        for (int j = 0; j < n; ++j) {
            const double x = vmin + double(j) * (vmax - vmin) / double(n - 1);
            const Classified k = c.classify(x, 0.0);
            table_[std::size_t(j)] = glm::dvec4(k.color, k.opacity);
            // VTK corrects the table entries (not the interpolated opacity) for the sample distance.
            table_alpha_[std::size_t(j)] = alpha(k.opacity, step_);
        }
    }
}

ProfileIntegrator::~ProfileIntegrator() = default;

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
    if (shell_) return seed_shell_value(x);
    return ctx_.pipeline.sampler().value(glm::clamp(x, domain_lo_, domain_hi_));
}

// Seed 001's interpolateCyl / interpolateSpher with tex3D (Profile::seed_shell_reads).
double ProfileIntegrator::seed_shell_value(const glm::dvec3& x) const {
    const glm::dvec3 c = shell_->shell_coordinates(x);
    glm::dvec3 u;
    std::array<std::int64_t, 3> i0{}, i1{};
    glm::dvec3 w;
    for (int a = 0; a < 3; ++a) {
        const ShellAxis& ax = shell_->axis(a);
        const double n = double(ax.n);
        double rel = c[shell_->coordinate_of_axis(a)] - ax.lo;
        if (ax.angular) rel = std::fmod(std::fmod(rel, 360.0) + 360.0, 360.0);  // atan2 + 2 pi: [0, 360) from lo
        const double tex = rel / ((ax.hi - ax.lo) / n);
        if (!(tex >= 0.0 && tex <= n - 1.0)) return lo_;  // outVal (0: the data minimum, s = 0)
        u[a] = std::clamp(tex - 0.5, 0.0, n - 1.0);       // texel i centred at i + 0.5, clamped
        i0[std::size_t(a)] = ax.n > 1 ? std::min(std::int64_t(std::floor(u[a])), ax.n - 2) : 0;
        i1[std::size_t(a)] = ax.n > 1 ? i0[std::size_t(a)] + 1 : 0;
        w[a] = ax.n > 1 ? u[a] - double(i0[std::size_t(a)]) : 0.0;
    }
    const Volume& v = *volume_;
    auto at = [&](int bx, int by, int bz) {
        return v.at(bx ? i1[0] : i0[0], by ? i1[1] : i0[1], bz ? i1[2] : i0[2]);
    };
    const double x00 = at(0, 0, 0) + w.x * (at(1, 0, 0) - at(0, 0, 0));
    const double x10 = at(0, 1, 0) + w.x * (at(1, 1, 0) - at(0, 1, 0));
    const double x01 = at(0, 0, 1) + w.x * (at(1, 0, 1) - at(0, 0, 1));
    const double x11 = at(0, 1, 1) + w.x * (at(1, 1, 1) - at(0, 1, 1));
    const double y0 = x00 + w.y * (x10 - x00), y1 = x01 + w.y * (x11 - x01);
    return y0 + w.z * (y1 - y0);
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
    const double u = p_.table_coordinate == Profile::TableCoordinate::DataRangeTimesTransferScale ? std::clamp(normalised(v) * ctx_.render.profile_options.transfer_scale, 0.0, 1.0)
                                     : normalised(v);
    const double pos = std::clamp(u * double(n) - 0.5, 0.0, double(n - 1));
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
    const double h = step_;
    if (p_.placement == Profile::Placement::Midpoints) {
        for_each_segment(intervals, h, [&](const Segment& s) { return fn(s.midpoint(), s.length()); });
        return;
    }
    if (p_.placement == Profile::Placement::FromExit) {  // seed 001: s = outAbs, outAbs - h, ... >= inAbs
        if (intervals.empty()) return;
        Interval span = intervals.front();
        span.t1 = intervals.back().t1;
        const double n = from_entry_count(span, h, 0.0);
        for (double k = 0.0; k < n; k += 1.0)
            if (!fn(span.t1 - k * h, h)) return;
        return;
    }
    for (const Interval& iv : intervals) {
        const double n = from_entry_count(iv, h, p_.first);
        for (double k = 0.0; k < n; k += 1.0)
            if (!fn(from_entry_sample(iv, h, p_.first, k), h)) return;
    }
}

namespace {

// Starts a record for a sample at t standing for length d.
template <class Rec>
void begin_record(Rec& rec, SampleRecord& r, const glm::dvec3& x, double t, double d, double v) {
    rec.begin(r, t - 0.5 * d, t + 0.5 * d);
    r.t = t;
    r.length = d;
    r.sample.position = x;
    r.sample.value = v;
}

}  // namespace

template <class Rec>
PixelValue ProfileIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    switch (ctx_.render.projection) {
        case Projection::Composite: return composite(ray, intervals, rec);
        case Projection::Mip: return extremum(ray, intervals, true, rec);
        case Projection::Minip: return extremum(ray, intervals, false, rec);
        case Projection::Average: return line_integral(ray, intervals, true, rec);
        case Projection::Xray: return line_integral(ray, intervals, false, rec);
        case Projection::FirstHit: break;
    }
    return {};
}

template <class Rec>
PixelValue ProfileIntegrator::composite(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    if (p_.compositing == Profile::Compositing::BackToFrontLerp) return composite_lerp(ray, intervals, rec);
    // A GPU shader's compositing: A += (1 - A) alpha, C += (1 - A) alpha c (march/Accumulators.h),
    // stopping as the profile says after every sample.
    FrontToBack<Scalar, TransmittanceRule::OpacitySum> acc;
    const Shader* shader = ctx_.pipeline.shader();
    for_each_sample(intervals, [&](double t, double d) {
        const glm::dvec3 x = ray.at(t);
        const double v = value(x);
        [[maybe_unused]] std::conditional_t<Rec::kOn, SampleRecord, char> r{};
        if constexpr (Rec::kOn) begin_record(rec, r, x, t, d, v);
        Lookup k = std::isfinite(v) && !(v < p_.value_cutoff) ? lookup(v, d) : Lookup{};
        if (p_.color_from_value && std::isfinite(v)) k.color = glm::dvec3(v);  // seed 002: textureValue.rrr
        if (p_.alpha_times_intensity) k.alpha *= ctx_.render.profile_options.intensity;  // seed 002's K
        [[maybe_unused]] const double T_before = acc.transmittance();
        if (k.alpha > 0.0) {
            glm::dvec3 c = k.color;
            if (shader) {
                const glm::dvec3 g = gradient(x);
                const glm::dvec3 n = p_.normal_along_gradient ? -g : g;
                if constexpr (Rec::kOn) {
                    c = shader->shade(c, n, -ray.direction, t, r.sample.shading);
                    r.sample.has_gradient = true;
                    r.sample.gradient = g;
                    r.sample.shaded = true;
                } else {
                    c = shader->shade(c, n, -ray.direction, t);
                }
                if (p_.clamp_shaded) c = glm::clamp(c, 0.0, 1.0);
            }
            const double cc[3] = {c.r, c.g, c.b};
            acc.add(true, false, 0.0, k.alpha, cc);
            if constexpr (Rec::kOn) r.sample.color = c;
        } else if constexpr (Rec::kOn) {
            r.sample.color = k.color;
        }
        if constexpr (Rec::kOn) {
            r.sample.classified = std::isfinite(v);
            r.sample.classified_color = k.color;
            r.sample.opacity = k.opacity;
            r.composited = true;
            r.alpha = k.alpha;
            r.tau = k.alpha < 1.0 ? -std::log1p(-k.alpha) : std::numeric_limits<double>::infinity();
            r.transmittance_before = T_before;
            r.transmittance_after = acc.transmittance();
            r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
            rec.recorder.record(r);
        }
        return !acc.stops(true, p_.termination);
    });
    PixelValue out;
    out.rgba = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
    return out;
}

// sum = lerp(sum, col, col.a density) from the far end; samples with s < the iso threshold skipped.
template <class Rec>
PixelValue ProfileIntegrator::composite_lerp(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    std::vector<std::pair<double, double>> samples;
    for_each_sample(intervals, [&](double t, double d) {
        samples.emplace_back(t, d);
        return true;
    });
    const ProfileOptions& o = ctx_.render.profile_options;
    BackToFront<Scalar, BackToFrontRule::Lerp> acc;
    // Back to front: FromExit yields the samples in that order already; the other placements front to back.
    const bool reverse = p_.placement != Profile::Placement::FromExit;
    for (std::size_t j = 0; j < samples.size(); ++j) {
        const auto [t, d] = samples[reverse ? samples.size() - 1 - j : j];
        const glm::dvec3 x = ray.at(t);
        const double v = value(x);
        const bool used = std::isfinite(v) && !(p_.sample_filter == Profile::SampleFilter::AtOrAboveIsoThreshold && normalised(v) < o.iso_threshold);
        const Lookup k = used ? lookup(v, d) : Lookup{};
        const double w = k.opacity * o.density;
        const double c[3] = {k.color.r, k.color.g, k.color.b};
        acc.lerp(used, w, c, k.opacity);
        if constexpr (Rec::kOn) {
            SampleRecord r{};
            begin_record(rec, r, x, t, d, v);
            r.sample.classified = used;
            r.sample.classified_color = k.color;
            r.sample.opacity = k.opacity;
            r.sample.color = k.color;
            r.composited = true;
            r.alpha = used ? w : 0.0;
            r.accumulated = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
            rec.recorder.record(r);
        }
    }
    PixelValue out;
    out.rgba = glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha());
    return out;
}

template <class Rec>
PixelValue ProfileIntegrator::extremum(const Ray& ray, const std::vector<Interval>& intervals, bool maximum,
                                       Rec& rec) const {
    Extremum<Scalar> acc(maximum);
    auto pixel = [&](double v) {
        const Lookup k = lookup(v, step_);
        return glm::dvec4(k.opacity * k.color, k.opacity);
    };
    for_each_sample(intervals, [&](double t, double d) {
        const glm::dvec3 x = ray.at(t);
        const double v = value(x);
        acc.add(true, v, t);
        if constexpr (Rec::kOn) {
            SampleRecord r{};
            begin_record(rec, r, x, t, d, v);
            if (std::isfinite(v)) {
                const Lookup k = lookup(v, d);
                r.sample.classified = true;
                r.sample.classified_color = k.color;
                r.sample.opacity = k.opacity;
                r.sample.color = k.color;
            }
            r.running = acc.value();
            r.accumulated = acc.any() ? pixel(acc.value()) : glm::dvec4(0.0);
            rec.recorder.record(r);
        }
        (void)d;
        return true;
    });
    PixelValue out;
    if (acc.any()) out.rgba = pixel(acc.value());
    return out;
}

template <class Rec>
PixelValue ProfileIntegrator::line_integral(const Ray& ray, const std::vector<Interval>& intervals, bool mean,
                                            Rec& rec) const {
    // A shader's plain sums (march/Accumulators.h); x-ray maximum: the largest normalised value.
    LineIntegral<PlainSum> acc;
    Extremum<Scalar> largest(true);
    const Classifier& c = ctx_.pipeline.classifier();
    const bool weighted = mean && p_.average == Profile::Average::MeanOpacityTimesNormalised;
    auto result = [&]() {
        if (!mean && p_.xray == Profile::Xray::BrightnessTimesMaximum)
            return ctx_.render.profile_options.brightness * (largest.any() ? std::max(0.0, largest.value()) : 0.0);
        return mean ? (acc.length() > 0.0 ? acc.mean() : 0.0) : ctx_.render.gain * acc.integral();
    };
    for_each_sample(intervals, [&](double t, double d) {
        const glm::dvec3 x = ray.at(t);
        const double v = value(x);
        [[maybe_unused]] double s = 0.0;
        if (std::isfinite(v)) {
            s = weighted ? lookup(v, d).opacity * normalised(v) : c.coordinate(v);
            acc.add(weighted ? s : s * d, weighted ? 1.0 : d);
            // seed 001: maxVal = 0, then fmaxf(maxVal, sample) over the samples with sample >= isoValue
            const bool kept = !(p_.sample_filter == Profile::SampleFilter::AtOrAboveIsoThreshold &&
                                normalised(v) < ctx_.render.profile_options.iso_threshold);
            largest.add(kept, normalised(v), t);
        }
        if constexpr (Rec::kOn) {
            SampleRecord r{};
            begin_record(rec, r, x, t, d, v);
            r.coordinate = s;
            r.running = result();
            r.accumulated = glm::dvec4(r.running, r.running, r.running, 1.0);
            rec.recorder.record(r);
        }
        return true;
    });
    PixelValue out;
    if (intervals.empty()) return out;
    const double g = result();
    out.rgba = glm::dvec4(g, g, g, 1.0);
    return out;
}

}  // namespace volref
