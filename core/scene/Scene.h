// Scene: what to render, validated and with every default filled in (docs/scene-format.md).
// The loader (SceneLoader.h) builds it from JSON; the renderer builds only what it names.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/scene/Projection.h"
#include "core/scene/ShellSpec.h"

namespace volref {

// A procedural field sampled at the grid's vertices (scene-format.md, volume.source.field).
struct FieldSpec {
    enum class Kind { Constant, Linear, Radial, MarschnerLobb, Gaussian, Cells };
    Kind kind = Kind::Constant;
    std::array<std::int64_t, 3> dims{2, 2, 2};
    double value = 0.0;                           // constant
    std::array<double, 4> coefficients{0, 0, 0, 0};  // linear: f = a x + b y + c z + d (world)
    glm::dvec3 center{0.0};                       // radial, gaussian (world)
    double fm = 6.0, alpha = 0.25;                // marschner-lobb
    double sigma = 1.0, amplitude = 1.0;          // gaussian
    std::vector<double> values;                   // cells: nx*ny*nz values, i fastest
};

struct Volume;

struct VolumeSourceSpec {
    // Exactly one of file / field is set.
    std::optional<std::filesystem::path> file;  // absolute (resolved against the scene file's folder)
    // A volume given in memory (a numpy array, python/NumpyVolumes.h; a volref-mpi rank's brick,
    // cli/mpi/main.cpp): the renderer shares it (share_volume, Renderer.h) instead of reading `file`,
    // which then only names it in messages. It is complete: its origin and spacing are its own, and the
    // spec's origin and spacing are not applied again (the caller put them in). Not in scene files.
    std::shared_ptr<const Volume> memory;
    std::string format;                          // "" (from the extension), "nrrd" or "raw"
    std::optional<FieldSpec> field;
};

struct TransferSpec {
    enum class Domain { Data, Normalized };
    Domain domain = Domain::Data;
    std::optional<std::array<double, 2>> window;  // normalised domain: [lo, hi]; absent = default window
    // Rows sorted by value (non-decreasing). Absent in the file: colour = one white row; opacity = a
    // ramp from 0 at the window's low end to 1 at its high end (filled by the renderer, which knows
    // the window), signalled here by an empty vector.
    std::vector<std::array<double, 4>> color;    // [value, r, g, b]
    std::vector<std::array<double, 2>> opacity;  // [value, a]
    double opacity_unit_distance = 1.0;          // l, world units, > 0
    // Gradient-magnitude opacity modulation: rows [|grad f|, factor >= 0] sorted by |grad f|; the
    // opacity is multiplied by the piecewise-linear factor. Empty = none (no gradient is computed).
    std::vector<std::array<double, 2>> gradient_opacity;
};

// Levoy's classification (conventions section 7), instead of a transfer function.
struct IsovalueContour {
    double value = 0.0;
    double opacity = 1.0;    // av in [0, 1]
    double thickness = 1.0;  // r, world units, > 0
    glm::dvec3 color{1.0};
};
struct BoundaryRegion {
    double value = 0.0;
    double opacity = 1.0;  // av in [0, 1]
    glm::dvec3 color{1.0};
};
struct ClassificationSpec {
    enum class Type { Isovalue, Boundary };
    Type type = Type::Isovalue;
    std::vector<IsovalueContour> isovalues;  // Isovalue: at least one
    std::vector<BoundaryRegion> regions;     // Boundary: at least two, strictly increasing values
    double opacity_unit_distance = 1.0;
};

// Gradient shading (conventions section 8). Absent in the scene = unshaded.
struct ShadingSpec {
    enum class Model { BlinnPhong, Phong, Nodal };
    Model model = Model::BlinnPhong;
    double ka = 0.1, kd = 0.7, ks = 0.2, n = 10.0;  // ks is 0 for nodal
    double kc = 1.0, kl = 0.0;                      // depth cueing 1 / (kc + kl d)
    bool two_sided = false;
};

// How gradients are computed when shading or classification needs them.
struct GradientSpec {
    // Default: analytic for the tricubic kernels, central otherwise.
    enum class Scheme { Default, Central, Forward, Analytic };
    Scheme scheme = Scheme::Default;
    bool cache = false;  // precompute a per-voxel gradient volume and interpolate it
    // "cache": "auto": cache when the render is expected to evaluate more gradients per voxel than
    // the measured break-even (core/Conventions.h, kGradientCacheBreakEven). Opt-in only: cached
    // gradients differ from on-the-fly ones by O(h^2), so the reference never switches silently.
    bool cache_auto = false;
};

enum class Interpolation { Nearest, Trilinear, TricubicBSpline, TricubicCatmullRom };

struct BoundsSpec {
    enum class Type { Box, Mesh, Cylindrical, Spherical, Tetrahedra };
    // Tetrahedra: how overlapping tetrahedra count. Union: a point is inside once, however many cover
    // it. Count (OpenGL Volumizer slicing each tetrahedron on its own, so a point m tetrahedra cover is
    // drawn m times): placement "slices" only, each fragment blended m times (conventions section 9).
    enum class Overlap { Union, Count };
    Type type = Type::Box;
    std::optional<glm::dvec3> min, max;  // box: absent = the volume's domain
    std::filesystem::path mesh;          // mesh: a closed triangle mesh (.obj, .ply); tetrahedra: a VTK
                                         // legacy UNSTRUCTURED_GRID (.vtk); absolute
    Overlap overlap = Overlap::Union;    // tetrahedra only
    CylindricalShell cylinder;           // cylindrical shell (the grid is in beam space)
    SphericalShell sphere;               // spherical shell (the grid is in beam space)
    int tessellate = 0;                  // shells: > 0 = use a triangle mesh of about this many segments per turn
};

// A clip plane (conventions section 4): the kept side is where (p - point) . normal >= 0 (as VTK's
// vtkPlane clipping), point and normal in world coordinates.
struct ClipPlaneSpec {
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0, 0.0, 1.0};  // non-zero (not normalised: only its direction matters)
};

