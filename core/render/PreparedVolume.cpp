#include "core/render/PreparedVolume.h"

#include "transfer/TransferFunction.h"

#include <cstdio>
#include <algorithm>
#include <optional>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/grid/ProceduralField.h"
#include "core/integrate/packet/FastProfile.h"
#include "core/camera/Camera.h"
#include "core/integrate/profiles/ProfileIntegrator.h"
#include "core/integrate/profiles/VtkJsIntegrator.h"
#include "core/integrate/profiles/VolPackRenderer.h"
#include "core/integrate/profiles/VtkFixedPointRenderer.h"
#include "core/io/VolumeReader.h"
#include "core/scene/SceneNames.h"
#include "geometry/ClipPlanes.h"
#include "geometry/CropRegions.h"
#include "geometry/ShellTessellation.h"
#include "geometry/TetrahedralMesh.h"
#include "geometry/TriangleMesh.h"

namespace volref {

namespace {

bool is_shell(const BoundsSpec& b) {
    return b.type == BoundsSpec::Type::Cylindrical || b.type == BoundsSpec::Type::Spherical;
}

// Empty-space skipping needs a classifier whose opacity can be 0 on a range of values: not Levoy's
// isovalue contours (see Classifier::may_have_opacity). A classifier that reads |grad f| is trusted
// to give 0 only for a finite |grad f| (g * 0 is NaN for g = inf), so skipping is also off where a
// gradient could overflow: non-finite data, |f| / spacing above 1e150 (every scheme's |grad f| is a
// few times that, whose square must stay finite), a domain so far from the origin that x +- h rounds
// away the spacing, or forward differences on an axis of two voxels (one-sided over x - lo, which can
// be tiny).
bool skipping_applies(const VolumeSpec& vs, const RenderSpec& render, const Classifier& classifier, const Volume& volume) {
    if (is_shell(vs.bounds)) return false;  // macrocells are Cartesian
    if (!is_composite(render.projection)) return false;
    if (vs.classification && vs.classification->type == ClassificationSpec::Type::Isovalue) return false;
    if (!classifier.needs_gradient()) return true;
    const auto [vmin, vmax] = volume.value_range();
    const double h = std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
    const double far = std::max({glm::length(volume.domain_min()), glm::length(volume.domain_max())});
    if (!(std::isfinite(vmin) && std::isfinite(vmax))) return false;
    if (!(std::max(std::fabs(vmin), std::fabs(vmax)) / h <= 1e150)) return false;
    if (!(far <= 0x1p40 * h)) return false;
    if (vs.gradient.scheme == GradientSpec::Scheme::Forward)
        for (int a = 0; a < 3; ++a)
            if (volume.dims[a] == 2) return false;
    return true;
}

// mip / minip skip macrocells whose values cannot beat a ray's extremum so far: on the SIMD path of
// the fixed step (ExtremumIntegrator's packets: Cartesian trilinear), reference or fast profile. A
// volume with non-finite voxels gets the grid too but ExtremumIntegrator takes its scalar path and
// never reads it (the rare case pays for a grid; the common one does not scan the voxels twice).
bool extremum_skipping_applies(const VolumeSpec& vs, const RenderSpec& render, const RenderOptions& options,
                               const VolumeSampler* sampler) {
    if (is_shell(vs.bounds) || !sampler || !options.simd) return false;
    if (!is_extremum(render.projection)) return false;
    if (render.integrator != IntegrationMethod::Fixed) return false;
    if (!render.reference_integrators() && render.profile != ProfileId::Fast) return false;
    return sampler->interpolation() == Interpolation::Trilinear;
}

}  // namespace

std::string volume_key(const Scene& scene, std::size_t index) {
    return scene.volumes.size() == 1 ? "volume" : "volumes[" + std::to_string(index) + "]";
}

int add_cartesian_bounds(BoundingGeometry& geometry, const VolumeSpec& vs, const std::string& key,
                         const glm::dvec3& domain_lo, const glm::dvec3& domain_hi, glm::dvec3& lo, glm::dvec3& hi) {
    if (vs.bounds.type == BoundsSpec::Type::Mesh || vs.bounds.type == BoundsSpec::Type::Tetrahedra) {
        // Tetrahedra: the union's boundary, a closed surface handed to the same mesh path
        // (geometry/TetrahedralMesh.h).
        const bool tetrahedra = vs.bounds.type == BoundsSpec::Type::Tetrahedra;
        const TriangleMesh mesh = tetrahedra ? read_tetrahedral_bounds(vs.bounds.mesh.string())
                                             : read_closed_mesh(vs.bounds.mesh.string());
        glm::dvec3 mlo(std::numeric_limits<double>::infinity()), mhi(-std::numeric_limits<double>::infinity());
        for (const glm::dvec3& p : mesh.vertices) {
            mlo = glm::min(mlo, p);
            mhi = glm::max(mhi, p);
        }
        lo = glm::max(mlo, domain_lo);
        hi = glm::min(mhi, domain_hi);
        return geometry.add_mesh(mesh, domain_lo, domain_hi, tetrahedra ? Closedness::Cycle : Closedness::Manifold);
    }
    const glm::dvec3 box_lo = vs.bounds.min.value_or(domain_lo), box_hi = vs.bounds.max.value_or(domain_hi);
    if (!(box_lo.x <= box_hi.x && box_lo.y <= box_hi.y && box_lo.z <= box_hi.z))
        throw Error(key + ".bounds: min must not exceed max");
    lo = glm::max(box_lo, domain_lo);
    hi = glm::min(box_hi, domain_hi);
    return geometry.add_box(box_lo, box_hi, domain_lo, domain_hi);
}

namespace {

// The box a profile's rays are clipped to (Profile::RayBox): the domain [grid_lo, grid_hi], the texel
// box (the domain grown by spacing / 2 on every side) or the profile's own box; reads outside the
// domain are clamped to it (ProfileIntegrator::value). `warnings` gets a line when volume.bounds reaches past the
// domain (the rays are clipped to the domain there).
int add_profile_bounds(BoundingGeometry& geometry, const VolumeSpec& vs, const std::string& key, const Profile& profile,
                       const Volume& volume, const glm::dvec3& grid_lo, const glm::dvec3& grid_hi, glm::dvec3& lo,
                       glm::dvec3& hi, std::vector<std::string>& warnings) {
    if (profile.ray_box != Profile::RayBox::Domain) {
        if (vs.bounds.type != BoundsSpec::Type::Box || vs.bounds.min || vs.bounds.max)
            throw Error(std::string("render.profile.ray_box: the profile's ray box replaces ") + key +
                        ".bounds (remove one of them)");
        const bool texel = profile.ray_box == Profile::RayBox::Texel;
        lo = texel ? grid_lo - 0.5 * volume.spacing : profile.box[0];
        hi = texel ? grid_hi + 0.5 * volume.spacing : profile.box[1];
        return geometry.add_box(lo, hi, lo, hi);
    }
    if (vs.bounds.type == BoundsSpec::Type::Box && ((vs.bounds.min && glm::any(glm::lessThan(*vs.bounds.min, grid_lo))) ||
                                                    (vs.bounds.max && glm::any(glm::greaterThan(*vs.bounds.max, grid_hi)))))
        warnings.push_back(key + ".bounds: reaches past the grid's domain; rays are clipped to the domain (render.profile's "
                                 "ray_box \"texel\" or a box of its own samples beyond it, reads clamped to the domain)");
    return add_cartesian_bounds(geometry, vs, key, grid_lo, grid_hi, lo, hi);
}

}  // namespace

void world_box(const VolumeTransform* transform, const glm::dvec3& lo, const glm::dvec3& hi, glm::dvec3& world_lo,
               glm::dvec3& world_hi) {
    if (!transform) {
        world_lo = lo;
        world_hi = hi;
        return;
    }
    world_lo = glm::dvec3(std::numeric_limits<double>::infinity());
    world_hi = -world_lo;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 p = transform->to_world(glm::dvec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z));
        world_lo = glm::min(world_lo, p);
        world_hi = glm::max(world_hi, p);
    }
}

