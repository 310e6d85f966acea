// Profile: a data description of another renderer's discretisation (conventions section 9), applied
// to the same scene by ProfileIntegrator. A profile never changes the scene (volume, transfer
// functions, camera, lights, step); it changes where samples are taken, how a transfer-function
// opacity becomes a sample's alpha, whether the transfer function is read through a table, the
// gradient scheme, the compositing rule and when a ray stops: each a rule (ProfileRuleValues,
// core/scene/Scene.h), read by one renderer (ProfileIntegrator, or VtkFixedPointRenderer for VTK's
// fixed-point mapper). Every number in a preset (Profile.cpp) is one renderer's convention, with its
// source; docs/conventions.md section 9 gives the formulas.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/integrate/march/Accumulators.h"
#include "core/scene/Scene.h"

namespace volref {

// The rules themselves (placement, correction, compositing, gradients, the slicers' rules...) are
// ProfileRuleValues (core/scene/Scene.h, each with its formula), read and written through the rule table
// (core/scene/ProfileRuleTable.h); a Profile adds what a scene cannot set as a rule.
struct Profile : ProfileRuleValues {
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

    // --- classification ---------------------------------------------------------------------------
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

    // --- termination (march/Accumulators.h) ---------------------------------------------------------
    // When a front-to-back ray stops, tested after every sample: A > alpha_above (VTK GPU: 1 - 1/255),
    // A >= alpha_at_least (a textbook shader: 1; OSPRay: T <= 0.001, i.e. A >= 0.999). An opaque sample
    // (alpha = 1) also stops OpticalDepth and Product; under OpacitySum it makes A = 1 and every later
    // sample adds 0. The rule "termination" sets it (resolve_profile: the accumulators' own type, which
    // the scene's rule table does not name).
    Termination termination{};

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