// VTK's cropping (vtkVolumeMapper::SetCroppingRegionPlanes / SetCroppingRegionFlags): six planes
// x0 <= x1, y0 <= y1, z0 <= z1 in the volume's own coordinates (before `transform`) cut its space
// into 27 regions, numbered (ix + 3 iy + 9 iz) with ix = 0 below x0, 1 in [x0, x1], 2 above x1 (the
// same for y, z); region r is kept when bit r of `regions` is set.
struct CropSpec {
    std::array<double, 6> planes{0, 0, 0, 0, 0, 0};  // x0, x1, y0, y1, z0, z1
    std::uint32_t regions = 0x0002000;                // VTK_CROP_SUBVOLUME
};

struct VolumeSpec {
    VolumeSourceSpec source;
    std::optional<glm::dvec3> origin;   // overrides the file's (procedural fields: default 0)
    std::optional<glm::dvec3> spacing;  // overrides the file's (procedural fields: default 1)
    Interpolation interpolation = Interpolation::Trilinear;
    BoundsSpec bounds;
    TransferSpec transfer;                              // used when classification is absent
    std::optional<ClassificationSpec> classification;  // Levoy's isovalue / boundary classification
    enum class Classify { Post, Pre };
    Classify classify = Classify::Post;  // post: interpolate, then classify; pre: classify voxels, then interpolate
    std::optional<ShadingSpec> shading;  // absent: unshaded
    GradientSpec gradient;
    // From the volume's own space (grid, bounds, crop planes) to world space; absent = identity.
    // An affine matrix (last row 0 0 0 1) with a non-zero determinant.
    std::optional<glm::dmat4> transform;
    std::vector<ClipPlaneSpec> clip_planes;  // each cuts the volume's intervals (kept side >= 0)
    std::optional<CropSpec> crop;
};

struct LightSpec {
    enum class Type { Headlight, Directional };
    Type type = Type::Headlight;
    glm::dvec3 direction{0.0, 0.0, 1.0};  // directional: towards the light (normalised by the loader)
    glm::dvec3 color{1.0};
};

struct CameraSpec {
    enum class Type { Default, Perspective, Orthographic, Matrices };
    Type type = Type::Default;  // Default: 30 degrees, looking along -z at the bounds' centre (camera/Camera.h)
    glm::dvec3 eye{0.0, 0.0, 1.0}, target{0.0}, up{0.0, 1.0, 0.0};
    double fov_y = 30.0;   // degrees, in (0, 180)
    double height = 1.0;   // orthographic view height, world units, > 0
    glm::dmat4 view{1.0}, projection{1.0};  // matrices (OpenGL conventions; given column-major)
    // Clipping depths along the view direction (eye space, 0 < near < far): read by placement "slices"
    // only (its range "view_volume" and its fragments' depth test; conventions section 9).
    std::optional<double> near, far;
};