void build_volume_model(const VolumeSpec& vs, VolumeModel& m) {
    if (!is_shell(vs.bounds)) {
        m.data = share_volume(vs);
        const Volume& v = *m.data;
        m.cartesian = std::make_unique<VolumeSampler>(v, vs.interpolation);
        m.sampler = m.cartesian.get();
        m.voxel = std::min({v.spacing.x, v.spacing.y, v.spacing.z});
        return;
    }
    if (vs.origin) throw Error("volume.origin: not used with shell bounds (the shell places the samples)");
    if (vs.spacing) throw Error("volume.spacing: not used with shell bounds (the shell places the samples)");
    const bool cylinder = vs.bounds.type == BoundsSpec::Type::Cylindrical;
    auto make_grid = [&](const std::array<std::int64_t, 3>& dims) {
        return cylinder ? std::make_unique<ShellGrid>(vs.bounds.cylinder, dims)
                        : std::make_unique<ShellGrid>(vs.bounds.sphere, dims);
    };
    if (vs.source.field) {
        m.shell_grid = make_grid(vs.source.field->dims);
        const ShellGrid& grid = *m.shell_grid;
        m.data = std::make_shared<const Volume>(make_procedural_volume(
            *vs.source.field, [&grid](std::int64_t i, std::int64_t j, std::int64_t k) { return grid.sample_position(i, j, k); }));
    } else {
        m.data = share_volume(vs);  // a file or memory: the shell places the samples, not origin and spacing
        m.shell_grid = make_grid(m.data->dims);
    }
    m.shell = cylinder ? std::make_unique<ShellSampler>(*m.data, vs.bounds.cylinder, vs.interpolation)
                       : std::make_unique<ShellSampler>(*m.data, vs.bounds.sphere, vs.interpolation);
    m.shell_field = std::make_unique<ShellField>(*m.shell);
    m.sampler = m.shell_field.get();
    m.voxel = m.shell_grid->default_gradient_step();
}

