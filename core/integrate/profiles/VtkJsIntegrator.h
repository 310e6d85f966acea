// VtkJsIntegrator: the `vtk-js` profile: vtk.js 37.4.3's volume ray caster
// (Rendering/OpenGL/VolumeMapper.js and its fragment shader Rendering/OpenGL/glsl/vtkVolumeFS.glsl.js,
// npm @kitware/vtk.js) reproduced as shipped, in double arithmetic, from the scene volref renders.
// docs/conventions.md section 9, "vtk-js", states every formula with the vtk.js lines it follows; in
// short (h the step in world units, l the opacity unit distance, n the dims, s the spacing):
//   - each pixel's ray is the one vtk.js's rasteriser interpolates: vtk.js draws a
//     screen-space quad over the window rectangle of the texel box's 8 projected corners
//     (VolumeMapper.js boundsDC, vtkVolumeVS.glsl) and takes the ray origin and direction from the
//     varying vertexVCVSOutput; the rasteriser snaps the quad's corners to 1 / 2^b of a pixel
//     (profile_options.subpixel_bits b, 4 as SwiftShader) but interpolates the corners' unsnapped
//     values, so the ray of the pixel at window position p (per axis) passes through
//     lo + (p - snap(lo)) (hi - lo) / (snap(hi) - snap(lo)), up to 2^-(b+1) pixel from the centre;
//   - the ray box is the texel box [o - s/2, o + (n - 1/2) s] (ImageData.getSpatialExtent inflates the
//     extent by 0.5); positions outside the domain read it clamped (CLAMP_TO_EDGE);
//   - R = (t_exit - t_entry) / h steps; a first sample at the entry with alpha 1 - (1 - a)^j (j the jitter,
//     render.profile_options.jitter), then samples at entry + (j + k) h while j + k + 1 < R, then the
//     exit sample with alpha 1 - (1 - a)^(R - steps travelled) unless the ray stopped; R <= 1: the entry
//     sample alone with alpha 1 - (1 - a)^R;
//   - a stop once A > 0.99 (A then set to 1, the colour kept);
//   - tables of 1024 entries over the transfer function's own node range (colour and opacity each over
//     its own): colour 8-bit (round(255 c)), opacity float with every entry corrected,
//     1 - (1 - a)^(h / l), read linearly at u 1024 - 0.5; a sample whose table alpha < 0.001 is dropped;
//   - Phong as vtk.js shades (the reflection vector, N = +grad f, L the light's direction of travel,
//     specular only where N.L > 0), the gradient (f(x + s_i e_i) - f(x - s_i e_i)) / s_i multiplied by
//     diag(n s) before normalising (the shipped vtk.js bug; profile_options.fixed_normal drops it);
//   - the pixel (C / A) A as a float framebuffer blends it: NaN colour where A = 0;
//   - mip/minip: the extremum of the same samples (entry, jittered interior, exit), pixel (a c, a) with
//     the corrected opacity table (a < 0.001: zero).
// The options flip_normal, ray_box "domain" and mip_correction false are the conventions
// `volref compare --fit --scene` tries (docs/compare.md), not vtk.js behaviour.
#pragma once
#include <memory>
#include <vector>

#include "core/grid/Volume.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/scene/Scene.h"

namespace volref {

class VtkJsIntegrator final : public OneLoopIntegrator<VtkJsIntegrator> {
public:
    // Throws volref::Error naming render.profile (or the key) for what vtk.js's mapper does not render
    // or the profile does not mirror.
    VtkJsIntegrator(const IntegrationContext& ctx, const Volume& volume, const VolumeSpec& spec, const Scene& scene);
    ~VtkJsIntegrator() override;

    // The 1024-entry tables, as uploaded (tests read them).
    static constexpr int kTableEntries = 1024;
    double table_opacity(double v) const;     // the corrected float table, read linearly
    glm::dvec3 table_color(double v) const;   // the 8-bit table, read linearly

private:
    friend class OneLoopIntegrator<VtkJsIntegrator>;
    struct Sample {
        glm::dvec3 color{0.0};
        double alpha = 0.0;
    };
    double value(const glm::dvec3& x) const;
    Sample color_at(const glm::dvec3& x, const glm::dvec3& ray_dir) const;
    glm::dvec3 shade(const glm::dvec3& c, const glm::dvec3& x, const glm::dvec3& ray_dir) const;
    bool box(const Ray& ray, double& t0, double& t1) const;
    Ray rasterised(const Ray& ray) const;  // the pixel's ray as the snapped proxy quad interpolates it

    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;

    glm::dvec3 domain_lo_, domain_hi_, box_lo_, box_hi_;
    glm::dvec3 spacing_, normal_scale_;
    glm::dvec3 forward_;  // the camera's direction of view (a headlight's direction of travel)
    double step_ = 0.0, jitter_ = 1.0;
    double color_lo_ = 0.0, color_width_ = 1.0, opacity_lo_ = 0.0, opacity_width_ = 1.0;
    std::vector<glm::dvec3> color_table_;
    std::vector<double> opacity_table_;      // corrected for the step (as uploaded)
    std::vector<double> opacity_raw_table_;  // uncorrected (mip_correction false)
    bool flip_normal_ = false;
    // The camera as vtk.js's proxy quad sees it (perspective or orthographic scene cameras only), and the
    // quad's window rectangle per axis (x right, y up, in pixels), unsnapped and snapped.
    bool snap_ = false, orthographic_ = false;
    glm::dvec3 eye_{0.0}, right_{0.0}, up_{0.0};
    double tan_half_fov_ = 0.0, half_height_ = 0.0, aspect_ = 1.0;
    glm::dvec2 image_{1.0}, quad_lo_{0.0}, quad_hi_{0.0}, snapped_lo_{0.0}, snapped_hi_{0.0};
};

}  // namespace volref
