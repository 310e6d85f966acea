// Profile: a data description of another renderer's discretisation (conventions section 9), applied
// to the same scene by ProfileIntegrator. A profile never changes the scene (volume, transfer
// functions, camera, lights, step); it changes where samples are taken, how a transfer-function
// opacity becomes a sample's alpha, whether the transfer function is read through a table, the
// gradient scheme, the compositing rule and when a ray stops: each a rule named below, read by one
// renderer (ProfileIntegrator, or VtkFixedPointRenderer for VTK's fixed-point mapper). Every number here is one renderer's
// convention, with its source; docs/conventions.md section 9 gives the formulas.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/integrate/march/Accumulators.h"
#include "core/scene/Scene.h"

namespace volref {

struct Profile {
    ProfileId id = ProfileId::Reference;
    std::string name = "reference";

    // Which renderer reads the rest: a ray caster over the scene's rays (ProfileIntegrator), or VTK's
    // image-space fixed-point caster (VtkFixedPointRenderer.h: its own internal image, 15-bit fixed
    // point, texture display; the fields below are not read).
    // VtkJs: VtkJsIntegrator.h; VolPack: VolPackRenderer.h
    enum class Renderer { RayCaster, VtkFixedPoint, VtkJs, VolPack };
    Renderer renderer = Renderer::RayCaster;

    // The grids the renderer reads: Cartesian only (texture reads clamped to the domain), or beam-space
    // shells as well (no clamping: the intervals stay inside; no gradients).
    enum class Grids { Cartesian, CartesianAndShells };
    Grids grids = Grids::Cartesian;
    // Seed 001's texture reads on shells (interpolateCyl / interpolateSpher; cuda-curvilinear):
    // per grid axis x = (c - lo) / ((hi - lo) / n) (an angle taken in [0, 360) from lo); a point with any
    // x < 0 or x > n - 1 reads outVal = 0, here the data minimum (s = 0); otherwise tex3D with unnormalised
    // coordinates and cudaAddressModeClamp: trilinear at grid index clamp(x - 0.5, 0, n - 1) (texel i is
    // centred at i + 0.5). Off: the shell sampler (conventions section 2).
    bool seed_shell_reads = false;

    // --- sample placement -------------------------------------------------------------------------
    // Where the samples of one interval [t0, t1] (length L, step h) lie.
    // Midpoints (the reference): segments of h, sampled at their midpoints, weighted by their lengths.
    // FromEntry: t0 + (first + k) h for k = 0 .. n-1, n by `step_count`. Positions past t1 read the
    //   texture clamped to the domain.
    // FromExit: seed 001 (cuda-curvilinear): `for (s = outAbs; s >= inAbs; s -= step)` over one
    //   span [inAbs, outAbs] = [the first interval's t0, the last one's t1]: t1 - k h for k = 0 .. n - 1
    //   (first = 0), back to front; samples in the gaps between intervals read the field as value() says.
    using Placement = ProfileRules::Placement;
    Placement placement = Placement::Midpoints;
    double first = 0.0;  // FromEntry: the first sample's distance from the entry, in steps
    // FromEntry, FromExit: ThroughExit: n = max(1, floor(L / h + 1 - first)) (at least one sample, even
    // when the chord is shorter than first * h; VTK's GPU shader samples before it tests the exit);
    // BeforeExit: n = max(0, ceil(L / h - first)) (a shader's `while (t < t_exit)`).
    using StepCount = ProfileRules::StepCount;
    StepCount step_count = StepCount::ThroughExit;
    // The box rays are clipped to (PreparedVolume): the domain [origin, origin + (n - 1) spacing], the
    // texel box (the domain grown by spacing / 2 on every side: a texture's [0, 1]), or `box`.
    using RayBox = ProfileRules::RayBox;
    RayBox ray_box = RayBox::Domain;
    std::array<glm::dvec3, 2> box{};  // RayBox::Given, in the volume's space
    // What render.step_units "voxel" means: the grid spacing (the reference), or size / n (the extent
    // over the sample count: the step is multiplied by (n - 1) / n, n the dims of the grid's axis of
    // smallest spacing (Cartesian) or the largest dims (shells)).
    using VoxelLength = ProfileRules::VoxelLength;
    VoxelLength voxel_length = VoxelLength::Spacing;

