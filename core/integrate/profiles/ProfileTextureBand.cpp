// The texture band of a mirror profile with a texture unit (render.profile_options.texture_band;
// conventions section 9, "The texture unit"): ProfileIntegrator::band and its interval arithmetic,
// apart from the loops of ProfileIntegrator.cpp.
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

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/integrate/march/SamplePlacement.h"
#include "core/integrate/march/Accumulators.h"
#include "core/integrate/profiles/CudaCurvilinearKernel.h"
#include "core/integrate/profiles/TextureUnit.h"
#include "core/sample/VolumeSampler.h"
#include "geometry/ShellCoordinates.h"
#include "transfer/OpacityCorrection.h"
#include "transfer/Shader.h"
#include "core/integrate/profiles/ProfileSamples-inl.h"
#include "transfer/TransferFunction.h"

namespace volref {

// --- the texture band (conventions section 9, "The texture unit") ------------------------------------
// Every quantity is carried as an interval [lo, hi] holding its value for every texture unit within the
// model: a fetch within [exact - band, exact + band] (TextureUnit.h), a table read anywhere on the
// table's piecewise-linear curve over the fetch's interval and off it by at most 1/512 of the step
// between the two texels it reads; every later step is multilinear in its inputs, so its extremes over
// a box of inputs lie at the box's corners. The pixel's error channel is the largest distance from
// the rendered value to its interval's ends over R, G, B, A, plus 1e-12 for the rounding of this
// double-precision arithmetic against the render's own.

namespace {

constexpr double kBandRounding = 1e-12;

struct Iv {
    double lo = 0.0, hi = 0.0;
    void hull(double v) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
};

// The range of x y over x in a, y in b.
Iv product(Iv a, Iv b) {
    Iv r{a.lo * b.lo, a.lo * b.lo};
    r.hull(a.lo * b.hi);
    r.hull(a.hi * b.lo);
    r.hull(a.hi * b.hi);
    return r;
}

Iv sum(Iv a, Iv b) { return {a.lo + b.lo, a.hi + b.hi}; }

}  // namespace

ProfileIntegrator::Box ProfileIntegrator::lookup_range(double vlo, double vhi, double d) const {
    Box b;
    auto start = [&](const double* c) {
        for (int j = 0; j < 5; ++j) b.lo[j] = b.hi[j] = c[j];
    };
    auto add = [&](const double* c) {
        for (int j = 0; j < 5; ++j) {
            b.lo[j] = std::min(b.lo[j], c[j]);
            b.hi[j] = std::max(b.hi[j], c[j]);
        }
    };
    if (table_.empty()) {  // the transfer function read exactly: its extremes at the ends and its knots
        auto at = [&](double v) {
            const Classified k = ctx_.pipeline.classifier().classify(v, 0.0);
            const double c[5] = {k.color.r, k.color.g, k.color.b, k.opacity, alpha(k.opacity, d)};
            return std::array<double, 5>{c[0], c[1], c[2], c[3], c[4]};
        };
        std::array<double, 5> c = at(vlo);
        start(c.data());
        c = at(vhi);
        add(c.data());
        const double inv = transfer_->normalized() ? transfer_->inverse_window_width() : 1.0;
        const double w0 = transfer_->normalized() ? transfer_->window()[0] : 0.0;
        auto knots = [&](const std::vector<double>& xs) {
            for (double x : xs) {
                const double v = w0 + x / inv;
                if (v > vlo && v < vhi) {
                    c = at(v);
                    add(c.data());
                }
            }
        };
        knots(transfer_->color_function().xs());
        knots(transfer_->opacity_function().xs());
        if (p_.correction == Profile::Correction::Power) {  // the floor: a jump in the corrected alpha
            const Classified klo = ctx_.pipeline.classifier().classify(vlo, 0.0);
            const Classified khi = ctx_.pipeline.classifier().classify(vhi, 0.0);
            const double f = p_.correction_floor;
            if (std::min(klo.opacity, khi.opacity) <= f && std::max(klo.opacity, khi.opacity) >= f) {
                const double l = ctx_.pipeline.classifier().unit_distance();
                b.lo[4] = std::min({b.lo[4], f, opacity_for_length(f, d, l)});
                b.hi[4] = std::max({b.hi[4], f, opacity_for_length(f, d, l)});
            }
        }
        return b;
    }
    // A table of n texels read at pos(v), monotone in v, the position widened by the unit's coordinate
    // move: texture_unit::table_hull per channel.
    const int n = p_.table_entries;
    auto pos = [&](double v) {
        const double u = p_.table_coordinate == Profile::TableCoordinate::DataRangeTimesTransferScale
                             ? std::clamp(normalised(v) * ctx_.render.profile_options.transfer_scale, 0.0, 1.0)
                             : normalised(v);
        return std::clamp(u * double(n) - 0.5, 0.0, double(n - 1));
    };
    auto entry = [&](int j, int c) { return c < 4 ? table_[std::size_t(j)][c] : table_alpha_[std::size_t(j)]; };
    // The unit reads at float32(u) cut to 20 bits: within n kNormalizedDelta texels of pos (TextureUnit.h).
    const double move = double(n) * texture_unit::kNormalizedDelta;
    const double plo = std::max(0.0, pos(vlo) - move), phi = std::min(double(n - 1), pos(vhi) + move);
    for (int c = 0; c < 5; ++c)  // r, g, b, opacity, vtk-gpu's corrected alpha
        texture_unit::table_hull([&](int j) { return entry(j, c); }, n, plo, phi, b.lo[c], b.hi[c]);
    return b;
}

// A composited sample as composite() / composite_lerp() build it, over v in [vlo, vhi].
ProfileIntegrator::Box ProfileIntegrator::sample_range(double vlo, double vhi, double d) const {
    const ProfileOptions& o = ctx_.render.profile_options;
    // Which values the sample is used for: composite() skips v < value_cutoff; composite_lerp() skips s < iso.
    double cut = -std::numeric_limits<double>::infinity();
    if (p_.value_cutoff > cut) cut = p_.value_cutoff;
    const bool lerp = p_.compositing == Profile::Compositing::Lerp;
    if (lerp && p_.sample_filter == Profile::SampleFilter::AtOrAboveIsoThreshold) cut = lo_ + o.iso_threshold * width_;
    const bool never = vhi < cut, always = !(vlo < cut);
    Box b{};
    if (never) {
        for (int j = 0; j < 5; ++j) b.lo[j] = b.hi[j] = 0.0;
    } else {
        b = lookup_range(std::max(vlo, cut), vhi, d);
        if (!always)  // skipped for some units: Lookup{} (colour 0, opacity 0)
            for (int j = 0; j < 5; ++j) {
                b.lo[j] = std::min(b.lo[j], 0.0);
                b.hi[j] = std::max(b.hi[j], 0.0);
            }
    }
    if (p_.color_from_value)  // seed 002: textureValue.rrr, whether or not the sample is used
        for (int j = 0; j < 3; ++j) b.lo[j] = vlo, b.hi[j] = vhi;
    if (p_.alpha_times_intensity) b.lo[4] *= o.intensity, b.hi[4] *= o.intensity;
    return b;
}

// The shaded colour over every gradient G in the box G0 +- dG (per-axis half-widths) and every material
// colour in b's colour box, as composite() shades (Shader.h; clamped when the profile clamps). With
// eps = |dG| (2-norm) and the normal N = -G / |G|: |N - N0| <= rho = min(2, 2 eps / |G0|), so every dot
// product N.X with a unit X lies in [N0.X - rho, N0.X + rho] cut to [-1, 1]; max(., 0), |.| and the
// specular power are monotone on such intervals, the rest are products of intervals. Where some G in
// the box has |G| <= the zero-gradient tolerance the sample may be unshaded (c = m): hulled in.
void ProfileIntegrator::shade_range(Box& b, const glm::dvec3& G0, const glm::dvec3& dG, const glm::dvec3& V,
                                    double depth) const {
    const Shader& sh = *ctx_.pipeline.shader();
    const ShadingSpec& k = sh.spec();
    const double eps = glm::length(dG), len = glm::length(G0), tol = sh.zero_gradient_tolerance();
    const bool maybe_unshaded = !(len - eps > tol), maybe_shaded = len + eps > tol;
    const double rho = len > 0.0 ? std::min(2.0, 2.0 * eps / len) : 2.0;
    const glm::dvec3 N0 = len > 0.0 ? -G0 / len : glm::dvec3(0.0);
    auto dot_range = [&](const glm::dvec3& X) {
        const double d = glm::dot(N0, X);
        return Iv{std::max(-1.0, d - rho), std::min(1.0, d + rho)};
    };
    auto clamp_dot = [&](Iv x) {
        if (!k.two_sided) return Iv{std::max(x.lo, 0.0), std::max(x.hi, 0.0)};
        if (x.lo <= 0.0 && x.hi >= 0.0) return Iv{0.0, std::max(-x.lo, x.hi)};
        return Iv{std::min(std::fabs(x.lo), std::fabs(x.hi)), std::max(std::fabs(x.lo), std::fabs(x.hi))};
    };
    const Iv m[3] = {{b.lo[0], b.hi[0]}, {b.lo[1], b.hi[1]}, {b.lo[2], b.hi[2]}};
    Iv c[3] = {};
    const double cue = 1.0 / (k.kc + k.kl * depth);
    for (const LightSpec& light : sh.lights()) {
        const glm::dvec3 L = light.type == LightSpec::Type::Headlight ? V : light.direction;
        const Iv nl = clamp_dot(dot_range(L));
        Iv sp{0.0, 0.0};
        if (k.ks != 0.0) {
            Iv dot;
            if (k.model == ShadingSpec::Model::Phong) {  // R.V = 2 (N.L)(N.V) - L.V, max(., 0)
                const Iv p = product(dot_range(L), dot_range(V));
                dot = {std::max(0.0, std::max(-1.0, 2.0 * p.lo - glm::dot(L, V))), std::max(0.0, std::min(1.0, 2.0 * p.hi - glm::dot(L, V)))};
            } else {
                dot = clamp_dot(dot_range(glm::normalize(L + V)));
            }
            sp = {k.ks * std::pow(dot.lo, k.n), k.ks * std::pow(dot.hi, k.n)};
        }
        for (int j = 0; j < 3; ++j) {
            const Iv amb = product(Iv{k.ka, k.ka}, m[j]);
            const Iv dif = product(product(Iv{k.kd * cue, k.kd * cue}, m[j]), nl);
            const Iv spec{sp.lo * cue, sp.hi * cue};
            c[j] = sum(c[j], product(Iv{light.color[j], light.color[j]}, sum(sum(amb, dif), spec)));
        }
    }
    for (int j = 0; j < 3; ++j) {
        Iv r = maybe_shaded ? c[j] : m[j];
        if (maybe_unshaded) r = {std::min(r.lo, m[j].lo), std::max(r.hi, m[j].hi)};
        if (p_.clamp_shaded) r = {std::clamp(r.lo, 0.0, 1.0), std::clamp(r.hi, 0.0, 1.0)};
        b.lo[j] = r.lo;
        b.hi[j] = r.hi;
    }
}

double ProfileIntegrator::band(const Ray& ray, const std::vector<Interval>& intervals, const glm::dvec4& rendered) const {
    const ProfileOptions& o = ctx_.render.profile_options;
    Iv F[4];  // the pixel's R, G, B, A over all units
    bool any = false;
    auto hull_into = [&](const Iv* p) {
        for (int j = 0; j < 4; ++j) F[j] = any ? Iv{std::min(F[j].lo, p[j].lo), std::max(F[j].hi, p[j].hi)} : p[j];
        any = true;
    };
    struct S {
        double t, d, vlo, vhi;
        glm::dvec3 g{0.0}, dg{0.0};  // shaded composite: the exact gradient and the half-widths of its box
    };
    std::vector<S> samples;
    const Shader* shader = is_composite(ctx_.render.projection) ? ctx_.pipeline.shader() : nullptr;
    for_each_sample(intervals, [&](double t, double d) {
        const glm::dvec3 x = ray.at(t);
        const Fetch f = texture_fetch(x);
        S q{t, d, f.exact, f.exact};
        if (std::isfinite(f.exact)) q.vlo = f.exact - f.band, q.vhi = f.exact + f.band;
        if (shader) {  // gradient() with each fetch's exact value and band
            for (int a = 0; a < 3; ++a) {
                glm::dvec3 e(0.0);
                e[a] = offset_[a];
                const bool forward = p_.gradient == Profile::Gradient::Forward;
                const Fetch fp = texture_fetch(x + e), fm = forward ? f : texture_fetch(x - e);
                const double h = forward ? offset_[a] : 2.0 * offset_[a];
                q.g[a] = (fp.exact - fm.exact) / h;
                q.dg[a] = (fp.band + fm.band) / h;
            }
        }
        samples.push_back(q);
        return true;
    });
    switch (accumulation(ctx_.render.projection)) {
        case Accumulation::Composite:
            if (p_.compositing == Profile::Compositing::Lerp) {
                // sum = sum (1 - w) + col w per channel, w = opacity density, col = (rgb, opacity)
                Iv sum[4] = {};
                const bool reverse = p_.placement != Profile::Placement::FromExit;
                for (std::size_t j = 0; j < samples.size(); ++j) {
                    const S& q = samples[reverse ? samples.size() - 1 - j : j];
                    if (!std::isfinite(q.vlo)) continue;
                    const Box b = sample_range(q.vlo, q.vhi, q.d);
                    const Iv w{b.lo[3] * o.density, b.hi[3] * o.density};
                    for (int c = 0; c < 4; ++c) {
                        const Iv col{b.lo[c == 3 ? 3 : c], b.hi[c == 3 ? 3 : c]};
                        Iv r{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
                        for (double sv : {sum[c].lo, sum[c].hi})
                            for (double cv : {col.lo, col.hi})
                                for (double wv : {w.lo, w.hi}) r.hull(sv * (1.0 - wv) + cv * wv);
                        sum[c] = r;
                    }
                }
                hull_into(sum);
            } else {
                // C += T alpha c, T *= 1 - alpha; the unit stops after the first sample where its own A
                // passes the profile's test: the pixel lies in the hull of the boxes where some unit may stop.
                Iv C[3] = {}, T{1.0, 1.0};
                const Termination& term = p_.termination;
                auto stops = [&](double A) {
                    return (term.test_alpha_above && A > term.alpha_above) ||
                           (term.test_alpha_at_least && A >= term.alpha_at_least) ||
                           (term.test_transmittance && 1.0 - A <= term.transmittance_at_most);
                };
                bool certain = false;
                for (const S& q : samples) {
                    if (!std::isfinite(q.vlo)) continue;
                    Box b = sample_range(q.vlo, q.vhi, q.d);
                    if (shader) shade_range(b, p_.normal_along_gradient ? -q.g : q.g, q.dg, -ray.direction, q.t);
                    const Iv a{b.lo[4], b.hi[4]};
                    const Iv Ta = product(T, a);
                    for (int c = 0; c < 3; ++c) C[c] = sum(C[c], product(Ta, Iv{b.lo[c], b.hi[c]}));
                    T = product(T, Iv{1.0 - a.hi, 1.0 - a.lo});
                    const Iv box[4] = {C[0], C[1], C[2], Iv{1.0 - T.hi, 1.0 - T.lo}};
                    if (stops(1.0 - T.lo)) hull_into(box);  // some unit may stop here
                    if (stops(1.0 - T.hi)) {                // every unit has stopped
                        certain = true;
                        break;
                    }
                }
                if (!certain) {
                    const Iv box[4] = {C[0], C[1], C[2], Iv{1.0 - T.hi, 1.0 - T.lo}};
                    hull_into(box);
                }
            }
            break;
        case Accumulation::Extremum: {
            const bool maximum = takes_maximum(ctx_.render.projection);
            Iv v{};
            bool found = false;
            for (const S& q : samples) {
                if (!std::isfinite(q.vlo)) continue;
                if (!found) v = {q.vlo, q.vhi};
                else if (maximum) v = {std::max(v.lo, q.vlo), std::max(v.hi, q.vhi)};
                else v = {std::min(v.lo, q.vlo), std::min(v.hi, q.vhi)};
                found = true;
            }
            if (!found) return 0.0;
            const Box b = lookup_range(v.lo, v.hi, step_);
            const Iv a{b.lo[3], b.hi[3]};
            const Iv p[4] = {product(a, {b.lo[0], b.hi[0]}), product(a, {b.lo[1], b.hi[1]}), product(a, {b.lo[2], b.hi[2]}), a};
            hull_into(p);
            break;
        }
        case Accumulation::LineIntegral: {
            const bool mean = takes_mean(ctx_.render.projection);
            const Classifier& cl = ctx_.pipeline.classifier();
            const bool weighted = mean && p_.average == Profile::Average::MeanOpacityTimesNormalised;
            Iv g{}, largest{0.0, 0.0};
            double length = 0.0;
            for (const S& q : samples) {
                if (!std::isfinite(q.vlo)) continue;
                Iv s;
                if (weighted) {
                    const Box b = lookup_range(q.vlo, q.vhi, q.d);
                    s = product({b.lo[3], b.hi[3]}, {normalised(q.vlo), normalised(q.vhi)});
                } else {
                    s = {std::min(cl.coordinate(q.vlo), cl.coordinate(q.vhi)), std::max(cl.coordinate(q.vlo), cl.coordinate(q.vhi))};
                }
                g = sum(g, weighted ? s : Iv{s.lo * q.d, s.hi * q.d});
                length += weighted ? 1.0 : q.d;
                // seed 001's maximum over the samples kept by the iso threshold (0 when none)
                const double cut = p_.sample_filter == Profile::SampleFilter::AtOrAboveIsoThreshold ? o.iso_threshold : -std::numeric_limits<double>::infinity();
                if (!(normalised(q.vlo) < cut)) largest.lo = std::max(largest.lo, normalised(q.vlo));
                if (!(normalised(q.vhi) < cut)) largest.hi = std::max(largest.hi, normalised(q.vhi));
            }
            if (intervals.empty()) return 0.0;
            Iv r;
            if (!mean && p_.xray == Profile::Xray::BrightnessTimesMaximum) r = {o.brightness * largest.lo, o.brightness * largest.hi};
            else if (mean) r = length > 0.0 ? Iv{g.lo / length, g.hi / length} : Iv{};
            else r = {ctx_.render.gain * g.lo, ctx_.render.gain * g.hi};
            const Iv p[4] = {r, r, r, Iv{1.0, 1.0}};
            hull_into(p);
            break;
        }
        case Accumulation::FirstHit: break;
    }
    if (!any) return 0.0;
    double e = 0.0;
    for (int j = 0; j < 4; ++j) e = std::max({e, F[j].hi - rendered[j], rendered[j] - F[j].lo});
    return e + kBandRounding * (1.0 + std::max({std::fabs(rendered.r), std::fabs(rendered.g), std::fabs(rendered.b), std::fabs(rendered.a)}));
}

}  // namespace volref