PreparedVolume::PreparedVolume(const Scene& scene, std::size_t index, const RenderOptions& options, std::size_t held_bytes,
                               const WholeDomain* whole)
    : spec(scene.volumes.at(index)) {
    const VolumeSpec& vs = spec;
    const std::string key = volume_key(scene, index);
    try {
        // The volumes before this one stay in memory: the reader's checks count them too.
        const HeldMemory earlier(held_bytes);
        build_volume_model(vs, model);
    } catch (const Error& e) {
        // The model's messages name keys as "volume.KEY"; in a list of volumes, name the element.
        const std::string what = e.what();
        if (key != "volume" && what.rfind("volume.", 0) == 0) throw Error(key + what.substr(6));
        throw;
    }
    if (vs.transform) transform.emplace(*vs.transform);
    const Volume& volume = model.volume();
    if (scene.render.profile == ProfileId::VolPack) {
        // VolPack's shear-warp: VolPack's own classification and shading from
        // render.profile_options (no transfer function, geometry or sample pipeline); the view is its own.
        bytes = volume.values.bytes() + volume.values.size() * (sizeof(float) + 3);  // the voxels' opacity, code, gradient
        check_memory(held_bytes + bytes, key + ": VolPack's classified voxels");
        image_space = std::make_unique<VolPackRenderer>(volume, *scene.render.profile_options.volpack, scene.image.width,
                                                        scene.image.height);
        view_lo = volume.domain_min();
        view_hi = volume.domain_max();
        return;
    }
    const FieldSampler& sampler = *model.sampler;
    classifier = make_classifier(vs, volume);

    // One voxel in world units: the smallest world length of the grid's spacing vectors (the spacing
    // itself without a transform; for shells, the beam-space step times the transform's smallest
    // stretch of an axis).
    double voxel = model.voxel;
    if (transform) {
        double shortest = std::numeric_limits<double>::infinity();  // min over axes of |A e_a s_a| (shells: s_a = 1)
        for (int a = 0; a < 3; ++a) {
            glm::dvec3 e(0.0);
            e[a] = model.cartesian ? volume.spacing[a] : 1.0;
            shortest = std::min(shortest, transform->world_length(e));
        }
        voxel = model.cartesian ? shortest : voxel * shortest;
    }
    step = scene.render.step_units == StepUnits::World ? scene.render.step : scene.render.step * voxel;

    const bool shell = model.shell != nullptr;
    if (shell && (vs.gradient.scheme != GradientSpec::Scheme::Default || vs.gradient.cache || vs.gradient.cache_auto))
        throw Error(key + ".gradient: shells take differences in world space (docs/shells.md); no scheme or cache applies");
    if (shell && vs.classify == VolumeSpec::Classify::Pre)
        throw Error(key + ".classify: pre-classification is not available for shell bounds");
    if (transform && vs.classify == VolumeSpec::Classify::Pre && classifier->needs_gradient())
        throw Error(key + ".classify: pre-classification of a transformed volume cannot use |grad f| (it would be "
                          "measured in the volume's own space); use \"post\" or a classification without gradients");
    if (!scene.render.reference_integrators() && transform)
        throw Error(key + ".transform: only render.profile \"reference\" (with no rules set over it) renders transformed volumes");
    if (scene.render.profile == ProfileId::Fast) {
        // The fast profile's float packets (FastProfile.h); the integrators check the volume.
        const Projection p = scene.render.projection;
        if (!is_composite(p) && !is_extremum(p))
            fast_profile_unavailable("this scene's projection is not one of them");
        if (scene.render.integrator != IntegrationMethod::Fixed) fast_profile_unavailable("this scene asks for the adaptive integrator");
        if (scene.render.profile_options.preintegration > 0 && !is_composite(p))
            throw Error("render.profile_options.preintegration: pre-integrated segments composite (the projection "
                        "\"composite\"); this scene's projection is \"" + std::string(scene_names::name_of(scene_names::kProjections, p)) + "\"");
    }

    // Only what the scene uses is built: gradients for shading or gradient-based classification,
    // the pre-classified volume for classify "pre", the shader for shading.
    const bool shades = vs.shading.has_value() && shades_samples(scene.render.projection);
    // Memory (core/MemoryLimit.h): what is held (earlier volumes, this volume) plus what is about to
    // be allocated.
    // The voxels are held in the file's type (VoxelArray); the derived grids (gradient cache,
    // pre-classified volume) are f64.
    const std::size_t voxels = volume.values.size(), volume_bytes = volume.values.bytes(), f64_bytes = voxels * sizeof(double);
    bytes = volume_bytes;
    // At most 6 channels (R G B A, Z for first-hit, error) of doubles (docs/conventions.md section 13).
    constexpr std::size_t kMaxImageChannels = 6;
    const std::size_t image_bytes =
        std::size_t(scene.image.width) * std::size_t(scene.image.height) * kMaxImageChannels * sizeof(double);
    const std::size_t held = held_bytes + volume_bytes + image_bytes;
    check_memory(held, "image: " + std::to_string(scene.image.width) + " x " + std::to_string(scene.image.height) +
                           " pixels with the volume" + (scene.volumes.size() == 1 ? std::string() : "s"));
    if (shades || classifier->needs_gradient()) {
        if (shell) {
            gradient = model.shell_field.get();
        } else {
            const GradientSpec g = resolve_gradient_cache(vs.gradient, volume, *classifier, scene.image, step);
            if (g.cache) {
                check_memory(held + 3 * f64_bytes, key + ".gradient.cache: the gradient volumes");
                bytes += 3 * f64_bytes;
            }
            gradient_field = std::make_unique<GradientField>(*model.cartesian, g);
            gradient = gradient_field.get();
        }
    }
    if (vs.classify == VolumeSpec::Classify::Pre) {
        check_memory(held_bytes + bytes + image_bytes + 4 * f64_bytes, key + ".classify: the pre-classified volume");
        preclassified = std::make_unique<PreClassifiedVolume>(*model.cartesian, *classifier, gradient);
        bytes += 4 * f64_bytes;
    }
    if (shades) {
        const auto [vmin, vmax] = volume.value_range();
        shader = std::make_unique<Shader>(*vs.shading, scene.lights,
                                          conventions::kZeroGradientRelative * std::max(std::fabs(vmin), std::fabs(vmax)) / voxel);
    }
    // The volume's one description (VolumeView.h). make_classifier builds a TransferFunction exactly
    // when the spec names no other classification.
    view = describe_volume(volume, model.cartesian.get(), model.shell_grid.get(),
                           vs.classification ? nullptr : static_cast<const TransferFunction*>(classifier.get()),
                           gradient_field.get(), shader.get(), preclassified != nullptr);
    pipeline = std::make_unique<SamplePipeline>(sampler, *classifier, gradient, preclassified.get(), shader.get(),
                                                transform ? &*transform : nullptr, &view);
    // The macrocell grid of empty-space skipping, kept only if some macrocell is empty; for mip and
    // minip (the fixed step's SIMD path), the grid's value bounds (SegmentWalk.h, extremum mode).
    // The grid's bytes (MacrocellGrid::bytes_for, an upper bound; with the composite packets' radii)
    // are checked before it is built and counted while it is kept.
    auto grid_bytes = [&](bool octant_radii) {
        const std::size_t b = MacrocellGrid::bytes_for(volume.dims.data(), octant_radii);
        check_memory(held_bytes + bytes + image_bytes + b, key + ": the macrocell grid of empty-space skipping");
        return b;
    };
    if (options.empty_space_skipping && skipping_applies(vs, scene.render, *classifier, volume)) {
        const std::size_t b = grid_bytes(is_composite(scene.render.projection));
        macrocells = std::make_unique<MacrocellGrid>(
            *model.cartesian, *classifier, preclassified ? MacrocellGrid::Classification::Pre : MacrocellGrid::Classification::Post);
        if (macrocells->empty_count() == 0) macrocells.reset();
        else bytes += b;
        // The composite packets' skipping radii, where the fixed-step composite's packets apply.
        const bool fixed_composite = is_composite(scene.render.projection) && scene.render.integrator == IntegrationMethod::Fixed &&
                                     (scene.render.reference_integrators() || scene.render.profile == ProfileId::Fast);
        if (macrocells && fixed_composite && !view.packet_unavailable(true, scene.render.order))
            describe_skipping(view, *macrocells, view_store);
    } else if (options.empty_space_skipping && extremum_skipping_applies(vs, scene.render, options, model.cartesian.get())) {
        bytes += grid_bytes(false);
        macrocells = std::make_unique<MacrocellGrid>(*model.cartesian, *classifier, MacrocellGrid::Classification::Post);
    }

    // The bounding geometry (in the volume's own space), and the box the default camera frames: over
    // the data's domain, or the whole volume's whose brick they are.
    const glm::dvec3 domain_lo = whole ? whole->lo : volume.domain_min(), domain_hi = whole ? whole->hi : volume.domain_max();
    glm::dvec3 lo, hi;
    const Profile resolved = resolve_profile(scene.render);  // the preset with the scene's rules
    if (vs.bounds.type == BoundsSpec::Type::Tetrahedra && vs.bounds.overlap == BoundsSpec::Overlap::Count &&
        (scene.render.reference_integrators() || scene.render.profile == ProfileId::Fast || resolved.placement != Profile::Placement::Slices))
        throw Error(key + ".bounds.overlap: \"count\" (each tetrahedron drawn on its own) is a slicer's: it applies to "
                          "render.profile placement \"slices\" (ray casters take the union)");
    // A rule set to another value than its preset's that this scene never reads is said, not dropped.
    if (const ProfileRules& rules = scene.render.profile_rules; !rules.empty()) {
        const nlohmann::json base = profile_rules_json(profile(scene.render.profile)), mine = profile_rules_json(resolved);
        const bool composite = is_composite(scene.render.projection);
        const bool shaded = composite && vs.shading.has_value();
        for (const std::string& k : rules.keys) {
            const bool compositing_rule = k == "correction" || k == "correction_floor" || k == "density_scale" || k == "compositing" || k == "termination";
            const bool shading_rule = k == "normal" || k == "gradient" || k == "gradient_offset" || k == "gradient_offset_texture" || k == "clamp_shaded";
            if (((compositing_rule && !composite) || (shading_rule && !shaded)) && base.value(k, nlohmann::json()) != mine.value(k, nlohmann::json()))
                warnings.push_back("render.profile." + k + ": not read by this scene (" +
                                   (compositing_rule ? "the projection does not composite" : "the scene is not a shaded composite") + ")");
        }
    }
    if (shell) {
        const bool cylinder = vs.bounds.type == BoundsSpec::Type::Cylindrical;
        const auto box = cylinder ? bounding_box(vs.bounds.cylinder) : bounding_box(vs.bounds.sphere);
        lo = box[0];
        hi = box[1];
        if (vs.bounds.tessellate > 0) {
            // The mesh may bulge past the shell's box by its chord error: no domain clipping.
            const glm::dvec3 pad(glm::length(box[1] - box[0]));
            geometry_id = geometry.add_mesh(cylinder ? tessellate(vs.bounds.cylinder, vs.bounds.tessellate)
                                                     : tessellate(vs.bounds.sphere, vs.bounds.tessellate),
                                            box[0] - pad, box[1] + pad);
        } else {
            geometry_id = cylinder ? geometry.add_cylindrical_shell(vs.bounds.cylinder)
                                   : geometry.add_spherical_shell(vs.bounds.sphere);
        }
    } else {
        geometry_id = add_profile_bounds(geometry, vs, key, resolved, volume, domain_lo, domain_hi, lo, hi, warnings);
    }
    geometry.commit();
    world_box(transform ? &*transform : nullptr, lo, hi, view_lo, view_hi);
    // the samples one ray may take here, before any ray is cast (conventions::kMaxSamplesPerRay):
    // no interval inside the volume's world box is longer than its diagonal.
    if (const double diagonal = glm::length(view_hi - view_lo); !(diagonal / step <= conventions::kMaxSamplesPerRay)) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "a step of %.6g world units takes %.3g samples along %s's diagonal of %.6g (at most 2^32 per ray)",
                      step, diagonal / step, key.c_str(), diagonal);
        throw Error(std::string("render.step: ") + buf);
    }
    // A profile's own ray box (texel or given) does not move the default camera: it frames the domain.
    if (!shell && resolved.ray_box != Profile::RayBox::Domain)
        world_box(transform ? &*transform : nullptr, domain_lo, domain_hi, view_lo, view_hi);

    context = std::make_unique<IntegrationContext>(IntegrationContext{*pipeline, step, scene.render, macrocells.get()});
    if (scene.render.profile == ProfileId::Fast) {
        context->lanes = IntegrationContext::Lanes::Float;
        // The float lanes' voxels and rows (and the pre-integration table), where the packets apply; the
        // integrator refuses the scene otherwise (FastProfile.h).
        const bool composite = is_composite(scene.render.projection);
        if (!view.packet_unavailable(composite, scene.render.order)) {
            describe_float_lanes(view, composite, view_store);
            if (composite && scene.render.profile_options.preintegration > 0)
                make_preintegrated(view, step, scene.render.profile_options.preintegration, view_store);
        }
    }
    // render.profile: another renderer's discretisation (ProfileIntegrator.h); the reference's own integrators otherwise.
    if (scene.render.reference_integrators() || scene.render.profile == ProfileId::Fast) {
        integrator = make_integrator(*context);
    } else if (const Profile& p = resolved; p.renderer == Profile::Renderer::VtkFixedPoint) {
        check_profile_applies(p, *pipeline, scene.render);
        if (vs.bounds.type != BoundsSpec::Type::Box || vs.bounds.min || vs.bounds.max)
            throw Error(std::string("render.profile: \"") + p.name +
                        "\" casts rays through the whole grid (VTK's mapper has no bounds): remove volume.bounds");
        image_space = std::make_unique<vtkcpu::VtkFixedPointRenderer>(volume, *classifier, shader.get(), scene.render.projection,
                                                                      step, scene.camera, scene.image, vs.interpolation);
    } else if (p.renderer == Profile::Renderer::VtkJs) {
        integrator = std::make_unique<VtkJsIntegrator>(*context, volume, vs, scene);
    } else {
        // placement "slices": the surfaces are placed from the frame's camera (for one volume
        // PreparedScene's, which frames this volume's box) and the geometry's box.
        std::optional<Camera> camera;
        SliceFrame frame;
        std::optional<TriangleMesh> overlap;
        if (p.placement == Profile::Placement::Slices) {
            if (transform) throw Error("volume.transform: placement \"slices\" places its surfaces in the volume's own space (remove the transform)");
            camera.emplace(scene.camera, scene.image.width, scene.image.height, view_lo, view_hi);
            frame = SliceFrame{&*camera, &scene.camera, lo, hi};
            if (vs.bounds.type == BoundsSpec::Type::Tetrahedra && vs.bounds.overlap == BoundsSpec::Overlap::Count) {
                overlap.emplace(read_tetrahedral_bounds(vs.bounds.mesh.string()));
                frame.overlap = &*overlap;
            }
        }
        integrator = std::make_unique<ProfileIntegrator>(*context, p, volume, &vs.bounds, camera ? &frame : nullptr);  // the preset or custom rules
    }
    // The SIMD packet paths shade and measure gradients in the grid's space: not for a transformed
    // volume whose gradient is used.
    packets = !(transform && (shader || classifier->needs_gradient()));
}

PreparedVolume::~PreparedVolume() = default;

void PreparedVolume::intervals(const Ray* rays, int count, Ray* local, std::vector<Interval>* out) const {
    for (int i = 0; i < count; ++i) local[i] = volume_ray(rays[i]);
    geometry.intervals(local, count, geometry_id, out);
    for (int i = 0; i < count; ++i) {
        if (spec.crop) crop_intervals(local[i], *spec.crop, out[i]);
        if (!spec.clip_planes.empty()) clip_intervals(rays[i], spec.clip_planes, out[i]);
    }
}

}  // namespace volref
