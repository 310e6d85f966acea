// Profile: a data description of another renderer's discretisation (conventions section 9), applied
// to the same scene by ProfileIntegrator. A profile never changes the scene (volume, transfer
// functions, camera, lights, step); it changes where samples are taken, how a transfer-function
// opacity becomes a sample's alpha, whether the transfer function is read through a table, the
// gradient scheme, the compositing formula and when a ray stops. Every number here is one renderer's
// convention, with its source; docs/conventions.md section 9 gives the formulas.
#pragma once
#include <string>

#include "core/scene/Scene.h"

namespace volref {

struct Profile {
    ProfileId id = ProfileId::Reference;
    const char* name = "reference";

    // Where the samples of one interval [t0, t1] (length L, step h) lie.
    enum class Placement {
        // The reference: segments of h, sampled at their midpoints, weighted by their lengths.
        Midpoints,
        // t0 + (first + k) h for k = 0 .. n-1, n = max(1, floor(L / h + 1 - first)) (at least one
        // sample, even when the chord is shorter than first * h; VTK's GPU shader samples before it
        // tests the exit). Positions past t1 read the texture clamped to the domain.
        FromEntry,
    };
    Placement placement = Placement::Midpoints;
    double first = 0.0;  // FromEntry: the first sample's distance from the entry, in steps

    // How a transfer-function opacity a (per unit distance l) becomes the alpha of one sample.
    enum class Correction {
        Power,       // alpha = 1 - (1 - a)^(h / l) applied to the table entries with a > floor (VTK GPU)
        None,        // alpha = a (per-sample opacity, a textbook shader)
        Extinction,  // alpha = 1 - exp(-a h density_scale) (OSPRay: a is an extinction coefficient)
    };
    Correction correction = Correction::Power;
    double correction_floor = 0.0;  // Power: entries with a <= floor are left as they are
    double density_scale = 1.0;     // Extinction

    // The transfer function read through 1-D tables of `table_entries` entries built at
    // min + j (max - min) / (N - 1) over the volume's data range [min, max] and read with linear
    // filtering at texel position s N - 0.5 (s = (v - min) / (max - min), clamped to the edge
    // texels, as an OpenGL texture with GL_LINEAR and CLAMP_TO_EDGE does). 0: the exact function.
    int table_entries = 0;

    // Front to back, premultiplied: C += (1 - A) alpha c, A += (1 - A) alpha; the ray stops once
    // A > terminate_above (VTK GPU: 1 - 1/255) or A >= terminate_at (a textbook shader: 1;
    // OSPRay: T <= 0.001, i.e. A >= 0.999). Values above 1 never stop.
    double terminate_above = 2.0;
    double terminate_at = 2.0;

    // Shading. Central differences of the clamped field at +-gradient_offset voxels (per axis), or
    // forward differences f(x + h) - f(x) when `forward`. normal_along_gradient: the renderer's
    // normal is +grad f (VTK's GLSL) rather than this contract's -grad f. clamp_shaded: the shaded
    // colour is clamped to [0, 1] before compositing.
    double gradient_offset = 1.0;  // voxels
    double gradient_offset_texture = 0.0;  // > 0: the offset is this fraction of the domain's extent per axis
    bool forward_gradient = false;
    bool normal_along_gradient = false;
    bool clamp_shaded = false;

    // Back to front with sum = lerp(sum, col, col.a * density) (RGBA, col = (c, a) from the table;
    // render.profile_options.density) instead of front-to-back compositing; no termination.
    bool lerp_back_to_front = false;
    // Tables read at s * render.profile_options.transfer_scale instead of s.
    bool scaled_table = false;
    // Composite skips samples with s < render.profile_options.iso_threshold.
    bool iso_skip = false;
    // X-ray: g = brightness * max_k s_k instead of the line integral.
    bool xray_maximum = false;
    // step_units "voxel": a voxel is size / n (extent over the sample count) rather than the spacing
    // size / (n - 1): the step is multiplied by (n - 1) / n, n the dims of the grid's axis of smallest
    // spacing (Cartesian) or the largest dims (shells).
    bool step_size_over_n = false;
    // The profile renders beam-space (shell) grids too: no domain clamping, no gradients.
    bool shells = false;

    // vtkFixedPointVolumeRayCastMapper (VtkCpuProfile.h): the whole discretisation (internal image,
    // 15-bit fixed-point ray casting, texture display) is that file's; the fields above are unused.
    bool vtk_fixed_point = false;

    // Average projection: VTK's GPU shader averages opacity(v) * s (s the value normalised over the
    // data range, opacity the uncorrected table) over the samples and writes it as grey, alpha 1.
    bool average_opacity_weighted = false;
};

// The profile a scene names (render.profile).
const Profile& profile(ProfileId id);

}  // namespace volref
