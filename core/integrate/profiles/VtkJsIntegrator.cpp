#include "core/integrate/profiles/VtkJsIntegrator.h"

#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/March.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "core/integrate/profiles/Profile.h"
#include "core/integrate/profiles/ProfileIntegrator.h"
#include "transfer/Shader.h"

namespace volref {

namespace {

const std::string kWhere = "render.profile: \"vtk-js\" ";

// vtk.js's colour table is a Uint8ClampedArray filled with 255 c (VolumeMapper.js, renderPiece):
// conversion rounds to nearest, ties to even (ECMAScript ToUint8Clamp), and clamps to [0, 255].
double to_uint8_clamped(double c) {
    const double x = 255.0 * double(float(c));  // c comes from a Float32Array (getTable's tmpTable)
    if (!(x > 0.0)) return 0.0;
    if (x >= 255.0) return 1.0;
    return std::nearbyint(x) / 255.0;  // the default rounding mode: ties to even
}

// GL_LINEAR over N texels with CLAMP_TO_EDGE at coordinate u: texel position u N - 0.5.
template <class T>
T read_linear(const std::vector<T>& table, double u) {
    const int n = int(table.size());
    const double pos = std::clamp(u * double(n) - 0.5, 0.0, double(n - 1));
    const int i = std::min(int(pos), n - 2);
    const double w = pos - double(i);
    return table[std::size_t(i)] + w * (table[std::size_t(i) + 1] - table[std::size_t(i)]);
}

}  // namespace

VtkJsIntegrator::VtkJsIntegrator(const IntegrationContext& ctx, const Volume& volume, const VolumeSpec& spec,
                                 const Scene& scene)
    : OneLoopIntegrator(ctx) {
    const Profile& p = profile(ProfileId::VtkJs);
    check_profile_applies(p, ctx.pipeline, ctx.render);
    const Projection proj = ctx.render.projection;
    if (!is_composite(proj) && !is_extremum(proj))
        throw Error(kWhere + "mirrors the composite, mip and minip projections only");
    if (!ctx.pipeline.view().cartesian) throw Error(kWhere + "needs a Cartesian grid");
    if (spec.bounds.type != BoundsSpec::Type::Box || spec.bounds.min || spec.bounds.max || spec.crop ||
        !spec.clip_planes.empty())
        throw Error(kWhere + "casts rays through the whole texel box (remove volume.bounds, crop and clip_planes)");
    if (spec.interpolation != Interpolation::Trilinear)
        throw Error(kWhere + "samples a linearly filtered texture (volume.interpolation \"trilinear\")");
    if (spec.classification || spec.transfer.domain != TransferSpec::Domain::Data || !spec.transfer.gradient_opacity.empty())
        throw Error(kWhere + "needs a transfer function over the data's values (no classification, "
                             "normalized domain or gradient_opacity)");
    const auto& color = spec.transfer.color;
    const auto& opacity = spec.transfer.opacity;
    if (color.size() < 2 || opacity.size() < 2 || !(color.back()[0] > color.front()[0]) ||
        !(opacity.back()[0] > opacity.front()[0]))
        throw Error(kWhere + "builds its tables over the transfer function's node range: volume.transfer.color "
                             "and .opacity need at least two rows with different values");
    const ProfileOptions& o = ctx.render.profile_options;
    if (!is_composite(proj) && ctx.pipeline.shader())
        throw Error(kWhere + "does not mirror vtk.js's shaded mip/minip (remove volume.shading)");
    if (ctx.pipeline.shader()) {
        if (spec.shading->kl != 0.0 || spec.shading->kc != 1.0)
            throw Error(kWhere + "has no depth cueing (volume.shading.kc 1, kl 0)");
    }

    domain_lo_ = volume.domain_min();
    domain_hi_ = volume.domain_max();
    spacing_ = volume.spacing;
    const glm::dvec3 half = 0.5 * volume.spacing;
    box_lo_ = o.ray_box_domain ? domain_lo_ : domain_lo_ - half;
    box_hi_ = o.ray_box_domain ? domain_hi_ : domain_hi_ + half;
    const glm::dvec3 dims(double(volume.dims[0]), double(volume.dims[1]), double(volume.dims[2]));
    normal_scale_ = o.fixed_normal ? glm::dvec3(1.0) : dims * volume.spacing;
    flip_normal_ = o.flip_normal;
    step_ = ctx.step;
    jitter_ = o.jitter;

    switch (scene.camera.type) {
        case CameraSpec::Type::Perspective:
        case CameraSpec::Type::Orthographic:
            forward_ = glm::normalize(scene.camera.target - scene.camera.eye);
            // The proxy quad: the window rectangle of the texel box's corners (VolumeMapper.js
            // setCameraShaderParameters: boundsDC of getBounds(), the spatial extent, whatever ray_box says).
            // The camera basis and projection as core/camera/Camera.cpp builds the pixel rays.
            if (o.subpixel_bits > 0) {
                orthographic_ = scene.camera.type == CameraSpec::Type::Orthographic;
                eye_ = scene.camera.eye;
                right_ = glm::normalize(glm::cross(forward_, scene.camera.up));
                up_ = glm::cross(right_, forward_);
                tan_half_fov_ = std::tan(scene.camera.fov_y * std::numbers::pi / 360.0);
                half_height_ = scene.camera.height / 2.0;
                image_ = glm::dvec2(double(scene.image.width), double(scene.image.height));
                aspect_ = image_.x / image_.y;
                const glm::dvec3 lo = domain_lo_ - half, hi = domain_hi_ + half;
                quad_lo_ = glm::dvec2(std::numeric_limits<double>::infinity());
                quad_hi_ = -quad_lo_;
                snap_ = true;
                for (int k = 0; k < 8; ++k) {
                    const glm::dvec3 c = glm::dvec3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z) - eye_;
                    const double z = glm::dot(c, forward_);
                    // A corner at or behind the eye's plane: vtk.js's quad is then unbounded; not mirrored
                    // (the rays stay at the pixel centres).
                    if (!orthographic_ && !(z > 0.0)) snap_ = false;
                    const double sx = orthographic_ ? half_height_ * aspect_ : z * tan_half_fov_ * aspect_;
                    const double sy = orthographic_ ? half_height_ : z * tan_half_fov_;
                    const glm::dvec2 w = 0.5 * (glm::dvec2(glm::dot(c, right_) / sx, glm::dot(c, up_) / sy) + 1.0) * image_;
                    quad_lo_ = glm::min(quad_lo_, w);
                    quad_hi_ = glm::max(quad_hi_, w);
                }
                // RoundInt of the fixed-point position: to nearest, ties to even.
                const double f = std::ldexp(1.0, o.subpixel_bits);
                for (int a = 0; a < 2; ++a) {
                    snapped_lo_[a] = std::nearbyint(quad_lo_[a] * f) / f;
                    snapped_hi_[a] = std::nearbyint(quad_hi_[a] * f) / f;
                    if (!(snapped_hi_[a] > snapped_lo_[a])) snap_ = false;  // no fragments: nothing to mirror
                }
            }
            break;
        case CameraSpec::Type::Matrices:
            forward_ = -glm::normalize(glm::dvec3(scene.camera.view[0][2], scene.camera.view[1][2], scene.camera.view[2][2]));
            break;
        case CameraSpec::Type::Default: forward_ = glm::dvec3(0.0, 0.0, -1.0); break;
    }

