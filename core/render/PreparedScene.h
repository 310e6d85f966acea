// PreparedScene: everything a render of one scene builds, in pipeline order
//   scene -> volume model (grid + sampler) -> classifier -> gradient -> pre-classified volume ->
//   shader -> sample pipeline -> macrocells -> bounding geometry -> camera -> integrator,
// built once and then shared read-only by every pixel. render_scene (Renderer.h) loops over the
// pixels; `volref trace` and `volref explain ray` follow one pixel through the very same objects.
// Only what the scene uses is built (null pointers for the rest).
#pragma once
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Camera.h"
#include "core/grid/Volume.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/SampleRecorder.h"
#include "core/integrate/SamplePipeline.h"
#include "core/render/Renderer.h"
#include "core/sample/GradientField.h"
#include "core/sample/MacrocellGrid.h"
#include "core/sample/PreClassifiedVolume.h"
#include "core/sample/ShellSampler.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/Scene.h"
#include "geometry/BoundingGeometry.h"
#include "geometry/ShellCoordinates.h"
#include "transfer/Classifier.h"
#include "transfer/Shader.h"

namespace volref {

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

// The grid a volume's data live on, and how a world point reads it: a Cartesian grid (box or mesh
// bounds) through VolumeSampler, or a beam-space grid (shell bounds) through ShellSampler.
// The samplers refer to `volume`, so a model is filled in place and never copied or moved.
struct VolumeModel {
    VolumeModel() = default;
    VolumeModel(const VolumeModel&) = delete;
    VolumeModel& operator=(const VolumeModel&) = delete;
    Volume volume;
    std::unique_ptr<VolumeSampler> cartesian;
    std::unique_ptr<ShellGrid> shell_grid;
    std::unique_ptr<ShellSampler> shell;
    std::unique_ptr<ShellField> shell_field;
    const FieldSampler* sampler = nullptr;
    double voxel = 1.0;  // the length of one voxel for step_units "voxel"
};

// Fills `out` (a fresh model) for `vs`.
void build_volume_model(const VolumeSpec& vs, VolumeModel& out);

struct PreparedScene {
    // Throws volref::Error for a scene that cannot be rendered (naming the key at fault).
    PreparedScene(const Scene& scene, const RenderOptions& options);
    PreparedScene(const PreparedScene&) = delete;
    PreparedScene& operator=(const PreparedScene&) = delete;
    ~PreparedScene();

    const Scene& scene;
    VolumeModel model;
    std::unique_ptr<Classifier> classifier;
    double step = 0.0;  // world units
    std::unique_ptr<GradientField> gradient_field;  // Cartesian gradients, when used
    const GradientSource* gradient = nullptr;       // null: no stage needs a gradient
    std::unique_ptr<PreClassifiedVolume> preclassified;
    std::unique_ptr<Shader> shader;
    std::unique_ptr<SamplePipeline> pipeline;
    std::unique_ptr<MacrocellGrid> macrocells;      // null: no empty-space skipping
    BoundingGeometry geometry;
    int volume_id = 0;
    glm::dvec3 view_lo{0.0}, view_hi{0.0};          // the box the default camera frames
    std::unique_ptr<Camera> camera;
    std::unique_ptr<IntegrationContext> context;
    std::unique_ptr<Integrator> integrator;

    // Pixel (x, y)'s ray (x right, y down from the top-left corner) and its intervals in the volume.
    Ray pixel_ray(int x, int y) const { return camera->pixel_ray(x, y); }
    std::vector<Interval> intervals(const Ray& ray) const;
    // One pixel by the scalar path (equal to the rendered pixel within the SIMD path's rounding).
    PixelValue render_pixel(int x, int y) const;
    // render_pixel by the same loop, reporting every sample to `recorder` (SampleRecorder.h).
    PixelValue trace_pixel(int x, int y, SampleRecorder& recorder) const;
};

}  // namespace volref
