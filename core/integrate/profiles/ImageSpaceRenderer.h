// ImageSpaceRenderer: a mirror profile that is not a ray integrator but draws the image its own way
// (vtk-cpu: VTK's fixed-point mapper on its internal image, VtkFixedPointRenderer.h; volpack: VolPack's
// shear-warp, VolPackRenderer.h). PreparedVolume builds one instead of an Integrator and the render step
// (PreparedScene::pixels) asks it for window pixels by their coordinates, each pixel on its own (any
// thread count, any tile order).
#pragma once
#include <array>
#include <optional>

#include "core/camera/Ray.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/scene/Scene.h"

namespace volref {

class ImageSpaceRenderer {
public:
    virtual ~ImageSpaceRenderer() = default;
    // Window pixel (x, y) (volref's film coordinates, row 0 at the top): premultiplied RGBA and, where
    // writes_error(), the "error" channel. `rec` (optional) records the steps of the pixel, its last
    // row holding the pixel (`accumulated`).
    virtual PixelValue pixel(int x, int y, Recording* rec) const = 0;
    // The window pixel whose centre `ray` passes through.
    virtual std::array<int, 2> pixel_of(const Ray& ray) const = 0;
    virtual bool writes_error() const { return false; }
    // The camera whose pixel rays are this renderer's pixels, when the renderer defines its own view
    // (volpack: rotate and window); the render step's camera is then this one (trace, explain ray).
    virtual std::optional<CameraSpec> view_camera() const { return std::nullopt; }
};

}  // namespace volref