    // The tables (VolumeMapper.js renderPiece): getTable(range[0], range[1], 1024) samples the function at
    // range[0] + i / 1023 (range[1] - range[0]); opacity entries 1 - (1 - a)^(sampleDistance / unitDistance)
    // stored as float, colour entries as Uint8ClampedArray(255 c).
    color_lo_ = color.front()[0];
    color_width_ = color.back()[0] - color.front()[0];
    opacity_lo_ = opacity.front()[0];
    opacity_width_ = opacity.back()[0] - opacity.front()[0];
    const Classifier& c = ctx.pipeline.classifier();
    const double factor = step_ / c.unit_distance();
    color_table_.resize(kTableEntries);
    opacity_table_.resize(kTableEntries);
    opacity_raw_table_.resize(kTableEntries);
    for (int i = 0; i < kTableEntries; ++i) {
        const double f = double(i) / double(kTableEntries - 1);
        const glm::dvec3 rgb = c.classify(color_lo_ + f * color_width_, 0.0).color;
        color_table_[std::size_t(i)] = glm::dvec3(to_uint8_clamped(rgb.r), to_uint8_clamped(rgb.g), to_uint8_clamped(rgb.b));
        const double a = double(float(c.classify(opacity_lo_ + f * opacity_width_, 0.0).opacity));
        opacity_table_[std::size_t(i)] = double(float(1.0 - std::pow(1.0 - a, factor)));
        opacity_raw_table_[std::size_t(i)] = a;
    }
    if (!o.mip_correction && !is_composite(proj)) opacity_table_ = opacity_raw_table_;
}

