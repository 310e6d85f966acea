#include "core/render/PreparedScene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/grid/ProceduralField.h"
#include "core/io/VolumeReader.h"
#include "core/integrate/ProfileIntegrator.h"
#include "geometry/ShellTessellation.h"
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
bool skipping_applies(const Scene& scene, const Classifier& classifier, const Volume& volume) {
    const VolumeSpec& vs = scene.volume();
    if (is_shell(vs.bounds)) return false;  // macrocells are Cartesian
    if (scene.render.projection != Projection::Composite) return false;
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

}  // namespace

void build_volume_model(const VolumeSpec& vs, VolumeModel& m) {
    if (!is_shell(vs.bounds)) {
        m.volume = load_volume(vs);
        m.cartesian = std::make_unique<VolumeSampler>(m.volume, vs.interpolation);
        m.sampler = m.cartesian.get();
        m.voxel = std::min({m.volume.spacing.x, m.volume.spacing.y, m.volume.spacing.z});
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
        m.volume = make_procedural_volume(*vs.source.field, [&grid](std::int64_t i, std::int64_t j, std::int64_t k) {
            return grid.sample_position(i, j, k);
        });
    } else {
        m.volume = read_volume(*vs.source.file, vs.source.format);
        m.shell_grid = make_grid(m.volume.dims);
    }
    m.shell = cylinder ? std::make_unique<ShellSampler>(m.volume, vs.bounds.cylinder, vs.interpolation)
                       : std::make_unique<ShellSampler>(m.volume, vs.bounds.sphere, vs.interpolation);
    m.shell_field = std::make_unique<ShellField>(*m.shell);
    m.sampler = m.shell_field.get();
    m.voxel = m.shell_grid->default_gradient_step();
}