    // --- classification ---------------------------------------------------------------------------
    // The transfer function read exactly (table_entries 0) or through 1-D tables of `table_entries`
    // entries built at min + j (max - min) / (N - 1) over the volume's data range [min, max] and read
    // with linear filtering at texel position u N - 0.5 (clamped to the edge texels, as an OpenGL
    // texture with GL_LINEAR and CLAMP_TO_EDGE does), u by the table coordinate rule.
    int table_entries = 0;
    // DataRange: u = s = (v - min) / (max - min); DataRangeTimesTransferScale:
    // u = clamp(s * render.profile_options.transfer_scale, 0, 1).
    using TableCoordinate = ProfileRules::TableCoordinate;
    TableCoordinate table_coordinate = TableCoordinate::DataRange;
    // Which samples are composited: all, or those with s >= render.profile_options.iso_threshold.
    enum class SampleFilter { All, AtOrAboveIsoThreshold };
    SampleFilter sample_filter = SampleFilter::All;
    // Seed 002's shader (glsl-basic, composite only): `color_from_value` composites the grey (v, v, v)
    // of the sample's own value (its `textureValue.rrr`) instead of the transfer function's colour;
    // samples with v < value_cutoff are skipped (its density cutoff 0.01); the sample's alpha is the
    // opacity times render.profile_options.intensity when `alpha_times_intensity` (its K, not clamped).
    bool color_from_value = false;
    double value_cutoff = -1.0e300;
    bool alpha_times_intensity = false;

    // --- opacity correction -----------------------------------------------------------------------
    // How a transfer-function opacity a (per unit distance l) becomes the alpha of one sample.
    // Power:      alpha = 1 - (1 - a)^(d / l) (d the length the sample stands for), applied to the table
    //             entries with a > floor before filtering (VTK GPU), or to a when there is no table;
    // Exact:      the same formula applied to the sample's own (filtered) opacity a, a > floor;
    // None:       alpha = a (per-sample opacity, a textbook shader);
    // Extinction: alpha = 1 - exp(-a d density_scale) (OSPRay: a is an extinction coefficient).
    using Correction = ProfileRules::Correction;
    Correction correction = Correction::Power;
    double correction_floor = 0.0;  // Power: entries with a <= floor are left as they are
    double density_scale = 1.0;     // Extinction

    // --- compositing and termination (march/Accumulators.h) -----------------------------------------
    // Front to back, premultiplied, C += T alpha c with the transmittance T kept by the rule
    // (march/Accumulators.h, TransmittanceRule): OpticalDepth (tau += -log1p(-alpha), T = exp(-tau): the
    // reference), Product (T *= 1 - alpha), OpacitySum (A += (1 - A) alpha, T = 1 - A: GPU shaders);
    // stopping by `termination` after every sample (an opaque sample, alpha = 1, also stops OpticalDepth
    // and Product; under OpacitySum it makes A = 1 and every later sample adds 0).
    // Lerp: seed 001: back to front, sum = lerp(sum, (c, a), a density) on R, G, B, A (density:
    // render.profile_options.density); no termination.
    using Compositing = ProfileRules::Compositing;
    Compositing compositing = Compositing::OpacitySum;
    // When a front-to-back ray stops: A > alpha_above (VTK GPU: 1 - 1/255), A >= alpha_at_least (a
    // textbook shader: 1; OSPRay: T <= 0.001, i.e. A >= 0.999).
    Termination termination{};