VtkJsIntegrator::~VtkJsIntegrator() = default;

double VtkJsIntegrator::table_opacity(double v) const {
    return read_linear(opacity_table_, (v - opacity_lo_) / opacity_width_);
}

glm::dvec3 VtkJsIntegrator::table_color(double v) const {
    return read_linear(color_table_, (v - color_lo_) / color_width_);
}

// The texture read clamps to the edge texels: positions past the domain read its boundary.
double VtkJsIntegrator::value(const glm::dvec3& x) const {
    return ctx_.pipeline.sampler().value(glm::clamp(x, domain_lo_, domain_hi_));
}

// vtkVolumeFS.glsl rayIntersectVolumeDistances: the slab test against the box (in index space there,
// the same t here); the entry is clamped to the ray's origin (computeRayDistances, dists.x = max(0, ..)).
bool VtkJsIntegrator::box(const Ray& ray, double& t0, double& t1) const {
    t0 = 0.0;
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        const double inv = 1.0 / ray.direction[a];
        double u = (box_lo_[a] - ray.origin[a]) * inv, w = (box_hi_[a] - ray.origin[a]) * inv;
        if (std::isnan(u) || std::isnan(w)) {  // parallel to the slab, on its plane
            u = -std::numeric_limits<double>::infinity();
            w = std::numeric_limits<double>::infinity();
        }
        t0 = std::max(t0, std::min(u, w));
        t1 = std::min(t1, std::max(u, w));
    }
    return t1 > t0 && t1 > 0.0;
}

// The ray vtk.js casts through the pixel whose centre `ray` passes through: the
// rasteriser interpolates vertexVCVSOutput (the quad's corners unprojected onto the near plane,
// vtkVolumeVS.glsl) over the quad as snapped to its sub-pixel grid (SwiftShader SetupRoutine: the plane
// equations are set up from the fixed-point corners X, Y and the corners' own varyings). Per axis the
// pixel at window position p gets the varying of lo + (p - snap(lo)) (hi - lo) / (snap(hi) - snap(lo));
// the fragment shader casts from that point (normalize(vertexVCVSOutput) in perspective, -z in parallel
// projection). Same line as the ray through that window point from the eye (or the eye's plane).
Ray VtkJsIntegrator::rasterised(const Ray& ray) const {
    glm::dvec2 ndc;
    if (orthographic_) {
        const glm::dvec3 c = ray.origin - eye_;
        ndc = glm::dvec2(glm::dot(c, right_) / (half_height_ * aspect_), glm::dot(c, up_) / half_height_);
    } else {
        const double z = glm::dot(ray.direction, forward_);
        ndc = glm::dvec2(glm::dot(ray.direction, right_) / (z * tan_half_fov_ * aspect_),
                         glm::dot(ray.direction, up_) / (z * tan_half_fov_));
    }
    for (int a = 0; a < 2; ++a) {
        const double p = 0.5 * (ndc[a] + 1.0) * image_[a];
        const double u = quad_lo_[a] + (p - snapped_lo_[a]) * (quad_hi_[a] - quad_lo_[a]) / (snapped_hi_[a] - snapped_lo_[a]);
        ndc[a] = 2.0 * u / image_[a] - 1.0;
    }
    Ray r;
    if (orthographic_) {
        r.origin = eye_ + (ndc.x * half_height_ * aspect_) * right_ + (ndc.y * half_height_) * up_;
        r.direction = forward_;
    } else {
        r.origin = ray.origin;
        r.direction = glm::normalize(forward_ + (ndc.x * tan_half_fov_ * aspect_) * right_ + (ndc.y * tan_half_fov_) * up_);
    }
    return r;
}