struct ImageSpec {
    int width = 256, height = 256;
    glm::dvec4 background{0.0, 0.0, 0.0, 0.0};  // RGBA, not premultiplied, each in [0, 1]
};

enum class CompositeOrder { FrontToBack, BackToFront };
enum class StepUnits { Voxel, World };
// How a ray's integral is computed: `Fixed` steps of render.step (conventions section 4), or
// `Adaptive` error-controlled integration to render.tolerance (docs/accuracy.md).
enum class IntegrationMethod { Fixed, Adaptive };
// render.profile: whose discretisation to reproduce (core/integrate/profiles/Profile.h, conventions section 9);
// Fast is volref's own float SIMD variant of the reference (core/integrate/packet/FastProfile.h).
enum class ProfileId { Reference, VtkGpu, GlslBasic, Ospray, CudaCurvilinear, VtkCpu, Fast, VtkJs, Volumizer, VolPack };
// render.profile "volpack" (core/integrate/profiles/VolPackRenderer.h, docs/conventions.md "VolPack"):
// VolPack 1.0b3's inputs as a VolPack program gives them, in render.profile_options.
struct VolPackTable {
    std::vector<float> entries;                    // the table as VolPack reads it (vpSetClassifierTable's floats)
    std::vector<std::pair<int, float>> ramp;       // when given as {"ramp": ...}: vpRamp's points (SceneWriter)
};
struct VolPackLight {
    glm::dvec3 direction{0.0, 0.0, 1.0};  // vpSetLight(VP_DIRECTION) while the model matrix is the identity
    glm::dvec3 color{1.0};                 // vpSetLight(VP_COLOR), each in [0, 1]
};
struct VolPackSpec {
    enum class Axis { X, Y, Z };
    std::vector<std::pair<Axis, double>> rotate;  // vpRotate(axis, degrees) on VP_MODEL, in order
    bool concat_left = false;                      // VP_CONCAT_MODE: VP_CONCAT_RIGHT (false, VolPack's default) or LEFT
    std::array<double, 6> window{-0.5, 0.5, -0.5, 0.5, -0.5, 0.5};  // vpWindow(VP_PARALLEL, l, r, b, t, n, f)
    VolPackTable scalar_table;                      // 256 opacities over the 8-bit scalar
    std::optional<VolPackTable> gradient_table;     // 256 (222 read) over the gradient-magnitude field
    bool shaded = false;                            // absent: every shade-table entry 255 (white, unlit)
    glm::dvec3 ambient{0.1}, diffuse{0.4}, specular{0.5};  // vpSetMaterial (VP_MATERIAL0, VP_BOTH_SIDES); x 255 inside
    double shininess = 10.0;
    std::optional<std::vector<VolPackLight>> lights;  // absent: VolPack's default VP_LIGHT0
    bool two_sided = false;                           // VP_LIGHT_BOTH_SIDES
    double min_voxel_opacity = 0.0, max_ray_opacity = 1.0;
    std::optional<std::array<double, 2>> depth_cue;   // vpSetDepthCueing(front, density); absent: off
    int channels = 1;                                 // 1: luminance, 3: RGB
    enum class Path { Classified, Raw };
    Path path = Path::Classified;                     // vpRenderClassifiedVolume or vpRenderRawVolume
    std::optional<Axis> axis;                         // VP_AXIS_OVERRIDE; absent: VolPack's choice
    // Conventions changed one at a time (the check that each is seen; conventions "VolPack"):
    enum class WarpWeights { Table, Exact };          // the 64-entry weight table, or the exact fractions
    enum class NormalCode { Quantised, Exact };        // shade by the 13-bit code's normal, or the exact one
    enum class CorrectionOrder { Voxel, Sample };      // correct each voxel's 8-bit opacity, or the resampled one
    WarpWeights warp_weights = WarpWeights::Table;
    NormalCode normal_code = NormalCode::Quantised;
    CorrectionOrder correction_order = CorrectionOrder::Voxel;
};