    // --- gradients and shading --------------------------------------------------------------------
    // Central differences of the clamped field at +-gradient_offset voxels (per axis), or forward
    // differences f(x + h) - f(x) (Gradient::Forward), or central with the stencil inside the domain
    // (Gradient::CentralInDomain: the reference's). normal_along_gradient: the renderer's
    // normal is +grad f (VTK's GLSL) rather than this contract's -grad f. clamp_shaded: the shaded
    // colour is clamped to [0, 1] before compositing.
    double gradient_offset = 1.0;  // voxels
    double gradient_offset_texture = 0.0;  // > 0: the offset is this fraction of the domain's extent per axis
    using Gradient = ProfileRules::Gradient;
    Gradient gradient = Gradient::Central;
    bool normal_along_gradient = false;
    bool clamp_shaded = false;

    // --- the projections of values ----------------------------------------------------------------
    enum class Average {
        MeanCoordinate,              // g = the length-weighted mean of the transfer function's coordinate
        MeanOpacityTimesNormalised,  // VTK's GPU shader: g = mean_k opacity(v_k) s_k (uncorrected table)
    };
    Average average = Average::MeanCoordinate;
    enum class Xray {
        LineIntegral,            // g = gain sum_k coordinate(v_k) d_k
        BrightnessTimesMaximum,  // seed 001: g = brightness max_k s_k
    };
    Xray xray = Xray::LineIntegral;

    // --- slicers (placement Slices; Slices.h, FrameBuffer.h) ----------------------------------------
    // The sampling surfaces, what a slice fragment computes and the frame buffer that blends them
    // (conventions section 9, "Slice-order renderers"); read only under placement Slices.
    ProfileRules::Slices slices{};
    using Texture = ProfileRules::Texture;
    Texture texture = Texture::Texture3d;
    using TexelFormat = ProfileRules::TexelFormat;
    TexelFormat texel_format = TexelFormat::Float;
    using TextureWindow = ProfileRules::TextureWindow;
    TextureWindow texture_window = TextureWindow::TransferRows;
    glm::dvec2 texture_window_given{0.0, 1.0};
    using TableLookup = ProfileRules::TableLookup;
    TableLookup table_lookup = TableLookup::Texture;
    using TableFormat = ProfileRules::TableFormat;
    TableFormat table_format = TableFormat::Float;
    using SliceClassify = ProfileRules::SliceClassify;
    SliceClassify classify = SliceClassify::Post;
    using FrameBuffer = ProfileRules::FrameBuffer;
    FrameBuffer framebuffer = FrameBuffer::Double;
    using Rounding = ProfileRules::Rounding;
    Rounding framebuffer_rounding = Rounding::Nearest;
    using BlendProducts = ProfileRules::BlendProducts;
    BlendProducts blend_products = BlendProducts::Exact;
    using Blend = ProfileRules::Blend;
    Blend blend = Blend::SrcAlpha;
    using BlendAlpha = ProfileRules::BlendAlpha;
    BlendAlpha blend_alpha = BlendAlpha::SrcAlpha;
    using TextureFilter = ProfileRules::TextureFilter;
    TextureFilter texture_filter = TextureFilter::Exact;
};

// The preset a scene names (render.profile, or its "base").
const Profile& profile(ProfileId id);

// The profile a scene renders with: the preset render.profile names with the scene's rules
// (render.profile as an object) set over it; `name` says "custom (base ...)" when a rule is set.
Profile resolve_profile(const RenderSpec& render);

// Every rule of a ray-casting profile as render.profile's object holds it ("base" the preset's name),
// for volref.profiles() and the resolved scene; the image-space renderers (vtk-cpu, vtk-js) and "fast"
// give {"base": name} alone.
nlohmann::json profile_rules_json(const Profile& p);

// The resolved scene's render.profile (SceneWriter.h writes the scene's own form; python/SceneInput.cpp
// puts this in its place): every rule of resolve_profile(render), texture_unit and arithmetic where the
// scene set them as rules.
nlohmann::json resolved_profile_json(const RenderSpec& render);

// The presets, in the order `volref info` lists them.
const std::vector<ProfileId>& preset_ids();

}  // namespace volref