namespace {

// GLSL pow(x, e) in the shader as SwiftShader evaluates it: exp2(e log2(x)) with
// log2(0) = -127, so pow(0, e) = 2^(-127 e) and not 0: a sample whose table opacity is exactly 1 counts
// 1 - 2^(-127 e) for a fraction e of a step (measured: e = 0.00262 gives 0.206 where pow would give 1).
// For x > 0 the correctly rounded pow (SwiftShader's is within a few float ulps of it).
double glsl_pow(double x, double e) { return x > 0.0 ? std::pow(x, e) : std::exp2(-127.0 * e); }

}  // namespace

// getColorForDependentComponents (one component): the tables, the drop below EPSILON = 0.001, then
// applyAllLightning -> applySurfaceShadowLighting when the scene is shaded.
VtkJsIntegrator::Sample VtkJsIntegrator::color_at(const glm::dvec3& x, const glm::dvec3& ray_dir) const {
    Sample s;
    const double v = value(x);
    if (!std::isfinite(v)) return s;
    const double a = table_opacity(v);
    if (a < 0.001) return s;
    s.alpha = a;
    s.color = table_color(v);
    if (ctx_.pipeline.shader()) s.color = shade(s.color, x, ray_dir);
    return s;
}

// computeNormalForDensity: central differences of the texture at +-1 texel, times inverseSpacing, then
// normalISToVCMatrix (diag(dims * spacing) times the rotations: the shipped scaling bug), normalised; a
// zero gradient gives a zero normal (no diffuse or specular, ambient only). applySurfaceShadowLighting:
// ndotL = N.L with L the light's direction of travel; two-sided lighting negates a negative ndotL;
// where ndotL > 0: diffuse += ndotL colour, R = normalize(L - 2 ndotL N), specular += max(0, V.R)^p colour.
glm::dvec3 VtkJsIntegrator::shade(const glm::dvec3& c, const glm::dvec3& x, const glm::dvec3& ray_dir) const {
    const Shader& sh = *ctx_.pipeline.shader();
    const ShadingSpec& sp = sh.spec();
    glm::dvec3 g(0.0);
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 e(0.0);
        e[a] = spacing_[a];
        g[a] = (value(x + e) - value(x - e)) / spacing_[a];
    }
    glm::dvec3 n = g * normal_scale_;
    const double len = glm::length(n);
    n = len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);
    if (flip_normal_) n = -n;
    const double power = sp.n == 0.0 ? 1.0 : sp.n;  // VolumeMapper.js: specularPower 0 is sent as 1
    glm::dvec3 diffuse(0.0), specular(0.0);
    for (const LightSpec& l : sh.lights()) {
        const glm::dvec3 L = l.type == LightSpec::Type::Headlight ? forward_ : -l.direction;
        double ndotl = glm::dot(n, L);
        if (ndotl < 0.0 && sp.two_sided) ndotl = -ndotl;
        if (ndotl > 0.0) {
            diffuse += ndotl * l.color;
            const double vdotr = glm::dot(-ray_dir, glm::normalize(L - 2.0 * ndotl * n));
            if (vdotr > 0.0) specular += std::pow(vdotr, power) * l.color;
        }
    }
    return c * (diffuse * sp.kd + sp.ka) + specular * sp.ks;
}