// render.profile_options: the cuda-curvilinear renderer's own parameters (conventions section 9).
struct ProfileOptions {
    double density = 1.0;         // the lerp weight is col.a * density
    double transfer_scale = 1.0;  // the table is read at s * transfer_scale
    double iso_threshold = 0.0;   // samples with s below it are skipped (s: value normalised over the data range)
    double brightness = 1.0;      // x-ray: the maximum of s times this
    // vtk-js (VtkJsIntegrator.h): the jitter fraction in [0.01, 1] (vtk.js: 0.01 + 0.99 seed);
    // fixed_normal drops vtk.js's diag(dims * spacing) normal scaling; flip_normal, ray_box_domain and
    // mip_correction false are conventions `volref compare --fit --scene` tries.
    double jitter = 1.0;
    bool fixed_normal = false, flip_normal = false, ray_box_domain = false, mip_correction = true;
    // vtk-js: the rasteriser's sub-pixel precision. vtk.js takes each pixel's ray from
    // the varying interpolated over its proxy quad, whose corners the rasteriser snaps to 1 / 2^bits of a
    // pixel: 4 (the default) is SwiftShader's (vk::SUBPIXEL_PRECISION_BITS), what the check runs; 0: no
    // snapping, each ray through its pixel centre.
    int subpixel_bits = 4;
    double intensity = 1.0;       // glsl-basic: seed 002's K, the sample's alpha is K times the opacity
    // vtk-gpu, glsl-basic, cuda-curvilinear (core/integrate/profiles/TextureUnit.h, conventions
    // section 9, "The texture unit"): the profile's linearly filtered texture reads, exact (llvmpipe) or
    // the NVIDIA H100's rule bit for bit; texture_band: the render writes the "error" channel, a bound
    // on how far any texture unit of the rule's family can be from this render. Admissible: tests only
    // (no scene-file value): every fetch is a unit of the family, chosen by a hash of texture_seed and
    // the fetch's position (a Monte Carlo of the units the band covers).
    enum class TextureUnit { Exact, H100, Admissible };
    TextureUnit texture_unit = TextureUnit::Exact;
    // cuda-curvilinear on shells (CudaCurvilinearKernel.h): "float32" (the default) runs seed 001's kernel
    // as the program does, in float32 on the host's bounding triangles with its unsigned-short data (composite
    // and x-ray; other projections keep the double-precision profile); "double": the double-precision
    // profile on the exact shell.
    enum class Kernel { Float32, Double };
    Kernel kernel = Kernel::Float32;
    // cuda-curvilinear on shells: seed 001's tri-cubic option (its --tricubic, cubicInterpolate: the seed's
    // cubic weights through 8 linear fetches at the mixture coordinates; conventions section 9,
    // "cuda-curvilinear and seed 001") instead of one linear fetch per sample.
    bool tricubic = false;
    bool texture_band = false;
    unsigned long long texture_seed = 0;  // Admissible
    // cuda-curvilinear on shells: the data texture as seed 001 holds it, the values normalised over the
    // data range to unsigned shorts (rounded to nearest) read as v / 65535 (render.profile_options.
    // texture_format "unorm16"), or the values themselves ("float", the default).
    bool data_unorm16 = false;
    // placement "slices": the render writes the "error" channel, the interval of what every
    // rounding variant of the frame buffer stores (conventions section 9, "Slice-order renderers").
    bool framebuffer_band = false;
    // fast (transfer/PreIntegration.h): pre-integrated segments, the table's intervals per axis
    // (render.profile_options.preintegration); 0: off, samples at the segments' midpoints.
    int preintegration = 0;
    // volpack: VolPack's inputs (VolPackSpec above); set for render.profile "volpack" only.
    std::optional<VolPackSpec> volpack;
};

// render.profile's rules (docs/conventions.md section 9, "Profiles as data") in three structs:
// ProfileRuleTypes, the rules' enumerations; ProfileRuleValues, the value of every rule in a resolved
// profile (Profile, core/integrate/profiles/Profile.h, extends it with what is not a rule: the renderer,
// the projections' own conventions, termination); and ProfileRules, the rules a scene sets over its
// preset (render.profile written as an object). Each rule is one entry of the rule table
// (core/scene/ProfileRuleTable.h): its key, how it is read and written, how it sets ProfileRuleValues,
// the values the convention search tries and the placements and scenes that read it.
struct ProfileRuleTypes {
    enum class Placement { Midpoints, FromEntry, FromExit, Slices };
    enum class StepCount { ThroughExit, BeforeExit };
    enum class RayBox { Domain, Texel, Given };
    enum class VoxelLength { Spacing, ExtentOverSamples };
    enum class Correction { Power, None, Extinction, Exact };
    enum class Compositing { OpticalDepth, Product, OpacitySum, Lerp };
    enum class Stop { None, AlphaAbove, AlphaAtLeast, TransmittanceAtMost };
    enum class TableCoordinate { DataRange, DataRangeTimesTransferScale };
    enum class Arithmetic { Double, Float32 };
    enum class Gradient { Central, Forward, CentralInDomain };

