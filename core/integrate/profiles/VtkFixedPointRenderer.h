// VtkFixedPointRenderer: the `vtk-cpu` profile, VTK 9.1's vtkFixedPointVolumeRayCastMapper (its CPU mapper)
// reproduced step by step in its own fixed-point arithmetic (conventions section 9, docs/gpu-checking.md).
//
// It is an image-space renderer, not a ray integrator: PreparedVolume builds it instead of an
// Integrator for render.profile "vtk-cpu" (Profile::Renderer::VtkFixedPoint), and the render step
// (PreparedScene::pixels) asks it for window pixels by their coordinates. The mapper does three
// things a per-ray integrator does not:
//  1. It casts rays on an internal image: one ray per window pixel centre inside the volume's
//     projected bounding box widened by 2 pixels (ImageOrigin, ImageInUseSize), and inside each
//     row only between the box's edges pulled in by about a pixel (RowBounds); elsewhere 0.
//  2. Along a ray everything is 15-bit fixed point (one unit = 1/32768 unless said otherwise):
//     positions and steps in voxels (x 32767, rounded), trilinear weights from the fraction bits,
//     scalars (shift / scale to 0 .. 32767, truncated), colour and opacity tables of 32768 entries,
//     per-voxel normals encoded in 16 bits (vtkSphericalDirectionEncoder) with shading tables,
//     front-to-back compositing of unsigned integers, and a stop once the remaining transparency is
//     below 0xff / 0x7fff.
//  3. It draws the internal image through a linearly filtered texture whose texel centres are put
//     on the quad's corners (the image is stretched by M / (M - 1)), scaled by 2 (0x7fff is 1/2 of
//     a 16-bit texel).
// The pixel volref writes for window pixel (x, y) is step 3 applied to the up to four internal
// pixels it blends (each a ray of steps 1-2), so every output pixel is computed on its own (any
// thread count, any tile order). Its compositing is VTK's 15-bit integer arithmetic (composite()
// below), the one compositing formula outside march/Accumulators.h: it is that mapper's, not volref's.
//
// Sources (Kitware/VTK, 9.1): vtkFixedPointVolumeRayCastMapper.{h,cxx} (ComputeRayInfo,
// ClipRayAgainstVolume, ComputeRowBounds, UpdateColorTable, ComputeGradients, UpdateShadingTable),
// vtkFixedPointVolumeRayCastHelper.h (the macros), vtkFixedPointVolumeRayCastCompositeHelper.cxx,
// ...CompositeShadeHelper.cxx, ...MIPHelper.cxx, vtkSphericalDirectionEncoder.cxx,
// vtkEncodedGradientShader.cxx, vtkOpenGLRayCastImageDisplayHelper.cxx, and
// vtkRenderer::ResetCameraClippingRange (the near plane the samples are counted from).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/camera/Ray.h"
#include "core/grid/Volume.h"
#include "core/integrate/profiles/ImageSpaceRenderer.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/scene/Scene.h"

namespace volref {

class Classifier;
class Shader;

namespace vtkcpu {

inline constexpr unsigned kShift = 15;          // VTKKW_FP_SHIFT
inline constexpr unsigned kMask = 0x7fffu;      // VTKKW_FP_MASK
inline constexpr double kScale = 32767.0;       // VTKKW_FP_SCALE
inline constexpr unsigned kTerminate = 0xffu;   // the ray stops once the remaining transparency < 0xff
inline constexpr int kTableSize = 32768;        // float data: 32768-entry tables
inline constexpr int kDirections = 65536;       // vtkSphericalDirectionEncoder: 256 x 256 codes

// ToFixedPointPosition: unsigned(v * 32767 + 0.5) (v a float, the product in double).
unsigned fixed_position(float v);
// ToFixedPointDirection: the magnitude as fixed_position, bit 31 set for d >= 0.
unsigned fixed_direction(float d);
// pos += dir in fixed point (FixedPointIncrement).
void fixed_increment(unsigned pos[3], const unsigned dir[3]);

// The eight corner weights of VTKKWRCHelper_ComputeWeights + InterpolateScalar for the fraction
// bits w2 = pos & 0x7fff, w1 = 0x7fff - w2 (so w1 + w2 = 32767): wXY = (0x4000 + wX wY) >> 15, then
// corner = (0x4000 + wXY wZ) >> 15, corners in VTK's order A (x, y, z), B (+x), C (+y), D (+x+y),
// E (+z), F (+x+z), G (+y+z), H (+x+y+z).
std::array<unsigned, 8> trilinear_weights(const unsigned pos[3]);
// (0x7fff + sum_i v_i w_i) >> 15.
unsigned interpolate(const std::array<unsigned, 8>& corners, const std::array<unsigned, 8>& w);

// LookupColorUS: opacity a = table entry; colour c_k = (C_k a + 0x7fff) >> 15 (premultiplied).
struct Sample15 {
    unsigned short rgb[3] = {0, 0, 0};
    unsigned short a = 0;
};
Sample15 lookup(const unsigned short* color_table, const unsigned short* opacity_table, unsigned index);
// VTKKWRCHelper_CompositeColorAndCheckEarlyTermination: color_k += (s_k R + 0x7fff) >> 15,
// R = (R (0x7fff - s_a) + 0x7fff) >> 15. Returns true when the ray stops (R < 0xff).
bool composite(unsigned color[3], unsigned short& remaining, const Sample15& s);

// vtkSphericalDirectionEncoder::GetEncodedDirection of a unit (or zero) vector.
unsigned encode_direction(const float n[3]);
// Its DecodedGradientTable entry for `code`.
glm::vec3 decode_direction(unsigned code);

// The camera's clipping range as vtkRenderer::ResetCameraClippingRange sets it for a box (the
// volume's domain), 24-bit depth buffer (near-plane tolerance 0.001), ClippingRangeExpansion 0.5.
std::array<double, 2> clipping_range(const glm::dvec3& eye, const glm::dvec3& forward, double fov_y_degrees,
                                     const glm::dvec3& box_lo, const glm::dvec3& box_hi);

// One internal ray's result: 15-bit premultiplied RGBA as the mapper stores it (0 .. 32767).
struct Pixel15 {
    std::array<unsigned short, 4> rgba{0, 0, 0, 0};
};

class VtkFixedPointRenderer final : public ImageSpaceRenderer {
public:
    // Throws volref::Error naming the scene key vtk-cpu cannot mirror.
    VtkFixedPointRenderer(const Volume& volume, const Classifier& classifier, const Shader* shader, Projection projection,
           double step, const CameraSpec& camera, const ImageSpec& image, const Interpolation interpolation);

