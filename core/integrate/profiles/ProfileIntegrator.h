// ProfileIntegrator: renders a scene with another renderer's discretisation, read from a Profile
// (Profile.h; conventions section 9): sample placement, table lookup, opacity correction, gradient
// scheme, compositing and termination. Scalar path only; the reference profile never comes here
// (make_integrator's integrators and their SIMD paths render it).
//
// Per projection (v_k the samples' values, (c, a) = transfer function or table at v, alpha_k the
// profile's per-sample alpha, s = (v - min) / (max - min) over the volume's data range):
//   composite: C += (1 - A) alpha_k c_k, A += (1 - A) alpha_k, front to back, stopping as the profile
//              says; c_k shaded (and clamped when the profile clamps) when the scene is shaded;
//   mip/minip: v* = max/min v_k, pixel (a(v*) c(v*), a(v*)) with the uncorrected opacity;
//   average:   Average::MeanOpacityTimesNormalised: g = mean_k a(v_k) s_k; MeanCoordinate: g = the
//              weighted mean of the transfer function's coordinate; pixel (g, g, g, 1);
//   xray:      g = gain * sum_k coordinate(v_k) d_k (BrightnessTimesMaximum: brightness * max_k s_k);
//              pixel (g, g, g, 1).
//   composite with Compositing::BackToFrontLerp: sum = lerp(sum, (c, a), a density) from the far end.
// Every formula is an accumulator's (march/Accumulators.h).
// vtk-cpu (Renderer::VtkFixedPoint) is not a ray integrator: VtkFixedPointRenderer.h renders its image
// in image space, called from the render step (PreparedScene::pixels).
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec4.hpp>

#include "core/grid/Volume.h"
#include "core/integrate/Integrator.h"
#include "core/integrate/profiles/Profile.h"
#include "core/integrate/march/SampleRecorder.h"

namespace volref {

class ShellGrid;
class CudaCurvilinearKernel;
class Camera;
struct BoundsSpec;
struct TriangleMesh;
struct SliceLattice;

// What placement "slices" places its surfaces from (Slices.h): the frame's camera and the geometry's
// bounding box in the volume's space.
struct SliceFrame {
    const Camera* camera = nullptr;
    const CameraSpec* spec = nullptr;
    glm::dvec3 box_lo{0.0}, box_hi{0.0};
    // Tetrahedra with overlap "count": the union's boundary, whose winding number at a fragment is the
    // number of tetrahedra covering it (geometry/TetrahedralMesh.h); null otherwise.
    const TriangleMesh* overlap = nullptr;
};

// What every mirror profile needs of the scene (fixed step, front-to-back order, its own termination,
// a grid it reads, post-classification by value alone); throws volref::Error naming render.profile.
void check_profile_applies(const Profile& p, const SamplePipeline& pipeline, const RenderSpec& render);

// integrate_traced records every sample (SampleRecorder.h): the record's segment is the length the
// sample stands for centred on it, `t` the sample's own position, `alpha` its alpha, `opacity` the
// (table's) uncorrected opacity, transmittance 1 - A before and after it.
class ProfileIntegrator final : public OneLoopIntegrator<ProfileIntegrator> {
public:
    // Throws volref::Error naming render.profile for what the profile cannot render.
    // `bounds`: the volume's bounds (seed 001's kernel builds its triangles from them; may be null otherwise).
    // `slice_frame`: placement "slices" (required there).
    ProfileIntegrator(const IntegrationContext& ctx, const Profile& profile, const Volume& volume,
                      const BoundsSpec* bounds = nullptr, const SliceFrame* slice_frame = nullptr);
    ~ProfileIntegrator() override;
    // Traits: the error channel with render.profile_options.texture_band (PixelValue::error is the
    // texture band, band()) or framebuffer_band (the frame buffer's band); the fault channel with
    // cuda-curvilinear's float32 kernel (the rays seed 001's loop cannot finish, fault_reason).
    std::string fault_reason(const Ray& ray) const override;

private:
    friend class OneLoopIntegrator<ProfileIntegrator>;
    struct Lookup {
        glm::dvec3 color{0.0};
        double opacity = 0.0;    // the transfer function's (uncorrected)
        double alpha = 0.0;      // the sample's alpha (composite)
    };
    // fn(t, d): a sample at ray parameter t standing for length d; returns false to stop.
    template <class Fn>
    void for_each_sample(const std::vector<Interval>& intervals, Fn&& fn) const;
    void check_rules(const RenderSpec& render, bool cartesian) const;
    double value(const glm::dvec3& x) const;
    double seed_shell_value(const glm::dvec3& x) const;  // Profile::seed_shell_reads
    // A texture fetch under render.profile_options.texture_unit (TextureUnit.h): the value the unit
    // returns, the exact trilinear value and the band |fetch - exact| <= band for any unit of the family.
    struct Fetch {
        double value = 0.0, exact = 0.0, band = 0.0;
    };
    Fetch texture_fetch(const glm::dvec3& x) const;
    bool shell_texels(const glm::dvec3& x, std::array<double, 8>& corners, glm::dvec3& w, glm::dvec3& coord) const;
    double texel(std::int64_t i, std::int64_t j, std::int64_t k) const;              // as a value
    std::uint16_t texel_code(std::int64_t i, std::int64_t j, std::int64_t k) const;  // seed 001's unorm16
    double code_value(std::uint16_t q) const { return lo_ + width_ * (double(q) / 65535.0); }  // min + (max - min) q / 65535
    // The texture band (conventions section 9, "The texture unit"): intervals of every sample's value,
    // classification and the projection's accumulation over all units within the model.
    struct Box {
        double lo[5], hi[5];  // r, g, b, uncorrected opacity, alpha
    };
    Box lookup_range(double vlo, double vhi, double d) const;
    Box sample_range(double vlo, double vhi, double d) const;  // composite: cutoff, colour, K, filter
    // The shaded colour box over gradients G0 +- dG (shaded composite).
    void shade_range(Box& b, const glm::dvec3& G0, const glm::dvec3& dG, const glm::dvec3& view, double depth) const;
    double band(const Ray& ray, const std::vector<Interval>& intervals, const glm::dvec4& rendered) const;
    Lookup lookup(double v, double d) const;
    double alpha(double a, double d) const;
    glm::dvec3 gradient(const glm::dvec3& x) const;
    double normalised(double v) const { return width_ > 0.0 ? (v - lo_) / width_ : 0.0; }