    // The slicer's surfaces (placement "slices"; conventions section 9, "Slice-order renderers").
    struct Slices {
        enum class Orientation { Viewport, Axis, Spherical };
        enum class Range { Object, ViewVolume };
        enum class First { Bound, Half };
        enum class Order { BackToFront, FrontToBack };
        Orientation orientation = Orientation::Viewport;
        Range range = Range::Object;
        std::optional<double> spacing;              // in render.step_units; none of the three: the scene's step
        std::optional<std::int64_t> count;          // Volumizer's samplesNumber
        std::optional<glm::dvec3> period;           // Volumizer's samplingPeriod, voxels
        std::optional<std::int64_t> max_count;      // n = min(n, max_count)
        First first = First::Bound;
        Order order = Order::BackToFront;
        bool operator==(const Slices&) const = default;
    };
    enum class Texture { Texture3d, Texture2d };
    enum class TexelFormat { Float, Unorm16, Unorm8 };
    enum class TextureWindow { TransferRows, DataRange, Given };
    enum class TableLookup { Texture, Linear, Nearest };
    enum class TableFormat { Float, Unorm8 };
    enum class SliceClassify { Post, PreUnweighted };
    enum class FrameBuffer { Double, Rgba32f, Rgba16f, Rgba8 };
    enum class Rounding { Nearest, Truncate };
    enum class BlendProducts { Exact, Rounded, Llvmpipe };
    enum class TextureFilter { Exact, Fixed8 };
    enum class Blend { SrcAlpha, Premultiplied, Max };
    enum class BlendAlpha { SrcAlpha, One };
};

// The value of every rule in a resolved profile, each with its formula; the defaults are the values a
// preset does not set (core/integrate/profiles/Profile.cpp has the presets).
struct ProfileRuleValues : ProfileRuleTypes {
    // --- sample placement -------------------------------------------------------------------------
    // Where the samples of one interval [t0, t1] (length L, step h) lie.
    // Midpoints (the reference): segments of h, sampled at their midpoints, weighted by their lengths.
    // FromEntry: t0 + (first + k) h for k = 0 .. n-1, n by `step_count`. Positions past t1 read the
    //   texture clamped to the domain.
    // FromExit: seed 001 (cuda-curvilinear): `for (s = outAbs; s >= inAbs; s -= step)` over one
    //   span [inAbs, outAbs] = [the first interval's t0, the last one's t1]: t1 - k h for k = 0 .. n - 1
    //   (first = 0), back to front; samples in the gaps between intervals read the field as value() says.
    // Slices: a slicer's sampling surfaces (`slices` below).
    Placement placement = Placement::Midpoints;
    double first = 0.0;  // FromEntry: the first sample's distance from the entry, in steps
    // FromEntry, FromExit: ThroughExit: n = max(1, floor(L / h + 1 - first)) (at least one sample, even
    // when the chord is shorter than first * h; VTK's GPU shader samples before it tests the exit);
    // BeforeExit: n = max(0, ceil(L / h - first)) (a shader's `while (t < t_exit)`).
    StepCount step_count = StepCount::ThroughExit;
    // The box rays are clipped to (PreparedVolume): the domain [origin, origin + (n - 1) spacing], the
    // texel box (the domain grown by spacing / 2 on every side: a texture's [0, 1]), or `box`; reads
    // outside the domain are clamped.
    RayBox ray_box = RayBox::Domain;
    std::array<glm::dvec3, 2> box{};  // RayBox::Given: min, max in the volume's space
    // What render.step_units "voxel" means: the grid spacing (the reference), or size / n (the extent
    // over the sample count: the step is multiplied by (n - 1) / n, n the dims of the grid's axis of
    // smallest spacing (Cartesian) or the largest dims (shells)).
    VoxelLength voxel_length = VoxelLength::Spacing;