PreparedScene::PreparedScene(const Scene& scene_, const RenderOptions& options) : scene(scene_) {
    const VolumeSpec& vs = scene.volume();
    build_volume_model(vs, model);
    const Volume& volume = model.volume;
    const FieldSampler& sampler = *model.sampler;
    classifier = make_classifier(vs, volume);
    step = scene.render.step_units == StepUnits::World ? scene.render.step : scene.render.step * model.voxel;
    const bool shell = model.shell != nullptr;
    if (shell && (vs.gradient.scheme != GradientSpec::Scheme::Default || vs.gradient.cache || vs.gradient.cache_auto))
        throw Error("volume.gradient: shells take differences in world space (docs/shells.md); no scheme or cache applies");
    if (shell && vs.classify == VolumeSpec::Classify::Pre)
        throw Error("volume.classify: pre-classification is not available for shell bounds");

    // Only what the scene uses is built: gradients for shading or gradient-based classification,
    // the pre-classified volume for classify "pre", the shader for shading.
    const bool shades = vs.shading.has_value() &&
                        (scene.render.projection == Projection::Composite || scene.render.projection == Projection::FirstHit);
    // Memory (core/MemoryLimit.h): what is held (the volume) plus what is about to be allocated.
    const std::size_t voxels = volume.values.size(), volume_bytes = voxels * sizeof(double);
    // At most 6 channels (R G B A, Z for first-hit, error) of doubles (docs/conventions.md section 13).
    constexpr std::size_t kMaxImageChannels = 6;
    const std::size_t image_bytes =
        std::size_t(scene.image.width) * std::size_t(scene.image.height) * kMaxImageChannels * sizeof(double);
    check_memory(volume_bytes + image_bytes, "image: " + std::to_string(scene.image.width) + " x " +
                                                 std::to_string(scene.image.height) + " pixels with the volume");
    if (shades || classifier->needs_gradient()) {
        if (shell) {
            gradient = model.shell_field.get();
        } else {
            const GradientSpec g = resolve_gradient_cache(vs.gradient, volume, *classifier, scene.image, step);
            if (g.cache) check_memory(volume_bytes + image_bytes + 3 * volume_bytes, "volume.gradient.cache: the gradient volumes");
            gradient_field = std::make_unique<GradientField>(*model.cartesian, g);
            gradient = gradient_field.get();
        }
    }
    if (vs.classify == VolumeSpec::Classify::Pre)
        check_memory(volume_bytes + image_bytes + 4 * volume_bytes, "volume.classify: the pre-classified volume");
    if (vs.classify == VolumeSpec::Classify::Pre)
        preclassified = std::make_unique<PreClassifiedVolume>(*model.cartesian, *classifier, gradient);
    if (shades) {
        const auto [vmin, vmax] = volume.value_range();
        shader = std::make_unique<Shader>(*vs.shading, scene.lights,
                                          conventions::kZeroGradientRelative * std::max(std::fabs(vmin), std::fabs(vmax)) / model.voxel);
    }
    pipeline = std::make_unique<SamplePipeline>(sampler, *classifier, gradient, preclassified.get(), shader.get());
    // The macrocell grid of empty-space skipping, kept only if some macrocell is empty.
    if (options.empty_space_skipping && skipping_applies(scene, *classifier, volume)) {
        macrocells = std::make_unique<MacrocellGrid>(
            *model.cartesian, *classifier, preclassified ? MacrocellGrid::Classification::Pre : MacrocellGrid::Classification::Post);
        if (macrocells->empty_count() == 0) macrocells.reset();
    }

    // The bounding geometry, and the box the default camera frames.
    if (shell) {
        const bool cylinder = vs.bounds.type == BoundsSpec::Type::Cylindrical;
        const auto box = cylinder ? bounding_box(vs.bounds.cylinder) : bounding_box(vs.bounds.sphere);
        view_lo = box[0];
        view_hi = box[1];
        if (vs.bounds.tessellate > 0) {
            // The mesh may bulge past the shell's box by its chord error: no domain clipping.
            const glm::dvec3 pad(glm::length(box[1] - box[0]));
            volume_id = geometry.add_mesh(cylinder ? tessellate(vs.bounds.cylinder, vs.bounds.tessellate)
                                                   : tessellate(vs.bounds.sphere, vs.bounds.tessellate),
                                          box[0] - pad, box[1] + pad);
        } else {
            volume_id = cylinder ? geometry.add_cylindrical_shell(vs.bounds.cylinder)
                                 : geometry.add_spherical_shell(vs.bounds.sphere);
        }
    } else {
        const glm::dvec3 domain_lo = volume.domain_min(), domain_hi = volume.domain_max();
        if (vs.bounds.type == BoundsSpec::Type::Mesh) {
            const TriangleMesh mesh = read_closed_mesh(vs.bounds.mesh.string());
            glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
            for (const glm::dvec3& p : mesh.vertices) {
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
            view_lo = glm::max(lo, domain_lo);
            view_hi = glm::min(hi, domain_hi);
            volume_id = geometry.add_mesh(mesh, domain_lo, domain_hi);
        } else {
            const glm::dvec3 box_lo = vs.bounds.min.value_or(domain_lo), box_hi = vs.bounds.max.value_or(domain_hi);
            if (!(box_lo.x <= box_hi.x && box_lo.y <= box_hi.y && box_lo.z <= box_hi.z))
                throw Error("volume.bounds: min must not exceed max");
            view_lo = glm::max(box_lo, domain_lo);
            view_hi = glm::min(box_hi, domain_hi);
            volume_id = geometry.add_box(box_lo, box_hi, domain_lo, domain_hi);
        }
    }
    geometry.commit();


    camera = std::make_unique<Camera>(scene.camera, scene.image.width, scene.image.height, view_lo, view_hi);
    context = std::make_unique<IntegrationContext>(IntegrationContext{*pipeline, step, scene.render, macrocells.get()});
    // render.profile: another renderer's discretisation (ProfileIntegrator.h); the reference's own integrators otherwise.
    integrator = scene.render.profile == ProfileId::Reference
                     ? make_integrator(*context)
                     : std::make_unique<ProfileIntegrator>(*context, profile(scene.render.profile), volume, &scene);
}

PreparedScene::~PreparedScene() = default;

std::vector<Interval> PreparedScene::intervals(const Ray& ray) const {
    std::vector<Interval> out;
    geometry.intervals(ray, volume_id, out);
    return out;
}

PixelValue PreparedScene::render_pixel(int x, int y) const {
    const Ray ray = pixel_ray(x, y);
    return integrator->integrate(ray, intervals(ray));
}

PixelValue PreparedScene::trace_pixel(int x, int y, SampleRecorder& recorder) const {
    const Ray ray = pixel_ray(x, y);
    return integrator->integrate_traced(ray, intervals(ray), recorder);
}

}  // namespace volref