    template <class Rec>
    PixelValue integrate_impl(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    template <class Rec>
    PixelValue composite(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    template <TransmittanceRule R, class Rec>
    PixelValue composite_front_to_back(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    template <class Rec>
    PixelValue composite_lerp(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    template <class Rec>
    PixelValue extremum(const Ray& ray, const std::vector<Interval>& intervals, bool maximum, Rec& rec) const;
    template <class Rec>
    PixelValue line_integral(const Ray& ray, const std::vector<Interval>& intervals, bool mean, Rec& rec) const;

    const Profile p_;  // the preset with the scene's rules (resolve_profile)
    const Volume* volume_ = nullptr;          // seed_shell_reads: the beam-space data
    const ShellGrid* shell_ = nullptr;        // seed_shell_reads: its grid (null on Cartesian grids)
    glm::dvec3 domain_lo_, domain_hi_;
    glm::dvec3 offset_;  // per-axis gradient offset, world units
    double step_ = 0.0;  // the profile's step, world units
    double lo_ = 0.0, width_ = 0.0;  // the data range [lo, lo + width]
    std::vector<glm::dvec4> table_;  // rgb + uncorrected opacity
    std::vector<double> table_alpha_;  // corrected for the step (composite)
    ProfileOptions::TextureUnit texture_unit_ = ProfileOptions::TextureUnit::Exact;
    bool band_ = false;
    bool tricubic_ = false;                      // render.profile_options.tricubic (seed 001's cubicInterpolate)
    const Volume* texels_ = nullptr;             // the texture's texels (the volume)
    std::array<std::int64_t, 3> texture_dims_{};  // its texels per axis
    bool normalized_coordinates_ = true;         // GLSL's texture(): normalised; seed 001's tex3D: not
    const VolumeSampler* cartesian_ = nullptr;         // texture_unit / band on Cartesian grids
    const class TransferFunction* transfer_ = nullptr;  // band without a table: its knots
    std::unique_ptr<CudaCurvilinearKernel> kernel_;  // cuda-curvilinear, kernel "float32", on a shell
    template <class Rec>
    PixelValue seed_kernel(const Ray& ray, Rec& rec) const;

    // --- placement "slices" (ProfileSlices.cpp, Slices.h, FrameBuffer.h) -----------------------------
    struct Fragment {
        double s = 0.0;        // the texture's filtered value (post) or the trilinear s (pre-unweighted)
        glm::dvec3 color{0.0};  // the classification's colour (not premultiplied)
        double opacity = 0.0;  // its opacity (uncorrected)
        double alpha = 0.0;    // the fragment's alpha
    };
    void prepare_slices(const Volume& volume, const SliceFrame& frame);
    double slice_texel(std::int64_t i, std::int64_t j, std::int64_t k) const;  // s_i in the texture's format
    glm::dvec4 slice_lookup(double s, bool fixed8) const;  // (c, a) at the texture's value s (fixed8: llvmpipe's 1D filter)
    // `fixed8`: filter the texels by llvmpipe's 8-bit filter (the rule's, or the band's other unit).
    Fragment slice_fragment(const glm::dvec3& x, std::size_t level, double d, bool fixed8) const;
    template <class Rec>
    PixelValue slices(const Ray& ray, const std::vector<Interval>& intervals, Rec& rec) const;
    std::unique_ptr<SliceLattice> lattice_;
    double window_lo_ = 0.0, window_width_ = 1.0;  // the texture window [lo, lo + width]
    std::vector<glm::dvec4> slice_table_;          // the table's entries (c, a) over the window, stored
    bool framebuffer_band_ = false;
    bool band_units_ = false;
    std::shared_ptr<const TriangleMesh> overlap_;  // tetrahedra drawn each on its own (SliceFrame::overlap)  // the band also takes each fragment from the other 8-bit texture unit
};

}  // namespace volref