    // The displayed value of window pixel (x, y) (volref's film coordinates, row 0 at the top),
    // premultiplied RGBA in [0, 1). `rec` (optional) records the samples of each internal ray the
    // pixel blends, then one row holding the blend (its `accumulated` is the returned value).
    glm::dvec4 display(int x, int y, Recording* rec) const;
    PixelValue pixel(int x, int y, Recording* rec) const override { return PixelValue{display(x, y, rec)}; }
    // The window pixel whose centre `ray` passes through (the camera's pixel_ray inverted).
    std::array<int, 2> pixel_of(const Ray& ray) const override;
    // Internal pixel (i, j) (VTK's coordinates: from the image origin, row 0 at the bottom).
    Pixel15 cast(int i, int j, Recording* rec) const;

    // The internal image's layout (ComputeRowBounds), for tests and docs.
    struct Layout {
        int origin[2] = {0, 0};
        int in_use[2] = {0, 0};
        bool any = false;                  // false: the box is outside the view, nothing drawn
        std::vector<int> row_lo, row_hi;   // per internal row; lo > hi: no ray cast in that row
    };
    const Layout& layout() const { return layout_; }
    double near_plane() const { return near_; }
    const std::vector<unsigned short>& opacity_table() const { return opacity_; }
    const std::vector<unsigned short>& color_table() const { return color_; }
    float table_shift() const { return shift_; }
    float table_scale() const { return scale_; }

private:
    struct RayInfo {
        unsigned pos[3] = {0, 0, 0}, dir[3] = {0, 0, 0};
        unsigned steps = 0;
    };
    RayInfo ray_info(int i, int j) const;
    void build_tables(const Classifier& classifier);
    void build_gradients();
    void build_shading(const Shader& shader);
    glm::dvec3 world(const glm::dvec3& voxel) const { return origin_ + voxel * spacing_; }
    glm::dvec3 voxel(const glm::dvec3& w) const { return (w - origin_) / spacing_; }
    void build_view_to_voxels();

    std::array<std::int64_t, 3> dims_{};
    glm::dvec3 origin_{0.0}, spacing_{1.0};
    Projection projection_;
    bool shaded_ = false;
    double step_ = 0.0;
    int width_ = 0, height_ = 0;
    glm::dvec3 eye_{0.0}, forward_{0.0}, right_{0.0}, up_{0.0};
    double tan_half_ = 0.0, aspect_ = 1.0, near_ = 0.0, far_ = 0.0;
    float view_to_voxels_[16] = {};  // ViewToVoxelsArray: row-major, as the mapper copies it to float
    float shift_ = 0.0f, scale_ = 1.0f;
    std::vector<unsigned> scalars_;          // per voxel: unsigned(scale (v + shift))
    std::vector<float> data_;                // shaded: the data cast to float (the gradient's input)
    std::vector<unsigned short> color_;      // 3 per entry
    std::vector<unsigned short> opacity_;    // composite: corrected for the step
    std::vector<unsigned short> normals_;    // per voxel: encoded direction
    std::vector<unsigned short> diffuse_, specular_;  // 3 per direction code
    Layout layout_;
};

}  // namespace vtkcpu
}  // namespace volref