    // --- classification ---------------------------------------------------------------------------
    // The transfer function read exactly (table_entries 0) or through 1-D tables of `table_entries`
    // entries built at min + j (max - min) / (N - 1) over the volume's data range [min, max] and read
    // with linear filtering at texel position u N - 0.5 (clamped to the edge texels, as an OpenGL
    // texture with GL_LINEAR and CLAMP_TO_EDGE does), u by the table coordinate rule.
    int table_entries = 0;
    // DataRange: u = s = (v - min) / (max - min); DataRangeTimesTransferScale:
    // u = clamp(s * render.profile_options.transfer_scale, 0, 1).
    TableCoordinate table_coordinate = TableCoordinate::DataRange;

    // --- opacity correction -----------------------------------------------------------------------
    // How a transfer-function opacity a (per unit distance l) becomes the alpha of one sample.
    // Power:      alpha = 1 - (1 - a)^(d / l) (d the length the sample stands for), applied to the table
    //             entries with a > floor before filtering (VTK GPU), or to a when there is no table;
    // Exact:      the same formula applied to the sample's own (filtered) opacity a, a > floor;
    // None:       alpha = a (per-sample opacity, a textbook shader);
    // Extinction: alpha = 1 - exp(-a d density_scale) (OSPRay: a is an extinction coefficient).
    Correction correction = Correction::Power;
    double correction_floor = 0.0;  // Power: entries with a <= floor are left as they are
    double density_scale = 1.0;     // Extinction

    // --- compositing (march/Accumulators.h; the stopping rule is Profile::termination) --------------
    // Front to back, premultiplied, C += T alpha c with the transmittance T kept by the rule
    // (march/Accumulators.h, TransmittanceRule): OpticalDepth (tau += -log1p(-alpha), T = exp(-tau): the
    // reference), Product (T *= 1 - alpha), OpacitySum (A += (1 - A) alpha, T = 1 - A: GPU shaders).
    // Lerp: seed 001: back to front, sum = lerp(sum, (c, a), a density) on R, G, B, A (density:
    // render.profile_options.density); no termination.
    Compositing compositing = Compositing::OpacitySum;

    // --- gradients and shading --------------------------------------------------------------------
    // Central differences (f(x + o) - f(x - o)) / 2o of the field clamped to the domain at
    // o = +-gradient_offset voxels per axis (GPU shaders), or forward differences (f(x + o) - f(x)) / o
    // (Gradient::Forward), or central with the stencil kept inside the domain, one-sided at its
    // boundary (Gradient::CentralInDomain: the reference's GradientField, conventions section 2).
    // normal_along_gradient: the renderer's normal is +grad f (VTK's GLSL) rather than this contract's
    // -grad f. clamp_shaded: the shaded colour is clamped to [0, 1] before compositing.
    double gradient_offset = 1.0;          // voxels
    double gradient_offset_texture = 0.0;  // > 0: the offset is this fraction of the domain's extent per axis
    Gradient gradient = Gradient::Central;
    bool normal_along_gradient = false;
    bool clamp_shaded = false;

    // --- slicers (placement Slices; core/integrate/profiles/Slices.h, FrameBuffer.h) ----------------
    // The sampling surfaces, what a slice fragment computes and the frame buffer that blends them
    // (conventions section 9, "Slice-order renderers"); read only under placement Slices.
    Slices slices{};
    Texture texture = Texture::Texture3d;
    TexelFormat texel_format = TexelFormat::Float;
    TextureWindow texture_window = TextureWindow::TransferRows;
    glm::dvec2 texture_window_given{0.0, 1.0};  // TextureWindow::Given: [lo, hi], lo < hi
    TableLookup table_lookup = TableLookup::Texture;
    TableFormat table_format = TableFormat::Float;
    SliceClassify classify = SliceClassify::Post;
    FrameBuffer framebuffer = FrameBuffer::Double;
    Rounding framebuffer_rounding = Rounding::Nearest;
    // Llvmpipe: each product (t + (t >> 8) + 128) >> 8, t = q_s f_s (Mesa's llvmpipe, measured by
    // tests/gpu/slicing/gl_probe: one less than round(t / 255) for 24 pairs of codes >= 152).
    BlendProducts blend_products = BlendProducts::Exact;
    Blend blend = Blend::SrcAlpha;
    BlendAlpha blend_alpha = BlendAlpha::SrcAlpha;
    // Exact: trilinear in double of the stored texels; Fixed8: llvmpipe's 8-bit filter (unorm8 texels):
    // weights of 1/256, each lerp v0 + ((w (v1 - v0) + 128) >> 8) in codes, x, then y, then z.
    TextureFilter texture_filter = TextureFilter::Exact;
};

