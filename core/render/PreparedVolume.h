// PreparedVolume: everything one volume of a scene builds, in pipeline order
//   volume spec -> volume model (grid + sampler) -> classifier -> gradient -> pre-classified volume ->
//   shader -> sample pipeline -> macrocells -> bounding geometry (+ transform, clip planes, crop) ->
//   integrator,
// built once and then shared read-only by every pixel. PreparedScene (PreparedScene.h) holds one per
// volume of the scene, plus the camera. Only what the volume uses is built (null pointers for the rest).
//
// A volume with a `transform` works in its own space: its rays are the world rays mapped by
// VolumeTransform::local_ray (the same t, so every length stays a world length), its geometry and
// crop planes are intersected with the local ray, and its pipeline maps gradients and the view
// direction back to world space. Clip planes are world-space and cut with the world ray.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/grid/Volume.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/render/Renderer.h"
#include "core/sample/GradientField.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/PreClassifiedVolume.h"
#include "core/sample/ShellSampler.h"
#include "core/sample/VolumeSampler.h"
#include "core/sample/VolumeView.h"
#include "core/scene/Scene.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/ShellCoordinates.h"
#include "geometry/VolumeTransform.h"
#include "transfer/Classifier.h"
#include "transfer/Shader.h"

namespace volref {

class ImageSpaceRenderer;

// A ShellSampler as the pipeline's FieldSampler and GradientSource (world-space differences).
class ShellField final : public FieldSampler, public GradientSource {
public:
    explicit ShellField(const ShellSampler& s) : s_(s) {}
    double value(const glm::dvec3& world) const override { return s_.value(world); }
    glm::dvec3 gradient(const glm::dvec3& world) const override { return s_.gradient(world); }
    const ShellSampler& shell_sampler() const { return s_; }  // its grid (the adaptive integrator's cuts)

private:
    const ShellSampler& s_;
};

// The grid a volume's data live on, and how a point of the volume's space reads it: a Cartesian grid
// (box or mesh bounds) through VolumeSampler, or a beam-space grid (shell bounds) through ShellSampler.
// The samplers refer to `volume`, so a model is filled in place and never copied or moved.
struct VolumeModel {
    VolumeModel() = default;
    VolumeModel(const VolumeModel&) = delete;
    VolumeModel& operator=(const VolumeModel&) = delete;
    // The volume's data: read, generated, or given in memory (VolumeSourceSpec::memory, shared, not
    // copied). volume() is what the samplers refer to.
    std::shared_ptr<const Volume> data;
    const Volume& volume() const { return *data; }
    std::unique_ptr<VolumeSampler> cartesian;
    std::unique_ptr<ShellGrid> shell_grid;
    std::unique_ptr<ShellSampler> shell;
    std::unique_ptr<ShellField> shell_field;
    const FieldSampler* sampler = nullptr;
    double voxel = 1.0;  // the length of one voxel (in the volume's own space) for step_units "voxel"
};

// Fills `out` (a fresh model) for `vs`.
void build_volume_model(const VolumeSpec& vs, VolumeModel& out);

// "volume" for a scene of one volume, "volumes[i]" otherwise (the key path in messages).
std::string volume_key(const Scene& scene, std::size_t index);

// A Cartesian volume's bounding shape (`bounds`: a box, default the domain, or a closed mesh) over
// the data domain [domain_lo, domain_hi], in the volume's own space: added to `geometry` (its id
// returned), and [lo, hi] set to the box of the shape AND the domain. Errors name `key`.bounds.
int add_cartesian_bounds(BoundingGeometry& geometry, const VolumeSpec& vs, const std::string& key,
                         const glm::dvec3& domain_lo, const glm::dvec3& domain_hi, glm::dvec3& lo, glm::dvec3& hi);

// The world box of the volume-space box [lo, hi]: itself, or with a transform the bounds of its 8
// corners mapped to the world (what the default camera frames).
void world_box(const VolumeTransform* transform, const glm::dvec3& lo, const glm::dvec3& hi, glm::dvec3& world_lo,
               glm::dvec3& world_hi);

// The data domain of the whole Cartesian volume whose brick a volume's data are (volref-mpi: a rank
// holds a brick of every volume, VolumeSourceSpec::memory): the rays are bounded, and the default
// camera frames, by the whole volume's domain, so that every rank's intervals are the single process's.
struct WholeDomain {
    glm::dvec3 lo{0.0}, hi{0.0};
};

struct PreparedVolume {
    // `index` is the volume's position in scene.volumes (for messages); `held_bytes` is the memory
    // already held by the volumes prepared before it (core/MemoryLimit.h); `whole`: the data are a
    // brick of that domain (null: the data are the whole volume).
    // Throws volref::Error for a volume that cannot be rendered (naming the key at fault).
    PreparedVolume(const Scene& scene, std::size_t index, const RenderOptions& options, std::size_t held_bytes,
                   const WholeDomain* whole = nullptr);
    PreparedVolume(const PreparedVolume&) = delete;
    PreparedVolume& operator=(const PreparedVolume&) = delete;
    ~PreparedVolume();

    const VolumeSpec& spec;
    VolumeModel model;
    std::optional<VolumeTransform> transform;       // absent: the volume's space is world space
    std::unique_ptr<Classifier> classifier;
    double step = 0.0;                              // this volume's step, world units
    std::unique_ptr<GradientField> gradient_field;  // Cartesian gradients, when used
    const GradientSource* gradient = nullptr;       // null: no stage needs a gradient
    std::unique_ptr<PreClassifiedVolume> preclassified;
    std::unique_ptr<Shader> shader;
    VolumeView view;             // the stages above as one description (VolumeView.h)
    VolumeViewStore view_store;  // what the view holds of its own (float lanes, pre-integration, skipping radii)
    std::unique_ptr<SamplePipeline> pipeline;
    std::unique_ptr<MacrocellGrid> macrocells;      // null: no empty-space skipping
    BoundingGeometry geometry;
    int geometry_id = 0;
    glm::dvec3 view_lo{0.0}, view_hi{0.0};          // the world box this volume adds to the default camera's view
    std::unique_ptr<IntegrationContext> context;
    std::unique_ptr<Integrator> integrator;  // null when an image-space renderer draws the image instead
    // render.profile "vtk-cpu" (VTK's fixed-point mapper, its own internal image and display;
    // VtkFixedPointRenderer.h) and "volpack" (VolPack's shear-warp; VolPackRenderer.h): an image-space
    // renderer (ImageSpaceRenderer.h), called from the render step instead of `integrator`.
    std::unique_ptr<ImageSpaceRenderer> image_space;
    bool packets = true;  // false: the integrator's SIMD packet path does not apply (shading a transformed volume)

    // The ray this volume's geometry, pipeline and integrator take: the world ray, or its local ray.
    Ray volume_ray(const Ray& world) const { return transform ? transform->local_ray(world) : world; }
    // The intervals of a world ray inside the volume (bounds AND domain AND clip planes AND crop), for
    // `count` rays at once (Embree packets); `local` receives volume_ray(rays[i]).
    void intervals(const Ray* rays, int count, Ray* local, std::vector<Interval>* out) const;
    // The bytes this volume holds (its voxels and the derived volumes it built).
    std::size_t bytes = 0;
    // What the set-up noticed that changes nothing but the user should know (RenderStats::warnings).
    std::vector<std::string> warnings;
};

}  // namespace volref
