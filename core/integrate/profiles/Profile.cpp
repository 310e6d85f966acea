#include "core/integrate/profiles/Profile.h"

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/scene/ProfileRuleTable.h"
#include "core/scene/SceneNames.h"
#include "core/scene/SceneWriter.h"

namespace volref {

namespace {

// The reference's conventions as rules: what a custom profile on base "reference" starts
// from. The reference itself renders through its own integrators (RenderSpec::reference_integrators);
// this preset's ProfileIntegrator differs from them only in rounding (and from a gradient cache, volume.
// gradient.cache, by its interpolation).
Profile make_reference() {
    Profile p;
    p.compositing = Profile::Compositing::OpticalDepth;
    p.gradient = Profile::Gradient::CentralInDomain;
    return p;
}

// vtkGPUVolumeRayCastMapper of VTK 9.1 (its GLSL, vtkVolumeShaderComposer.h, and the opacity and
// colour tables vtkOpenGLVolumeOpacityTable / vtkOpenGLVolumeRGBTable), as the shared spec's section 9
// describes it and as measured against python3-vtk9 under Mesa llvmpipe (scripts/vtk-parity.sh).
Profile make_vtk_gpu() {
    Profile p;
    p.id = ProfileId::VtkGpu;
    p.name = "vtk-gpu";
    p.placement = Profile::Placement::FromEntry;
    p.first = 1.0;  // no jittering: the first sample one step inside
    p.correction = Profile::Correction::Power;
    p.correction_floor = 1e-4;
    p.table_entries = 1024;
    p.termination.test_alpha_above = true;
    p.termination.alpha_above = 1.0 - 1.0 / 255.0;
    p.gradient_offset = 1.0;
    p.normal_along_gradient = true;
    p.clamp_shaded = true;
    p.average = Profile::Average::MeanOpacityTimesNormalised;
    return p;
}

// vtkFixedPointVolumeRayCastMapper of VTK 9.1, its CPU mapper: 15-bit fixed point throughout, on an
// internal image drawn as a stretched texture: its own renderer (VtkFixedPointRenderer.h has it;
// (conventions section 9 states each formula).
Profile make_vtk_cpu() {
    Profile p;
    p.id = ProfileId::VtkCpu;
    p.name = "vtk-cpu";
    p.renderer = Profile::Renderer::VtkFixedPoint;
    return p;
}

// VolPack 1.0b3's shear-warp: its own renderer (VolPackRenderer.h), its inputs
// render.profile_options (docs/conventions.md, "VolPack").
Profile make_volpack() {
    Profile p;
    p.id = ProfileId::VolPack;
    p.name = "volpack";
    p.renderer = Profile::Renderer::VolPack;
    return p;
}

// A textbook GLSL ray caster: samples from the entry point on, acc += (1 - acc.a) col.a col
// with the transfer function's opacity used as the sample's alpha (no correction), stop at alpha >= 1,
// central differences at +-0.1 in texture coordinates ([0, 1] over the volume's domain).
Profile make_glsl_basic() {
    Profile p;
    p.id = ProfileId::GlslBasic;
    p.name = "glsl-basic";
    p.placement = Profile::Placement::FromEntry;
    p.first = 0.0;
    p.correction = Profile::Correction::None;
    p.termination.test_alpha_at_least = true;
    p.termination.alpha_at_least = 1.0;
    p.gradient_offset = 0.0;
    p.gradient_offset_texture = 0.1;
    // Seed 002: acc += (1 - acc.a) * K * tf(v).a * v.rrra, samples with v < 0.01 skipped,
    // getNormalFromVol's normal = +grad f.
    p.color_from_value = true;
    p.value_cutoff = 0.01;
    p.alpha_times_intensity = true;
    p.normal_along_gradient = true;
    return p;
}

// OSPRay SciVis / Open VKL (spec section 9): alpha = 1 - exp(-a dt densityScale) with
// densityScale 1 (the transfer-function opacity taken as an extinction coefficient per world unit),
// forward-difference gradients (one voxel), termination at T <= 0.001. Placement: the reference's
// segment midpoints (OSPRay jitters its samples inside each step; without jitter the midpoint is the
// expected position).
Profile make_ospray() {
    Profile p;
    p.id = ProfileId::Ospray;
    p.name = "ospray";
    p.placement = Profile::Placement::Midpoints;
    p.correction = Profile::Correction::Extinction;
    p.density_scale = 1.0;
    p.termination.test_alpha_at_least = true;
    p.termination.alpha_at_least = 1.0 - 0.001;
    p.gradient_offset = 1.0;
    p.gradient = Profile::Gradient::Forward;
    return p;
}

// A CUDA ray caster for cylindrical and spherical data (shared spec section 9): samples from
// the entry point on at a step of size / n voxels, composited back to front by
// sum = lerp(sum, col, col.a * density) over the samples with s >= the iso threshold, the transfer
// function read from a 9-entry linearly filtered table over [0, 1] at s * transfer scale (texel position
// 9 u - 0.5, as CUDA's normalised linear texture fetch), x-ray = max s times brightness; unshaded.
Profile make_cuda_curvilinear() {
    Profile p;
    p.id = ProfileId::CudaCurvilinear;
    p.name = "cuda-curvilinear";
    p.placement = Profile::Placement::FromExit;  // the seed marches from outAbs towards inAbs
    p.first = 0.0;
    p.correction = Profile::Correction::None;
    p.table_entries = 9;
    p.compositing = Profile::Compositing::Lerp;
    p.table_coordinate = Profile::TableCoordinate::DataRangeTimesTransferScale;
    p.sample_filter = Profile::SampleFilter::AtOrAboveIsoThreshold;
    p.xray = Profile::Xray::BrightnessTimesMaximum;
    p.voxel_length = Profile::VoxelLength::ExtentOverSamples;
    p.grids = Profile::Grids::CartesianAndShells;
    p.seed_shell_reads = true;
    return p;
}

// vtk.js 37.4.3's WebGL2 volume mapper: its own integrator, VtkJsIntegrator.h (the fields
// below are not read; check_profile_applies reads grids).
Profile make_vtk_js() {
    Profile p;
    p.id = ProfileId::VtkJs;
    p.name = "vtk-js";
    p.renderer = Profile::Renderer::VtkJs;
    return p;
}

// OpenGL Volumizer (SGI, 1998; seed 003, ../shared/notes/volumizer.md): planes parallel to
// the viewport through the geometry's bounding box (samplingMode VIEWPORT_ALIGNED, samplingSpace OBJECT,
// the first plane on the far bound: L1202, L1231-1233), spaced by the scene's step (the guide's
// samplingPeriod of one voxel is `slices.period`), 3D textures of 8-bit texels over dataScaleRange
// (here the transfer function's rows, L1446), 256-entry 8-bit LUMINANCE_ALPHA tables read at the
// nearest entry (SGI_color_table, Example 3-1), no opacity correction for the spacing, blended back to
// front by glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA) into an 8-bit frame buffer (L1338, L1880).
// Axis slices with 2D textures (the guide's other mode) are `slices.orientation "axis"`, `texture "2d"`.
Profile make_volumizer() {
    Profile p;
    p.id = ProfileId::Volumizer;
    p.name = "volumizer";
    p.placement = Profile::Placement::Slices;
    p.correction = Profile::Correction::None;
    p.compositing = Profile::Compositing::OpacitySum;  // not read: the frame buffer blends
    p.table_entries = 256;
    p.table_lookup = Profile::TableLookup::Nearest;
    p.table_format = Profile::TableFormat::Unorm8;
    p.texel_format = Profile::TexelFormat::Unorm8;
    p.texture_window = Profile::TextureWindow::TransferRows;
    p.framebuffer = Profile::FrameBuffer::Rgba8;
    p.framebuffer_rounding = Profile::Rounding::Nearest;
    p.blend = Profile::Blend::SrcAlpha;
    p.blend_alpha = Profile::BlendAlpha::SrcAlpha;
    return p;
}

}  // namespace

const Profile& profile(ProfileId id) {
    static const Profile reference = make_reference(), vtk_gpu = make_vtk_gpu(), vtk_cpu = make_vtk_cpu(),
                         glsl_basic = make_glsl_basic(),
                         ospray = make_ospray(), cuda_curvilinear = make_cuda_curvilinear(), vtk_js = make_vtk_js(),
                         volumizer = make_volumizer(), volpack = make_volpack();
    switch (id) {
        case ProfileId::Reference: return reference;
        case ProfileId::VtkGpu: return vtk_gpu;
        case ProfileId::VtkCpu: return vtk_cpu;
        case ProfileId::GlslBasic: return glsl_basic;
        case ProfileId::Ospray: return ospray;
        case ProfileId::CudaCurvilinear: return cuda_curvilinear;
        case ProfileId::VtkJs: return vtk_js;
        case ProfileId::Volumizer: return volumizer;
        case ProfileId::VolPack: return volpack;
        case ProfileId::Fast: break;  // not a mirror profile: the reference's integrators (FastProfile.h)
    }
    throw Error("render.profile: unknown profile");
}

const std::vector<ProfileId>& preset_ids() {
    static const std::vector<ProfileId> ids{ProfileId::Reference, ProfileId::Fast,  ProfileId::VtkGpu,
                                            ProfileId::VtkCpu,    ProfileId::VtkJs, ProfileId::GlslBasic,
                                            ProfileId::Ospray,    ProfileId::CudaCurvilinear, ProfileId::Volumizer,
                                            ProfileId::VolPack};
    return ids;
}

namespace {

std::string preset_name(ProfileId id) { return scene_names::name_of(scene_names::kProfiles, id); }

// The rule "termination" as Profile::termination, the accumulators' Termination (march/Accumulators.h),
// and back: the one rule whose resolved form is not a scene type (ProfileRuleTable.h).
Termination termination_of(ProfileRules::Stop stop, double value) {
    Termination t;
    switch (stop) {
        case ProfileRules::Stop::None: break;
        case ProfileRules::Stop::AlphaAbove:
            t.test_alpha_above = true;
            t.alpha_above = value;
            break;
        case ProfileRules::Stop::AlphaAtLeast:
            t.test_alpha_at_least = true;
            t.alpha_at_least = value;
            break;
        case ProfileRules::Stop::TransmittanceAtMost:
            t.test_transmittance = true;
            t.transmittance_at_most = value;
            break;
    }
    return t;
}

void capture_termination(const Termination& t, ProfileRules& r) {
    r.termination = t.test_alpha_above      ? ProfileRules::Stop::AlphaAbove
                    : t.test_alpha_at_least ? ProfileRules::Stop::AlphaAtLeast
                    : t.test_transmittance  ? ProfileRules::Stop::TransmittanceAtMost
                                            : ProfileRules::Stop::None;
    r.termination_value = t.test_alpha_above ? t.alpha_above : t.test_alpha_at_least ? t.alpha_at_least : t.transmittance_at_most;
}

}  // namespace

Profile resolve_profile(const RenderSpec& render) {
    if (render.profile == ProfileId::Fast) {
        Profile p;
        p.id = ProfileId::Fast;
        p.name = "fast";
        return p;
    }
    Profile p = profile(render.profile);
    const ProfileRules& r = render.profile_rules;
    if (r.empty()) return p;
    p.name = std::string("custom (base ") + preset_name(render.profile) + ")";
    for (const ProfileRule& rule : profile_rule_table())
        if (rule.apply) rule.apply(r, p);
    if (r.termination) p.termination = termination_of(*r.termination, r.termination_value);
    return p;
}

nlohmann::json profile_rules_json(const Profile& p) {
    nlohmann::json j;
    j["base"] = preset_name(p.id);
    if (p.renderer != Profile::Renderer::RayCaster || p.id == ProfileId::Fast) return j;
    // Every rule the profile's placement reads, written by the scene writer's own inverse of the
    // loader (SceneWriter.h, profile_rules_object).
    ProfileRules r;
    for (const ProfileRule& rule : profile_rule_table())
        if (rule.capture && rule.read_under(p.placement)) rule.capture(p, r);
    if (find_profile_rule("termination")->read_under(p.placement)) capture_termination(p.termination, r);
    j.update(profile_rules_object(r));
    for (const ProfileRule& rule : profile_rule_table())
        if (rule.only_value) j[std::string(rule.key)] = rule.only_value;  // jitter "off"
    return j;
}

nlohmann::json resolved_profile_json(const RenderSpec& render) {
    nlohmann::json j = profile_rules_json(resolve_profile(render));
    // The rules that are render.profile_options too, where the scene set them as rules (the base's
    // options otherwise).
    for (const ProfileRule& rule : profile_rule_table())
        if (!rule.option.empty()) rule.write(render.profile_rules, j);
    return j;
}

}  // namespace volref
