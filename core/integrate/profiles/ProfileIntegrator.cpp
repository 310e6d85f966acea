#include "core/integrate/profiles/ProfileIntegrator.h"
#include "core/integrate/profiles/ProfileSamples-inl.h"

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
#include "core/integrate/profiles/Slices.h"
#include "core/integrate/profiles/TextureUnit.h"
#include "core/sample/VolumeSampler.h"
#include "geometry/ShellCoordinates.h"
#include "transfer/OpacityCorrection.h"
#include "transfer/Shader.h"
#include "transfer/TransferFunction.h"

namespace volref {

void check_profile_applies(const Profile& p, const SamplePipeline& pipeline, const RenderSpec& r) {
    const std::string where = std::string("render.profile: \"") + p.name + "\" ";
    if (is_first_hit(r.projection)) throw Error(where + "does not render the first-hit projection");
    if (r.integrator != IntegrationMethod::Fixed) throw Error(where + "needs render.integrator \"fixed\"");
    if (r.order != CompositeOrder::FrontToBack)
        throw Error(where + "composites in its own order (remove render.order \"back-to-front\")");
    if (r.early_termination) throw Error(where + "has its own termination rule (remove render.early_termination)");
    if (!pipeline.view().cartesian && p.grids == Profile::Grids::Cartesian)
        throw Error(where + "needs a Cartesian grid (box or mesh bounds)");
    if (p.grids == Profile::Grids::CartesianAndShells && pipeline.shaded() && is_composite(r.projection))
        throw Error(where + "does not shade (remove volume.shading)");
    if (pipeline.preclassified()) throw Error(where + "classifies after interpolation (volume.classify \"post\")");
    if (pipeline.classifier().needs_gradient())
        throw Error(where + "needs a classification by value alone (no gradient opacity or Levoy classification)");
}

ProfileIntegrator::ProfileIntegrator(const IntegrationContext& ctx, const Profile& profile, const Volume& volume,
                                     const BoundsSpec* bounds, const SliceFrame* slice_frame)
    : OneLoopIntegrator(ctx), p_(profile) {
    check_profile_applies(p_, ctx.pipeline, ctx.render);
    if (p_.renderer != Profile::Renderer::RayCaster)
        throw Error(std::string("render.profile: \"") + p_.name + "\" is an image-space renderer, not a ray integrator");
    const VolumeSampler* cartesian = ctx.pipeline.view().cartesian;
    const double inf = std::numeric_limits<double>::infinity();
    domain_lo_ = cartesian ? volume.domain_min() : glm::dvec3(-inf);  // shells: the intervals stay inside
    domain_hi_ = cartesian ? volume.domain_max() : glm::dvec3(inf);
    step_ = ctx.step;
    if (p_.seed_shell_reads && !cartesian) {
        shell_ = ctx.pipeline.view().shell_grid;
        volume_ = &volume;
        if (!shell_) throw Error(std::string("render.profile: \"") + p_.name + "\" needs the shell's grid");
    }
    // the texture unit and its band (TextureUnit.h; conventions section 9, "The texture unit")
    const ProfileOptions& po = ctx.render.profile_options;
    if (po.data_unorm16 && !shell_)
        throw Error("render.profile_options.texture_format: \"unorm16\" is seed 001's data texture on a shell (cylindrical or spherical bounds)");
    texture_unit_ = po.texture_unit;
    band_ = po.texture_band;
    texels_ = &volume;
    texture_dims_ = volume.dims;
    // GLSL programs (vtk-gpu, glsl-basic) read their volume with normalised coordinates, seed 001's
    // tex3D with unnormalised ones (TextureUnit.h: the 20-bit cut applies to the former only).
    normalized_coordinates_ = p_.id != ProfileId::CudaCurvilinear;
    if (texture_unit_ != ProfileOptions::TextureUnit::Exact || band_) {
        const std::string key = band_ ? "render.profile_options.texture_band" : "render.profile_options.texture_unit";
        if ((p_.id == ProfileId::Ospray || p_.id == ProfileId::Reference) && ctx.render.profile_rules.empty())
            throw Error(key + ": only the vtk-gpu, glsl-basic and cuda-curvilinear profiles and custom ones (render.profile's texture_unit) model a texture unit");
        if (!shell_) {
            cartesian_ = cartesian;
            if (!cartesian_ || &ctx.pipeline.sampler() != static_cast<const FieldSampler*>(cartesian_) ||
                cartesian_->interpolation() != Interpolation::Trilinear)
                throw Error(key + ": the texture unit filters trilinearly (volume.interpolation \"trilinear\", one Cartesian grid)");
        }
        if (band_ && p_.table_entries <= 1) {
            transfer_ = ctx.pipeline.view().transfer_function;
            if (!transfer_) throw Error(key + ": the band needs a transfer function (volume.transfer)");
        }
    }
    if (p_.voxel_length == Profile::VoxelLength::ExtentOverSamples && ctx.render.step_units == StepUnits::Voxel) {
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (cartesian ? volume.spacing[a] < volume.spacing[axis] : volume.dims[a] > volume.dims[axis]) axis = a;
        const double n = double(volume.dims[std::size_t(axis)]);
        if (n > 1.0) step_ = ctx.step * (n - 1.0) / n;
    }
    // seed 001's kernel in float32 (CudaCurvilinearKernel.h) for what the seed renders (composite, x-ray)
    if (p_.id == ProfileId::CudaCurvilinear && shell_ && bounds && po.kernel == ProfileOptions::Kernel::Float32 &&
        (ctx.render.projection == Projection::Composite || ctx.render.projection == Projection::Xray)) {
        if (texture_unit_ == ProfileOptions::TextureUnit::Admissible)
            throw Error("render.profile_options.texture_unit: the float32 kernel reads through the exact or the h100 unit");
        kernel_ = std::make_unique<CudaCurvilinearKernel>(seed001_frame(volume, *bounds, ctx.pipeline.classifier(), ctx.render, step_),
                                                  texture_unit_ == ProfileOptions::TextureUnit::H100, band_);
    }
    if (po.tricubic) {  // seed 001's cubicInterpolate (CudaCurvilinearKernel.h, seed001_cubic)
        if (!shell_)
            throw Error("render.profile_options.tricubic: seed 001's tri-cubic option reads a shell's data (cylindrical or spherical bounds)");
        if (!kernel_ && (texture_unit_ != ProfileOptions::TextureUnit::Exact || band_))
            throw Error("render.profile_options.tricubic: with kernel \"double\" (or a projection other than composite and x-ray) the cubic reads exactly; the h100 unit and texture_band need kernel \"float32\"");
        tricubic_ = true;
    }
    check_rules(ctx.render, cartesian != nullptr);
    traits_.writes_error = band_;
    traits_.writes_fault = kernel_ != nullptr;
    if (p_.placement == Profile::Placement::Slices) {
        if (!slice_frame) throw Error("render.profile.placement: \"slices\" needs the frame's camera");
        const auto [smin, smax] = volume.value_range();
        lo_ = smin;
        width_ = smax - smin;
        prepare_slices(volume, *slice_frame);
        traits_.writes_error = band_ || framebuffer_band_;
        return;  // the slicer's table and texels (prepare_slices): nothing below is read
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

// A rule this integrator cannot honour is an error naming it: never ignored.
void ProfileIntegrator::check_rules(const RenderSpec& render, bool cartesian) const {
    const ProfileRules& r = render.profile_rules;
    auto fail = [](const std::string& key, const std::string& why) { throw Error("render.profile." + key + ": " + why); };
    if (r.arithmetic == ProfileRules::Arithmetic::Float32 && !kernel_)
        fail("arithmetic", "float32 is implemented by seed 001's kernel only (base \"cuda-curvilinear\" on a shell, composite or "
                           "x-ray); a profile computes in double, which matches a float32 renderer to its rounding (docs/gpu-quick-start.md)");
    if (kernel_)
        for (const std::string& k : r.keys)
            if (k != "arithmetic" && k != "texture_unit")
                fail(k, "seed 001's float32 kernel runs the program's own loop, whose rules are fixed (set render.profile.arithmetic "
                        "\"double\" to render with other rules)");
    if (r.first && p_.placement != Profile::Placement::FromEntry) fail("first", "the first sample's offset applies to placement \"from-entry\"");
    if (p_.placement != Profile::Placement::Slices) {  // the slicers' rules
        for (const char* k : {"slices", "texture", "texture_format", "texture_window", "table_lookup", "table_format", "classify",
                              "framebuffer", "framebuffer_rounding", "blend_products", "blend", "blend_alpha", "texture_filter"})
            if (std::find(r.keys.begin(), r.keys.end(), k) != r.keys.end())
                fail(k, "applies to placement \"slices\" (a slicer's rule)");
        if (render.profile_options.framebuffer_band)
            throw Error("render.profile_options.framebuffer_band: applies to placement \"slices\"");
    } else if (r.step_count || r.first || r.compositing || r.termination || (r.ray_box && *r.ray_box != ProfileRules::RayBox::Domain)) {
        fail(r.step_count ? "step_count" : r.first ? "first" : r.compositing ? "compositing" : r.termination ? "termination" : "ray_box",
             "not read by placement \"slices\" (its samples are the surfaces' crossings, its compositing the frame buffer's blend)");
    }
    if (r.step_count && (p_.placement == Profile::Placement::Midpoints))
        fail("step_count", "applies to the placements \"from-entry\" and \"from-exit\" (midpoints: segment_count, conventions section 4)");
    if (r.ray_box && *r.ray_box != ProfileRules::RayBox::Domain && !cartesian) fail("ray_box", "a texel or given box needs a Cartesian grid");
    const Termination& t = p_.termination;
    const bool stops = t.test_alpha_above || t.test_alpha_at_least || t.test_transmittance;
    const bool composite = is_composite(render.projection);
    if (composite && p_.compositing == Profile::Compositing::Lerp) {
        if (r.termination && *r.termination != ProfileRules::Stop::None)
            fail("termination", "lerp compositing runs back to front and has no termination");
        if (stops && r.compositing)
            fail("compositing", "lerp has no termination, and the base's termination would be dropped (set termination \"none\")");
        if (r.correction && *r.correction != profile(render.profile).correction)  // the base's own value reads nothing
            fail("correction", "lerp compositing weights each sample by its uncorrected opacity times render.profile_options.density");
    }
    if (composite && p_.placement == Profile::Placement::FromExit && p_.compositing != Profile::Compositing::Lerp)
        fail(r.placement ? "placement" : "compositing", "placement \"from-exit\" visits the samples back to front: it composites with \"lerp\"");
    if (band_ && p_.gradient == Profile::Gradient::CentralInDomain && ctx_.pipeline.shaded())
        throw Error("render.profile_options.texture_band: the band is derived for the central and forward gradients, not \"central-in-domain\"");
    if (band_ && p_.correction == Profile::Correction::Exact && p_.table_entries > 1)
        throw Error("render.profile_options.texture_band: the band is derived for tables whose entries are corrected (correction \"pow\"), not \"exact\"");
}

double ProfileIntegrator::alpha(double a, double d) const {
    const double l = ctx_.pipeline.classifier().unit_distance();
    a = std::clamp(a, 0.0, 1.0);
    switch (p_.correction) {
        case Profile::Correction::Power:
        case Profile::Correction::Exact: return a > p_.correction_floor ? opacity_for_length(a, d, l) : a;
        case Profile::Correction::None: return a;
        case Profile::Correction::Extinction: return -std::expm1(-a * d * p_.density_scale);
    }
    return a;
}

// A texture read clamps to the edge: positions past the domain read its boundary.
double ProfileIntegrator::value(const glm::dvec3& x) const {
    if (shell_) return seed_shell_value(x);
    if (texture_unit_ != ProfileOptions::TextureUnit::Exact) return texture_fetch(x).value;
    return ctx_.pipeline.sampler().value(glm::clamp(x, domain_lo_, domain_hi_));
}

// Seed 001's interpolateCyl / interpolateSpher with tex3D (Profile::seed_shell_reads).
namespace {

// Exact trilinear interpolation of corners c = x + 2 y + 4 z, as seed_shell_value always computed it.
double lerp_corners(const std::array<double, 8>& k, const glm::dvec3& w) {
    const double x00 = k[0] + w.x * (k[1] - k[0]);
    const double x10 = k[2] + w.x * (k[3] - k[2]);
    const double x01 = k[4] + w.x * (k[5] - k[4]);
    const double x11 = k[6] + w.x * (k[7] - k[6]);
    const double y0 = x00 + w.y * (x10 - x00), y1 = x01 + w.y * (x11 - x01);
    return y0 + w.z * (y1 - y0);
}

}  // namespace

// The texels of seed 001's read at x (corners c = x + 2 y + 4 z, fractions w, the unnormalised
// texture coordinate `coord`); false: outVal.
bool ProfileIntegrator::shell_texels(const glm::dvec3& x, std::array<double, 8>& k, glm::dvec3& w,
                                     glm::dvec3& coord) const {
    const glm::dvec3 c = shell_->shell_coordinates(x);
    glm::dvec3 u;
    std::array<std::int64_t, 3> i0{}, i1{};
    for (int a = 0; a < 3; ++a) {
        const ShellAxis& ax = shell_->axis(a);
        const double n = double(ax.n);
        double rel = c[shell_->coordinate_of_axis(a)] - ax.lo;
        if (ax.angular) rel = std::fmod(std::fmod(rel, 360.0) + 360.0, 360.0);  // atan2 + 2 pi: [0, 360) from lo
        const double tex = rel / ((ax.hi - ax.lo) / n);
        if (!(tex >= 0.0 && tex <= n - 1.0)) return false;  // outVal (0: the data minimum, s = 0)
        coord[a] = tex;
        u[a] = std::clamp(tex - 0.5, 0.0, n - 1.0);       // texel i centred at i + 0.5, clamped
        i0[std::size_t(a)] = ax.n > 1 ? std::min(std::int64_t(std::floor(u[a])), ax.n - 2) : 0;
        i1[std::size_t(a)] = ax.n > 1 ? i0[std::size_t(a)] + 1 : 0;
        w[a] = ax.n > 1 ? u[a] - double(i0[std::size_t(a)]) : 0.0;
    }
    for (int j = 0; j < 8; ++j)
        k[std::size_t(j)] = texel((j & 1) ? i1[0] : i0[0], (j & 2) ? i1[1] : i0[1], (j & 4) ? i1[2] : i0[2]);
    return true;
}

// seed 001's unsigned shorts over the data range (texture_format "unorm16"): q = round(s 65535).
std::uint16_t ProfileIntegrator::texel_code(std::int64_t i, std::int64_t j, std::int64_t k) const {
    const double v = texels_->at(i, j, k);
    return texture_unit::unorm16(width_ > 0.0 ? (v - lo_) / width_ : 0.0);
}

// A texel as the profile's texture holds it, as a value: the voxel, or seed 001's min + (max - min) q / 65535.
double ProfileIntegrator::texel(std::int64_t i, std::int64_t j, std::int64_t k) const {
    if (ctx_.render.profile_options.data_unorm16) return code_value(texel_code(i, j, k));
    return texels_->at(i, j, k);
}

double ProfileIntegrator::seed_shell_value(const glm::dvec3& x) const {
    if (texture_unit_ != ProfileOptions::TextureUnit::Exact) return texture_fetch(x).value;
    std::array<double, 8> k;
    glm::dvec3 w, coord;
    if (!shell_texels(x, k, w, coord)) return lo_;
    if (tricubic_) {  // 8 exact linear reads (tex3D's convention) at the seed's mixture coordinates
        return seed001_cubic({coord.x, coord.y, coord.z}, [&](const std::array<double, 3>& m) {
            const texture_unit::Fetch3d fe = texture_unit::locate_3d(m, texture_dims_);
            const std::array<double, 8> e = texture_unit::exact_weights(fe.axis);
            double v = 0.0;
            for (int c = 0; c < 8; ++c) {
                const auto i = fe.corner_index(c);
                v += e[std::size_t(c)] * texel(i[0], i[1], i[2]);
            }
            return v;
        });
    }
    return lerp_corners(k, w);
}

// TextureUnit.h: exact, the h100 rule or a unit of its family, and the band around exact. The unit's
// coordinate per axis is the exact one rounded to float32 (normalised: u = float32((i + 0.5) / n), then
// the rule's 20-bit cut); the band takes the corner values of the exact position's cell and of the
// unit's, and the move delta between the two positions (TextureUnit.h, "The family and its band").
ProfileIntegrator::Fetch ProfileIntegrator::texture_fetch(const glm::dvec3& x) const {
    namespace tu = texture_unit;
    std::array<double, 8> k;
    glm::dvec3 w, coord;
    Fetch out;
    if (shell_) {
        if (!shell_texels(x, k, w, coord)) {
            out.value = out.exact = lo_;  // outVal: no texture read
            return out;
        }
        out.exact = lerp_corners(k, w);
    } else {  // VolumeSampler::trilinear, the exact path's value
        std::array<std::int64_t, 3> cell;
        const glm::dvec3 u = cartesian_->continuous_index(glm::clamp(x, domain_lo_, domain_hi_));
        cartesian_->locate(u, cell, w);
        const std::array<double, 8> L = cartesian_->corners(cell);  // Levoy's order
        k = {L[0], L[1], L[3], L[2], L[4], L[5], L[7], L[6]};
        out.exact = volref::trilinear(L, w.x, w.y, w.z);
        coord = u + 0.5;  // texel i centred at i + 0.5
    }
    std::array<double, 3> xu{};
    double delta = 0.0;
    for (int a = 0; a < 3; ++a) {
        const std::int64_t n = texture_dims_[std::size_t(a)];
        if (normalized_coordinates_) {
            xu[std::size_t(a)] = tu::unnormalized(tu::to_float32(coord[a] / double(n)), n);
            delta += tu::kNormalizedDelta * double(n);
        } else {
            xu[std::size_t(a)] = tu::to_float32(coord[a]);
            delta += tu::kCoordinateDelta * std::fabs(coord[a]) + 0x1p-149;
        }
    }
    const tu::Fetch3d f = tu::locate_3d(xu, texture_dims_);
    const bool unorm16 = ctx_.render.profile_options.data_unorm16;
    std::array<double, 8> q;            // the unit's corners as values
    std::array<std::uint16_t, 8> codes{};  // and as seed 001's unsigned shorts (unorm16)
    double vmin = k[0], vmax = k[0], amax = 0.0;
    for (int c = 0; c < 8; ++c) {
        const auto i = f.corner_index(c);
        if (unorm16) {  // texel(), keeping the code for the h100 filter
            codes[std::size_t(c)] = texel_code(i[0], i[1], i[2]);
            q[std::size_t(c)] = code_value(codes[std::size_t(c)]);
        } else {
            q[std::size_t(c)] = texel(i[0], i[1], i[2]);
        }
        for (double v : {k[std::size_t(c)], q[std::size_t(c)]}) {
            vmin = std::min(vmin, v);
            vmax = std::max(vmax, v);
            amax = std::max(amax, std::fabs(v));
        }
    }
    const double rounding = unorm16 ? width_ * tu::kUnorm16Rounding : tu::kFloatRounding * amax;
    out.band = tu::weight_factor(delta) * (vmax - vmin) + rounding;
    switch (texture_unit_) {
        case ProfileOptions::TextureUnit::Exact: out.value = out.exact; break;
        case ProfileOptions::TextureUnit::H100:
            if (unorm16) {
                out.value = lo_ + width_ * double(tu::filter_unorm16(f.w.data(), codes.data(), 8));
            } else {
                std::array<float, 8> t;
                for (int c = 0; c < 8; ++c) t[std::size_t(c)] = static_cast<float>(q[std::size_t(c)]);
                out.value = double(tu::filter_float(f.w.data(), t.data(), 8, 2));
            }
            break;
        case ProfileOptions::TextureUnit::Admissible: {
            tu::Admissible r(ctx_.render.profile_options.texture_seed, x.x, x.y, x.z);
            const std::array<double, 8> wc = tu::admissible_weights(tu::exact_weights(f.axis), r);
            out.value = 0.0;
            for (int c = 0; c < 8; ++c) out.value += wc[std::size_t(c)] * q[std::size_t(c)];
            out.value += 0.999 * rounding * r.next();
            break;
        }
    }
    return out;
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
    if (texture_unit_ == ProfileOptions::TextureUnit::H100) {  // TextureUnit.h: 1D, normalised, float32 texels
        const texture_unit::AxisRead r = texture_unit::axis_read(texture_unit::unnormalized(texture_unit::to_float32(u), n), n);
        const int w[2] = {texture_unit::kWeightOne - r.a, r.a};
        auto channel = [&](double t0, double t1) {
            const float t[2] = {static_cast<float>(t0), static_cast<float>(t1)};
            return double(texture_unit::filter_float(w, t, 2, 1));
        };
        const glm::dvec4& e0 = table_[std::size_t(r.i0)];
        const glm::dvec4& e1 = table_[std::size_t(r.i1)];
        out.color = glm::dvec3(channel(e0.r, e1.r), channel(e0.g, e1.g), channel(e0.b, e1.b));
        out.opacity = channel(e0.a, e1.a);
        out.alpha = p_.correction == Profile::Correction::Power
                        ? channel(table_alpha_[std::size_t(r.i0)], table_alpha_[std::size_t(r.i1)])
                        : alpha(out.opacity, d);
        return out;
    }
    const double pos = std::clamp(u * double(n) - 0.5, 0.0, double(n - 1));
    const int i = std::min(int(pos), n - 2);
    double w = pos - double(i);
    if (texture_unit_ == ProfileOptions::TextureUnit::Admissible) {  // within the band's 1D tolerance
        texture_unit::Admissible r(ctx_.render.profile_options.texture_seed, pos, 0.25, -1.0);
        w += (0.5 / 256.0 + texture_unit::kNormalizedDelta * double(n)) * r.next();
    }
    const glm::dvec4 e = table_[std::size_t(i)] + w * (table_[std::size_t(i) + 1] - table_[std::size_t(i)]);
    out.color = glm::dvec3(e);
    out.opacity = e.a;
    // Power corrects the entries (VTK: then filtered); the other rules correct the filtered opacity.
    out.alpha = p_.correction == Profile::Correction::Power
                    ? table_alpha_[std::size_t(i)] + w * (table_alpha_[std::size_t(i) + 1] - table_alpha_[std::size_t(i)])
                    : alpha(out.opacity, d);
    return out;
}

glm::dvec3 ProfileIntegrator::gradient(const glm::dvec3& x) const {
    glm::dvec3 g(0.0);
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 e(0.0);
        e[a] = offset_[a];
        if (p_.gradient == Profile::Gradient::CentralInDomain) {  // the reference's: one-sided at the boundary
            glm::dvec3 b = x, c = x;
            b[a] = std::min(x[a] + offset_[a], domain_hi_[a]);
            c[a] = std::max(x[a] - offset_[a], domain_lo_[a]);
            const double w = b[a] - c[a];
            g[a] = w > 0.0 ? (value(b) - value(c)) / w : 0.0;
            continue;
        }
        g[a] = p_.gradient == Profile::Gradient::Forward ? (value(x + e) - value(x)) / offset_[a]
                                                          : (value(x + e) - value(x - e)) / (2.0 * offset_[a]);
    }
    return g;
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

// Seed 001's kernel: the pixel, its band and fault; traced: each sample the kernel takes, at
// t = s (the kernel's distance along its float ray from the origin), its value as the profile's value.
template <class Rec>
PixelValue ProfileIntegrator::seed_kernel(const Ray& ray, Rec& rec) const {
    std::vector<CudaCurvilinearKernel::Sample> samples;
    const Seed001Pixel px = kernel_->pixel(ray, Rec::kOn ? &samples : nullptr);
    PixelValue out;
    out.rgba = px.rgba;
    out.error = px.error;
    out.fault = px.fault;
    if constexpr (Rec::kOn) {
        const glm::dvec3 c = kernel_->frame().center;
        const double h = double(kernel_->frame().step);
        for (const CudaCurvilinearKernel::Sample& s : samples) {
            SampleRecord r{};
            const glm::dvec3 x = c + glm::dvec3(s.point[0], s.point[1], s.point[2]);
            begin_record(rec, r, x, double(s.s), h, lo_ + width_ * double(s.sample));
            r.sample.classified = s.used;
            r.composited = is_composite(ctx_.render.projection);
            r.running = kernel_->frame().xray ? double(s.sum[0]) : 0.0;
            r.accumulated = glm::dvec4(s.sum[0], s.sum[1], s.sum[2], s.sum[3]);
            rec.recorder.record(r);
        }
    }
    return out;
}

std::string ProfileIntegrator::fault_reason(const Ray& ray) const {
    if (!kernel_) return {};
    const Seed001Pixel px = kernel_->pixel(ray);
    return px.fault ? px.why.text() : std::string();
}

template <class Rec>
PixelValue ProfileIntegrator::integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    if (kernel_) return seed_kernel(ray, rec);
    if (lattice_) return slices(ray, intervals, rec);
    PixelValue out;
    const Projection p = ctx_.render.projection;
    switch (accumulation(p)) {
        case Accumulation::Composite: out = composite(ray, intervals, rec); break;
        case Accumulation::Extremum: out = extremum(ray, intervals, takes_maximum(p), rec); break;
        case Accumulation::LineIntegral: out = line_integral(ray, intervals, takes_mean(p), rec); break;
        case Accumulation::FirstHit: break;  // refused (check_profile_applies)
    }
    if (band_) out.error = band(ray, intervals, out.rgba);
    return out;
}

// The texture band (band()): ProfileTextureBand.cpp.

template <class Rec>
PixelValue ProfileIntegrator::composite(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    switch (p_.compositing) {
        case Profile::Compositing::Lerp: return composite_lerp(ray, intervals, rec);
        case Profile::Compositing::OpticalDepth:
            return composite_front_to_back<TransmittanceRule::OpticalDepthSum>(ray, intervals, rec);
        case Profile::Compositing::Product: return composite_front_to_back<TransmittanceRule::Product>(ray, intervals, rec);
        case Profile::Compositing::OpacitySum: break;
    }
    return composite_front_to_back<TransmittanceRule::OpacitySum>(ray, intervals, rec);
}

// Front to back (march/Accumulators.h), the transmittance kept by rule R: a GPU shader's opacity sum
// A += (1 - A) alpha, C += (1 - A) alpha c, the product T *= 1 - alpha, or the reference's optical
// depth; stopping as the profile says after every sample. An opaque sample (alpha >= 1) stops the
// optical-depth and product rules (its optical depth is infinite); under the opacity sum it makes A = 1,
// after which every sample adds 0 (the ray runs on, as a shader's loop does, unless its test stops it).
template <TransmittanceRule R, class Rec>
PixelValue ProfileIntegrator::composite_front_to_back(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const {
    FrontToBack<Scalar, R> acc;
    bool opaque = false;
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
            if constexpr (R == TransmittanceRule::OpacitySum) {
                acc.add(true, false, 0.0, k.alpha, cc);
            } else {  // an opaque sample ends the ray (its optical depth is infinite)
                opaque = k.alpha >= 1.0;
                acc.add(true, opaque, opaque ? 0.0 : -std::log1p(-k.alpha), std::min(k.alpha, 1.0), cc);
            }
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
        return !(opaque || acc.stops(true, p_.termination));
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