template <class Rec>
PixelValue VtkJsIntegrator::integrate_impl(const Ray& ray_in, const std::vector<Interval>&, Rec& rec) const {
    PixelValue out;
    Ray ray = ray_in;
    const double dl = glm::length(ray.direction);
    ray.direction /= dl;  // t below in world units along a unit direction
    if (snap_) ray = rasterised(ray);
    double t0 = 0.0, t1 = 0.0;
    if (!box(ray, t0, t1)) return out;  // the fragment is discarded: the background stays
    const double h = step_;
    auto record = [&](double t, double alpha, const glm::dvec4& acc) {
        if constexpr (Rec::kOn) {
            SampleRecord r{};
            rec.begin(r, (t - 0.5 * h) / dl, (t + 0.5 * h) / dl);
            r.t = t / dl;
            r.length = h / dl;
            r.sample.position = ray.at(t);
            r.sample.value = value(ray.at(t));
            r.sample.classified = true;
            r.composited = true;
            r.alpha = alpha;
            r.accumulated = acc;
            rec.recorder.record(r);
        } else {
            (void)t, (void)alpha, (void)acc;
        }
    };

    // The samples: march()'s HullPartialEnds placement over [t0, t1] (the entry, t0 + (j + k) h while
    // j + k + 1 < R, the exit; R = (t1 - t0) / h; R <= 1: the entry alone).
    MarchOptions o;
    o.step = h;
    o.placement.kind = MarchPlacement::Kind::HullPartialEnds;
    o.placement.first = jitter_;
    const std::vector<Interval> hull{Interval{t0, t1}};
    using End = MarchSample::End;
    if (is_composite(ctx_.render.projection)) {
        const glm::dvec3 d = ray.direction;
        // Front to back with the opacity sum (march/Accumulators.h): C += (1 - A) a c, A += (1 - A) a.
        FrontToBack<Scalar, TransmittanceRule::OpacitySum> acc;
        auto add = [&](const Sample& s, double a) {
            const double c[3] = {s.color.r, s.color.g, s.color.b};
            acc.add(true, false, 0.0, a, c);
        };
        auto accumulated = [&] { return glm::dvec4(acc.color(0), acc.color(1), acc.color(2), acc.alpha()); };
        bool thin = false;
        march(hull, o, [&](const MarchSample& m) {
            const Sample s = color_at(ray.at(m.t), d);
            if (m.end == End::Only) {  // "handle very thin volumes": alpha for R steps, the pixel (a c, a)
                const double a = 1.0 - glsl_pow(1.0 - s.alpha, m.steps);
                out.rgba = glm::dvec4(s.color * a, a);
                record(m.t, a, out.rgba);
                thin = true;
                return false;
            }
            if (m.end == End::Entry) {  // the first sample counts for `jitter` of a step
                add(s, 1.0 - glsl_pow(1.0 - s.alpha, m.steps));
                record(m.t, acc.alpha(), accumulated());
                return true;
            }
            if (m.end == End::Exit) {  // the exit sample, for the remaining fraction, unless A reached 0.99
                if (!(acc.alpha() < 0.99)) return false;
                const double a = 1.0 - glsl_pow(1.0 - s.alpha, m.steps);
                add(s, a);
                record(m.t, a, accumulated());
                return false;
            }
            add(s, s.alpha);
            record(m.t, s.alpha, accumulated());
            if (acc.alpha() > 0.99) {  // alpha set to 1, the colour kept; the loop ends
                const double C[3] = {acc.color(0), acc.color(1), acc.color(2)};
                acc.resume(C, 1.0);
                return false;
            }
            return true;
        });
        if (thin) return out;
        const glm::dvec3 C(acc.color(0), acc.color(1), acc.color(2));
        const double A = acc.alpha();
        // gl_FragData = (C / A, A), blended with (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) over the cleared
        // float framebuffer: (C / A) A, NaN where A = 0.
        out.rgba = glm::dvec4((C / A) * A, A);
        return out;
    }

    // mip / minip: the same positions, every one read alike.
    const bool maximum = takes_maximum(ctx_.render.projection);
    auto better = [&](double v, double best) { return maximum ? v > best : v < best; };
    double best = 0.0;
    march(hull, o, [&](const MarchSample& m) {
        const double v = value(ray.at(m.t));
        if (m.end == End::Entry || m.end == End::Only || better(v, best)) best = v;
        record(m.t, 0.0, glm::dvec4(0.0));
        return true;
    });
    if (!std::isfinite(best)) return out;
    const double a = table_opacity(best);
    if (a < 0.001) return out;  // getColorForDependentComponents returns vec4(0)
    out.rgba = glm::dvec4(a * table_color(best), a);
    return out;
}

}  // namespace volref
