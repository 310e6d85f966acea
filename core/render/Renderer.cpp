#include "core/render/Renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <limits>
#include <mutex>
#include <thread>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/camera/Camera.h"
#include "core/grid/ProceduralField.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/PacketComposite.h"
#include "core/integrate/SamplePipeline.h"
#include "core/sample/GradientField.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/PreClassifiedVolume.h"
#include "core/io/VolumeReader.h"
#include "core/sample/VolumeSampler.h"
#include "core/sample/ShellSampler.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/ShellCoordinates.h"
#include "geometry/ShellTessellation.h"
#include "geometry/TriangleMesh.h"
#include "transfer/Classifier.h"
#include "transfer/Shader.h"

namespace volref {

Volume load_volume(const VolumeSpec& spec) {
    Volume v;
    if (spec.source.field) {
        v = make_procedural_volume(*spec.source.field, spec.origin.value_or(glm::dvec3(0.0)),
                                   spec.spacing.value_or(glm::dvec3(1.0)));
    } else {
        v = read_volume(*spec.source.file, spec.source.format);
        if (spec.origin) v.origin = *spec.origin;
        if (spec.spacing) v.spacing = *spec.spacing;
    }
    return v;
}

double world_step(const RenderSpec& render, const Volume& volume) {
    if (render.step_units == StepUnits::World) return render.step;
    return render.step * std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
}

GradientSpec resolve_gradient_cache(GradientSpec spec, const Volume& volume, const Classifier& classifier,
                                    const ImageSpec& image, double step) {
    if (!spec.cache_auto) return spec;
    std::size_t visible = 0;
    for (double v : volume.values)
        if (classifier.classify(v, 1.0).opacity > 0.0) ++visible;
    const double voxels = double(volume.values.size());
    const double diagonal = glm::length(volume.domain_max() - volume.domain_min());
    const double per_voxel = double(image.width) * double(image.height) * (diagonal / step) * (double(visible) / voxels) / voxels;
    spec.cache = per_voxel > conventions::kGradientCacheBreakEven;
    spec.cache_auto = false;
    return spec;
}

namespace {

bool is_shell(const BoundsSpec& b) {
    return b.type == BoundsSpec::Type::Cylindrical || b.type == BoundsSpec::Type::Spherical;
}

// A ShellSampler as the pipeline's FieldSampler and GradientSource (world-space differences).
class ShellField final : public FieldSampler, public GradientSource {
public:
    explicit ShellField(const ShellSampler& s) : s_(s) {}
    double value(const glm::dvec3& world) const override { return s_.value(world); }
    glm::dvec3 gradient(const glm::dvec3& world) const override { return s_.gradient(world); }

private:
    const ShellSampler& s_;
};

// Prints "volref: rendering NN%" on stderr every quarter second once a render has run for a second.
class ProgressReporter {
public:
    ProgressReporter(bool enabled, int total) : total_(total) {
        if (enabled) thread_ = std::thread([this] { run(); });
    }
    ~ProgressReporter() {
        {
            std::lock_guard lock(mutex_);
            done_flag_ = true;
        }
        cv_.notify_all();
        if (thread_.joinable()) thread_.join();
    }
    void tile_done() { done_.fetch_add(1, std::memory_order_relaxed); }

private:
    void run() {
        using namespace std::chrono;
        const auto start = steady_clock::now();
        bool printed = false;
        std::unique_lock lock(mutex_);
        while (!cv_.wait_for(lock, milliseconds(250), [this] { return done_flag_; })) {
            const double elapsed = duration<double>(steady_clock::now() - start).count();
            if (elapsed < 1.0) continue;
            std::fprintf(stderr, "\rvolref: rendering %3d%% (%.1f s)", int(100.0 * done_.load() / total_), elapsed);
            printed = true;
        }
        if (printed) std::fprintf(stderr, "\rvolref: rendering 100%%        \n");
    }
    int total_;
    std::atomic<int> done_{0};
    std::mutex mutex_;
    std::condition_variable cv_;
    bool done_flag_ = false;
    std::thread thread_;
};

// Empty-space skipping needs a classifier whose opacity can be 0 on a range of values: not Levoy's
// isovalue contours (see Classifier::may_have_opacity). A classifier that reads |grad f| is trusted
// to give 0 only for a finite |grad f| (g * 0 is NaN for g = inf), so skipping is also off where a
// gradient could overflow: non-finite data, |f| / spacing above 1e150 (every scheme's |grad f| is a
// few times that, whose square must stay finite), a domain so far from the origin that x +- h rounds
// away the spacing, or forward differences on an axis of two voxels (one-sided over x - lo, which can
// be tiny).
bool skipping_applies(const Scene& scene, const Classifier& classifier, const Volume& volume) {
    const VolumeSpec& vs = scene.volume;
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

// The grid a volume's data live on, and how a world point reads it: a Cartesian grid (box or mesh
// bounds) through VolumeSampler, or a beam-space grid (shell bounds) through ShellSampler.
struct VolumeModel {
    Volume volume;
    std::unique_ptr<VolumeSampler> cartesian;
    std::unique_ptr<ShellGrid> shell_grid;
    std::unique_ptr<ShellSampler> shell;
    std::unique_ptr<ShellField> shell_field;
    const FieldSampler* sampler = nullptr;
    double voxel = 1.0;  // the length of one voxel for step_units "voxel"
};

VolumeModel build_volume_model(const VolumeSpec& vs) {
    VolumeModel m;
    if (!is_shell(vs.bounds)) {
        m.volume = load_volume(vs);
        m.cartesian = std::make_unique<VolumeSampler>(m.volume, vs.interpolation);
        m.sampler = m.cartesian.get();
        m.voxel = std::min({m.volume.spacing.x, m.volume.spacing.y, m.volume.spacing.z});
        return m;
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
    return m;
}

Image render_scene(const Scene& scene, const RenderOptions& options) {
    const VolumeSpec& vs = scene.volume;
    const VolumeModel model = build_volume_model(vs);
    const Volume& volume = model.volume;
    const FieldSampler& sampler = *model.sampler;
    const std::unique_ptr<Classifier> classifier = make_classifier(vs, volume);
    const double step = scene.render.step_units == StepUnits::World ? scene.render.step : scene.render.step * model.voxel;
    const bool shell = model.shell != nullptr;
    if (shell && (vs.gradient.scheme != GradientSpec::Scheme::Default || vs.gradient.cache || vs.gradient.cache_auto))
        throw Error("volume.gradient: shells take differences in world space (docs/shells.md); no scheme or cache applies");
    if (shell && vs.classify == VolumeSpec::Classify::Pre)
        throw Error("volume.classify: pre-classification is not available for shell bounds");

    // Only what the scene uses is built: gradients for shading or gradient-based classification,
    // the pre-classified volume for classify "pre", the shader for shading.
    const bool shades = vs.shading.has_value() &&
                        (scene.render.projection == Projection::Composite || scene.render.projection == Projection::FirstHit);
    std::unique_ptr<GradientField> gradient_field;
    const GradientSource* gradient = nullptr;
    if (shades || classifier->needs_gradient()) {
        if (shell) {
            gradient = model.shell_field.get();
        } else {
            gradient_field = std::make_unique<GradientField>(
                *model.cartesian, resolve_gradient_cache(vs.gradient, volume, *classifier, scene.image, step));
            gradient = gradient_field.get();
        }
    }
    std::unique_ptr<PreClassifiedVolume> preclassified;
    if (vs.classify == VolumeSpec::Classify::Pre)
        preclassified = std::make_unique<PreClassifiedVolume>(*model.cartesian, *classifier, gradient);
    std::unique_ptr<Shader> shader;
    if (shades) {
        const auto [vmin, vmax] = volume.value_range();
        shader = std::make_unique<Shader>(*vs.shading, scene.lights,
                                          conventions::kZeroGradientRelative * std::max(std::fabs(vmin), std::fabs(vmax)) / model.voxel);
    }
    const SamplePipeline pipeline(sampler, *classifier, gradient, preclassified.get(), shader.get());
    // The macrocell grid of empty-space skipping, kept only if some macrocell is empty.
    std::unique_ptr<MacrocellGrid> macrocells;
    if (options.empty_space_skipping && skipping_applies(scene, *classifier, volume)) {
        macrocells = std::make_unique<MacrocellGrid>(
            *model.cartesian, *classifier, preclassified ? MacrocellGrid::Classification::Pre : MacrocellGrid::Classification::Post);
        if (macrocells->empty_count() == 0) macrocells.reset();
    }

    // The bounding geometry, and the box the default camera frames.
    BoundingGeometry geometry;
    int volume_id = 0;
    glm::dvec3 view_lo, view_hi;
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

    const int W = scene.image.width, H = scene.image.height;
    const Camera camera(scene.camera, W, H, view_lo, view_hi);
    const IntegrationContext ctx{pipeline, step, scene.render, macrocells.get()};
    const std::unique_ptr<Integrator> integrator = make_integrator(ctx);

    std::vector<std::string> channels{"R", "G", "B", "A"};
    if (integrator->writes_depth()) channels.push_back("Z");
    Image image(W, H, channels);

    const int T = conventions::kTileSize;
    const int tiles_x = (W + T - 1) / T, tiles_y = (H + T - 1) / T;
    ProgressReporter progress(options.progress, tiles_x * tiles_y);
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y), [&](const tbb::blocked_range<int>& r) {
            // Each tile row is integrated in packets of up to kMaxPacketRays pixels.
            std::vector<Interval> intervals[kMaxPacketRays];
            Ray rays[kMaxPacketRays];
            PixelValue values[kMaxPacketRays];
            for (int tile = r.begin(); tile != r.end(); ++tile) {
                const int x0 = (tile % tiles_x) * T, y0 = (tile / tiles_x) * T;
                const int x_end = std::min(x0 + T, W);
                for (int y = y0; y < std::min(y0 + T, H); ++y)
                    for (int xs = x0; xs < x_end; xs += kMaxPacketRays) {
                        const int count = std::min(kMaxPacketRays, x_end - xs);
                        for (int i = 0; i < count; ++i) rays[i] = camera.pixel_ray(xs + i, y);
                        geometry.intervals(rays, count, volume_id, intervals);  // Embree packets
                        if (options.simd)
                            integrator->integrate_packet(rays, intervals, values, count);
                        else
                            for (int i = 0; i < count; ++i) values[i] = integrator->integrate(rays[i], intervals[i]);
                        for (int i = 0; i < count; ++i) {
                            for (int c = 0; c < 4; ++c) image.at(xs + i, y, std::size_t(c)) = values[i].rgba[c];
                            if (integrator->writes_depth()) image.at(xs + i, y, 4) = values[i].depth;
                        }
                    }
                progress.tile_done();
            }
        });
    });
    return image;
}

}  // namespace volref
