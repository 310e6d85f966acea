// PreparedScene: everything a render of one scene builds: one PreparedVolume per volume
// (PreparedVolume.h: volume model -> classifier -> gradient -> pre-classified volume -> shader ->
// sample pipeline -> macrocells -> bounding geometry -> integrator), the camera, and for several
// volumes the MultiVolumeIntegrator that mixes them; built once and then shared read-only by every
// pixel. render_scene (Renderer.h) loops over the pixels; `volref trace` and `volref explain ray`
// follow one pixel through the very same objects; each volref-mpi rank builds one over its bricks
// (cli/mpi/Frame.h) and integrates its spans of the rays through the same volumes and mix.
#pragma once
#include <array>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Camera.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/mix/MultiVolumeIntegrator.h"
#include "core/integrate/profiles/ImageSpaceRenderer.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/render/PreparedVolume.h"
#include "core/render/Renderer.h"
#include "core/scene/Scene.h"

namespace volref {

struct PreparedScene {
    // Throws volref::Error for a scene that cannot be rendered (naming the key at fault). `whole`
    // (volref-mpi): volume k's data are a brick of the domain whole[k] (PreparedVolume.h WholeDomain);
    // empty: every volume's data are the whole volume.
    PreparedScene(const Scene& scene, const RenderOptions& options, std::span<const WholeDomain> whole = {});
    PreparedScene(const PreparedScene&) = delete;
    PreparedScene& operator=(const PreparedScene&) = delete;
    ~PreparedScene();

    const Scene& scene;
    std::vector<std::unique_ptr<PreparedVolume>> volumes;  // scene.volumes, in order
    glm::dvec3 view_lo{0.0}, view_hi{0.0};                  // the box the default camera frames (every volume's)
    std::unique_ptr<Camera> camera;
    std::unique_ptr<MultiVolumeIntegrator> multi;           // several volumes only

    // The first (for most scenes the only) volume.
    const PreparedVolume& volume() const { return *volumes.front(); }
    const Integrator& integrator() const { return *volumes.front()->integrator; }
    // The image-space renderer that draws the image instead of the integrators (vtk-cpu), or null.
    const ImageSpaceRenderer* image_space() const { return volumes.front()->image_space.get(); }
    bool writes_depth() const { return !image_space() && integrator().writes_depth(); }
    bool writes_error() const { return image_space() ? image_space()->writes_error() : integrator().writes_error(); }
    bool writes_fault() const { return !image_space() && volumes.size() == 1 && integrator().writes_fault(); }

    // Scratch space of one thread for integrate(): each volume's local rays and intervals.
    struct Scratch {
        std::vector<std::array<Ray, kMaxPacketRays>> rays;
        std::vector<std::array<std::vector<Interval>, kMaxPacketRays>> intervals;
        std::vector<std::array<PixelValue, kMaxPacketRays>> values;
        // One pixel's rays, intervals and values across the volumes, for the mix (several volumes).
        std::vector<Ray> pixel_rays;
        std::vector<std::vector<Interval>> pixel_intervals;
        std::vector<PixelValue> pixel_values;
    };
    // The pixels of `count` world rays (count <= kMaxPacketRays): every volume's intervals, then its
    // integrator (the SIMD packet path when `simd` and the volume allows it), then for several volumes
    // the mix. The result does not depend on `simd` beyond the packet path's documented rounding.
    void integrate(const Ray* rays, int count, PixelValue* out, bool simd, Scratch& scratch) const;

    // Pixels (x[i], y[i]) of the image, i < count <= kMaxPacketRays: the camera's rays integrated
    // (integrate), or the image-space renderer's pixels. The render step's one call (a block of pixels:
    // PixelBlocks.h).
    void pixels(const int* x, const int* y, int count, PixelValue* out, bool simd, Scratch& scratch) const;

    // The one volume `volref trace` and `volref explain ray` follow; an Error for several volumes.
    const PreparedVolume& traced_volume() const;

    // Pixel (x, y)'s ray (x right, y down from the top-left corner).
    Ray pixel_ray(int x, int y) const { return camera->pixel_ray(x, y); }
    // The ray's intervals in the first volume (in that volume's ray: see PreparedVolume::volume_ray).
    std::vector<Interval> intervals(const Ray& ray) const;
    // One pixel by the scalar path (equal to the rendered pixel within the SIMD path's rounding).
    PixelValue render_pixel(int x, int y) const;
    // render_pixel by the same loop, reporting every sample to `recorder` (SampleRecorder.h); one
    // volume only.
    PixelValue trace_pixel(int x, int y, SampleRecorder& recorder) const;
};

}  // namespace volref
