// VolPackRenderer: the `volpack` profile, VolPack 1.0b3's vpRenderClassifiedVolume / vpRenderRawVolume
// reproduced as the library runs (docs/conventions.md, section "VolPack"; the arithmetic in VolPack.h).
//
// Like vtk-cpu it is an image-space renderer (ImageSpaceRenderer.h). Built once per frame, it does what
// VolPack does before its warp:
//  1. factors the view (principal axis, shear, intermediate image; VolPack.h factor_view);
//  2. computes every voxel's fields (8-bit gradient magnitude, 13-bit normal code), classifies it (the
//     tables' product, truncated to a byte, thresholded, corrected with exponent L) and shades it by
//     its code's shade-table entry;
//  3. composites the intermediate image: one ray per intermediate pixel (u, v) through the principal
//     axis's slices front to back, each slice resampled bilinearly with the slice's float weights
//     (opacity and premultiplied colour interpolated), composited when the resampled opacity exceeds
//     VP_MIN_VOXEL_OPACITY, the ray stopped once its opacity reaches VP_MAX_RAY_OPACITY, all in float;
//     then the depth-cue fix-up. Each intermediate pixel's sequence of float operations is VolPack's,
//     whatever order the pixels are computed in (rows on TBB threads).
// pixel(x, y) is then VolPack's 2D warp of that pixel: the scanline's trapezoid counts and start state
// (VPAffineImageOverlap, the warp's 31-bit fractions) precomputed per output row, the pixel's fractions
// stepped in closed form, the four taps weighted from the 64-entry table, truncated to 8 bits.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"
#include "core/integrate/profiles/ImageSpaceRenderer.h"
#include "core/integrate/profiles/VolPack.h"
#include "core/scene/Scene.h"

namespace volref {

class VolPackRenderer final : public ImageSpaceRenderer {
public:
    // Throws volref::Error naming the key VolPack refuses (an 8-bit volume only; a view it can factor).
    VolPackRenderer(const Volume& volume, const VolPackSpec& spec, int width, int height);

    PixelValue pixel(int x, int y, Recording* rec) const override;
    std::array<int, 2> pixel_of(const Ray& ray) const override;
    bool writes_error() const override { return true; }

    const volpack::View& view() const { return view_; }
    const VolPackSpec& spec() const { return spec_; }

    // Intermediate pixel (u, v) as VolPack holds it after compositing and depth cueing: colour on the
    // 0 .. 255 scale (channels of them), opacity in [0, 1]. Outside the image: 0.
    struct IntermediatePixel {
        float color[3] = {0.0f, 0.0f, 0.0f};
        float opacity = 0.0f;
    };
    IntermediatePixel intermediate(int u, int v) const;

    // One output pixel's warp worked out (`volref explain volpack-warp`).
    struct Warp {
        bool covered = false;          // false: the scanline's zero run (VolPack writes 0)
        double in_x = 0.0, in_y = 0.0; // the pixel mapped back into the intermediate image (exact)
        int u = 0, v = 0;              // the top-left tap
        int xfrac = 0, yfrac = 0;      // the stepped 31-bit fractions
        int x_index = 0, y_index = 0;  // their weight-table indices (top 6 bits)
        float weight[4] = {};          // taps (u, v), (u + 1, v), (u, v + 1), (u + 1, v + 1)
        bool inside[4] = {};           // the tap lies in the intermediate image
        float sum[4] = {};             // colour channels (0 .. 255), then opacity (0 .. 1)
        int bytes[4] = {};             // the truncated bytes: colour channels, then alpha
        bool tie = false;              // some byte lies within kTieWindow of rounding the other way
    };
    Warp warp(int x, int y) const;

    // One voxel's classification and shading (`volref explain volpack-voxel`).
    struct Voxel {
        int scalar = 0, gradient = 0, code = 0;
        std::array<int, 3> delta{0, 0, 0};    // the central differences
        volpack::VoxelClass cls;
        std::array<double, 3> normal{0.0, 0.0, 0.0};  // the code's normal (object space)
        float shade[3] = {};                  // the shade-table entry (0 .. 255)
    };
    Voxel voxel(std::int64_t x, std::int64_t y, std::int64_t z) const;

    // A volref camera (type "matrices") whose pixel (x, y) ray is VolPack's output pixel (x, y) through
    // the volume's world space (voxel index i at origin + i spacing): what the same continuous scene's
    // reference render uses (conventions "VolPack", the view as a camera).
    CameraSpec camera() const;
    std::optional<CameraSpec> view_camera() const override { return camera(); }

private:
    void classify();
    void composite();
    void depth_cue();
    void prepare_warp();
    void composite_pixel(int u, int v, float* color, float& opacity) const;

    VolPackSpec spec_;
    volpack::View view_;
    int width_ = 0, height_ = 0;
    std::array<std::int64_t, 3> dims_{};
    glm::dvec3 origin_{0.0}, spacing_{1.0};  // the volume's world placement (pixel_of, camera)
    std::vector<std::uint8_t> scalars_;
    volpack::VoxelNormals normals_;
    std::vector<float> opacity_;      // per voxel (x fastest): corrected opacity, 0 when not kept (sample order: q / 255)
    std::vector<float> shade_table_;  // channels per normal code
    std::vector<float> voxel_shade_;  // normal_code "exact": channels per voxel
    // Per slice composited (n-th from the front), what is the same for every intermediate pixel: its slice
    // k, its place in the intermediate image (ceil(slice_u) - 1, ...), its four float weights TL, BL, TR, BR
    // and its depth-cue factor (VPRenderAffine).
    struct Slice {
        int k = 0, u = 0, v = 0;
        float weight[4] = {};
        float dc = 1.0f;
    };
    std::vector<Slice> slices_;
    std::array<std::int64_t, 3> stride_{};  // object-index strides of the permuted axes (i, j, k)
    std::vector<IntermediatePixel> image_;  // intermediate_width x intermediate_height, row v = j
    struct Scanline {
        int begin = 0, end = 0;        // covered pixels [begin, end): the edge and full counts
        int in_x_int = 0, in_y_int = 0, xfrac = 0, yfrac = 0;  // the state at x = begin
        double in_x = 0.0, in_y = 0.0;
    };
    std::vector<Scanline> scanlines_;
    int xfrac_incr_ = 0, yfrac_incr_ = 0, in_x_incr_int_ = 0, in_y_incr_int_ = 0;
    double in_x_incr_ = 0.0, in_y_incr_ = 0.0, denom_ = 0.0;
};

// The continuous scene a VolPack scene discretises (`volref explain volpack-scene`; docs/conventions.md,
// "VolPack", the continuous scene): the same volume and pixels (camera()), the scalar table as a
// transfer function's opacity rows at the integer values (one voxel's opacity seen face on: opacity unit
// distance one voxel), the gradient table as gradient_opacity rows over |grad f| = VolPack's field,
// white colour, VolPack's one material and lights as Blinn-Phong (N . L = VolPack's n . l: volref's
// light is the reverse of VolPack's object-space light vector), composited by the reference at `step`
// voxels. Throws volref::Error naming the key that has no continuous form in volref (depth cueing, a
// material whose channels are not one colour, lights whose colours do not sum to one white ambient).
Scene volpack_continuous_scene(const Scene& scene, const VolPackRenderer& renderer, double step);

}  // namespace volref