// render.profile written as an object: a preset (`base`) and the rules the scene sets over it, each
// absent where the scene leaves the base's value (ProfileRuleValues has each rule's formula).
struct ProfileRules : ProfileRuleTypes {
    std::optional<Placement> placement;
    std::optional<Slices> slices;
    std::optional<Texture> texture;
    std::optional<TexelFormat> texture_format;
    std::optional<TextureWindow> texture_window;
    glm::dvec2 texture_window_given{0.0, 1.0};  // TextureWindow::Given: [lo, hi], lo < hi
    std::optional<TableLookup> table_lookup;
    std::optional<TableFormat> table_format;
    std::optional<SliceClassify> classify;
    std::optional<FrameBuffer> framebuffer;
    std::optional<Rounding> framebuffer_rounding;
    std::optional<BlendProducts> blend_products;
    std::optional<TextureFilter> texture_filter;
    std::optional<Blend> blend;
    std::optional<BlendAlpha> blend_alpha;
    std::optional<double> first;  // from-entry: the first sample's distance from the entry, in steps
    std::optional<StepCount> step_count;
    std::optional<RayBox> ray_box;
    std::optional<std::array<glm::dvec3, 2>> box;  // RayBox::Given: min, max in the volume's space
    std::optional<VoxelLength> step_voxel;
    std::optional<Correction> correction;
    std::optional<double> correction_floor;  // Power: entries with a <= floor are not corrected
    std::optional<double> density_scale;     // Extinction
    std::optional<Compositing> compositing;
    // When a front-to-back ray stops (Profile::termination): never, or after the sample at which
    // A > termination_value (AlphaAbove), A >= termination_value (AlphaAtLeast) or
    // T <= termination_value (TransmittanceAtMost).
    std::optional<Stop> termination;
    double termination_value = 1.0;          // the threshold of `termination`
    std::optional<int> table_entries;        // 0: the transfer function read exactly
    std::optional<TableCoordinate> table_coordinate;
    std::optional<Arithmetic> arithmetic;    // float32: seed 001's kernel (render.profile_options.kernel)
    std::optional<ProfileOptions::TextureUnit> texture_unit;  // as render.profile_options.texture_unit
    std::optional<bool> normal_along_gradient;  // "normal": "+gradient" (true) or "-gradient"
    std::optional<Gradient> gradient;
    std::optional<double> gradient_offset;      // voxels
    std::optional<double> gradient_offset_texture;  // a fraction of the domain's extent per axis
    std::optional<bool> clamp_shaded;
    // The keys the scene set, in the rule table's order (messages, `volref compare --fit`, the resolved
    // scene).
    std::vector<std::string> keys;
    bool empty() const { return keys.empty(); }
};

struct RenderSpec {
    Projection projection = Projection::Composite;
    CompositeOrder order = CompositeOrder::FrontToBack;
    double step = 0.5;                    // > 0
    StepUnits step_units = StepUnits::Voxel;
    std::optional<double> isovalue;       // required by first-hit
    std::optional<double> early_termination;  // accumulated alpha threshold in (0, 1]; absent = off
    double gain = 1.0;                    // xray: the line integral is multiplied by this
    IntegrationMethod integrator = IntegrationMethod::Fixed;
    double tolerance = 1e-6;              // adaptive: absolute error per channel, > 0
    ProfileId profile = ProfileId::Reference;  // the preset (render.profile, or its "base")
    ProfileRules profile_rules;                // render.profile as an object: the rules set over the preset
    ProfileOptions profile_options;
    // The reference's own integrators (and their SIMD paths, skipping, transforms, several volumes):
    // render.profile "reference" with no rule set over it.
    bool reference_integrators() const { return profile == ProfileId::Reference && profile_rules.empty(); }
};

struct Scene {
    std::filesystem::path file;  // the scene file (for messages); empty for scenes built in code
    // `volumes` in the file (at least one); `volume` is the shorthand for a list of one.
    std::vector<VolumeSpec> volumes{VolumeSpec{}};
    // The first (for most scenes the only) volume.
    VolumeSpec& volume() { return volumes.front(); }
    const VolumeSpec& volume() const { return volumes.front(); }
    std::vector<LightSpec> lights{LightSpec{}};
    CameraSpec camera;
    ImageSpec image;
    RenderSpec render;
};

}  // namespace volref
