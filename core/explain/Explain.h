// The calculators of `volref explain TOPIC` (docs/explain.md): each works one formula of the
// renderer step by step, calling the renderer's own functions (Trilinear.h, VolumeSampler,
// OpacityCorrection.h, the classifiers, Shader, ShellCoordinates, BoxIntersection.h,
// ShellIntersection, Camera, the integrators through SampleRecorder) and returns the Explanation
// (Explanation.h) the command prints. Inputs are typed; the command line parses and checks them
// (cli/explain_command.cpp); the calculators throw volref::Error for values outside a formula's
// domain, naming the argument.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/explain/Explanation.h"
#include "core/scene/Scene.h"
#include "core/scene/ShellSpec.h"

namespace volref {

class VolumeSampler;
struct PreparedScene;
struct Volume;

namespace explain {

// trilinear: corners f1..f8 in Levoy's order (f1 (0,0,0), f2 (1,0,0), f3 (1,1,0), f4 (0,1,0), f5..f8
// the same at r = 1), local coordinates (p, q, r) in [0, 1].
Explanation trilinear(const std::array<double, 8>& corners, const glm::dvec3& pqr);
// trilinear at a world point of a Cartesian volume: the cell, its corners, the local coordinates,
// then the same steps.
Explanation trilinear_at(const VolumeSampler& sampler, const glm::dvec3& world);

// composite: samples listed front first, each colour (not premultiplied) and opacity a per unit
// distance l; each is one segment of length d, composited by CompositeIntegrator itself.
struct CompositeSample {
    glm::dvec3 color{1.0};
    double opacity = 0.0;
};
Explanation composite(const std::vector<CompositeSample>& samples, CompositeOrder order, double unit_distance,
                      double step);

// composite --framebuffer: the samples (listed front first) blended by a slicer's frame buffer,
// from the far end (or front to back, under, with `order`), each blend's source, factors, unrounded
// result and stored value (FrameBuffer.h), and the band of every rounding variant.
struct FrameBufferRules {
    ProfileRules::FrameBuffer format = ProfileRules::FrameBuffer::Rgba8;
    ProfileRules::Rounding rounding = ProfileRules::Rounding::Nearest;
    ProfileRules::BlendProducts products = ProfileRules::BlendProducts::Exact;
    ProfileRules::Blend blend = ProfileRules::Blend::SrcAlpha;
    ProfileRules::BlendAlpha blend_alpha = ProfileRules::BlendAlpha::SrcAlpha;
};
Explanation composite_framebuffer(const std::vector<CompositeSample>& samples, CompositeOrder order, const FrameBufferRules& rules);

// opacity-correction: a over l, segment length d.
Explanation opacity_correction(double a, double unit_distance, double length);

// classify-isovalue / classify-boundary: value f and gradient magnitude g.
Explanation classify_isovalue(double f, double g, const std::vector<IsovalueContour>& contours);
Explanation classify_boundary(double f, double g, const std::vector<BoundaryRegion>& regions);

// shade: gradient (N = -g / |g|), view vector V (towards the eye, unit), material colour m, depth d.
struct ShadeInput {
    glm::dvec3 gradient{0.0, 0.0, -1.0};
    glm::dvec3 view{0.0, 0.0, 1.0};
    glm::dvec3 material{1.0};
    double depth = 0.0;
    ShadingSpec spec;
    std::vector<LightSpec> lights{LightSpec{}};
};
Explanation shade(const ShadeInput& in);

// coords: a point given in one system (around `center`), in all three.
enum class CoordinateSystem { Cartesian, Cylindrical, Spherical };
// Cylindrical: (r, theta, h); spherical: (R, lon, lat); Cartesian: (x, y, z). Angles in degrees.
Explanation coords(CoordinateSystem given, const glm::dvec3& values, const glm::dvec3& center);

// intersect: a ray (direction normalised by the caller) against a box, a cylindrical or a spherical
// shell: every slab or root, the intervals.
Explanation intersect_box(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi);
Explanation intersect_cylinder(const Ray& ray, const CylindricalShell& shell);
Explanation intersect_sphere(const Ray& ray, const SphericalShell& shell);

// ray: pixel (x, y) of a prepared scene: the camera's ray, the intervals, every sample (the engine
// of `volref trace`, PixelTrace.h) and the pixel.
Explanation ray(const PreparedScene& scene, int x, int y);

// volpack-warp: output pixel (x, y) of a render.profile "volpack" scene through VolPack's 2D
// warp: the view's factorisation, the pixel mapped back, the stepped fixed-point fractions, the weight
// table's entry, the four intermediate pixels, the float sums and the truncated bytes.
Explanation volpack_warp(const PreparedScene& scene, int x, int y);
// volpack-voxel: voxel (x, y, z): its central differences, gradient byte and normal code, the tables,
// the 8-bit opacity and its correction, the shade-table entry.
Explanation volpack_voxel(const PreparedScene& scene, std::int64_t x, std::int64_t y, std::int64_t z);
// volpack-scene: the continuous scene the VolPack scene discretises (volpack_continuous_scene), as the
// scene file JSON (one note), composited by the reference at `step` voxels.
Explanation volpack_scene(const PreparedScene& scene, double step);

// texture-fetch: one linearly filtered fetch of a 3D texture (a u16 volume read as unorm16,
// an f32 volume as float) at a coordinate (unnormalised texels, texel i centred at i + 0.5, or normalised
// with `normalized`), by the H100 rule (`h100`, core/integrate/profiles/TextureUnit.h) or with exact
// weights, every step; throws volref::Error naming --volume for any other type.
Explanation texture_fetch(const Volume& volume, const glm::dvec3& at, bool h100, bool normalized);
// The same fetch at many points: one table, columns x, y, z, fetch.
Explanation texture_fetch_points(const Volume& volume, const std::vector<glm::dvec3>& points, bool h100, bool normalized);

}  // namespace explain
}  // namespace volref
