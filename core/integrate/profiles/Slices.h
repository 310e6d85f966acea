// A slicer's sampling surfaces (conventions section 9, "Slice-order renderers"): OpenGL
// Volumizer and every 2D/3D-texture slicer cut the volume's geometry with a family of surfaces, the
// level sets lambda(x) = lambda_k of one function, and a pixel's samples are its centre ray's crossings
// with them. SliceLattice is that family for one frame (built once, from the camera and the geometry's
// box); for_each_crossing places one ray's samples, the placement "slices" of ProfileIntegrator.
//   viewport:  lambda(x) = (x - E) . f            (planes of constant eye depth)
//   axis:      lambda(x) = sign(w_a) x_a           (a = argmax |w_a|, ties x, y, z)
//   spherical: lambda(x) = |x - E|                 (shells about the eye)
// Levels lambda_k, k = 0 .. n - 1, from the far bound; a crossing t_k stands for d_k = s / |dlambda/dt|,
// s the levels' spacing (planes: s / |n . d|; shells from the eye: s).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/scene/Scene.h"
#include "geometry/RayIntervals.h"

namespace volref {

class Camera;
struct Profile;

struct SliceLattice {
    using Orientation = ProfileRules::Slices::Orientation;
    Orientation orientation = Orientation::Viewport;
    glm::dvec3 eye{0.0};     // E
    glm::dvec3 normal{0.0};  // planes: lambda(x) = normal . x + offset (|normal| = 1)
    double offset = 0.0;
    int axis = -1;           // axis orientation: the slicing axis a
    std::vector<double> levels;  // lambda_k, k = 0 the farthest
    double spacing = 0.0;        // the levels' spacing s (lambda units: world units)
    bool back_to_front = true;
    // camera.near / far: a crossing is kept when near <= (x - E) . f <= far.
    bool depth_clip = false;
    double near = 0.0, far = 0.0;
    glm::dvec3 forward{0.0, 0.0, -1.0};

    // fn(t, d, k): the crossing of level k at ray parameter t, standing for the length d, in the
    // order of `back_to_front`; fn returns false to stop. The crossings kept: t >= 0, inside one of
    // `intervals` (closed), and within the depth clip.
    template <class Fn>
    void for_each_crossing(const Ray& ray, const std::vector<Interval>& intervals, Fn&& fn) const;

    // The crossing of level k by `ray` (planes: one; shells: the farther root, t >= 0), and the length d
    // it stands for; false when the ray does not cross it.
    bool crossing(const Ray& ray, std::size_t k, double& t, double& d) const;
};

// The lattice of a frame: `box_lo`, `box_hi` the geometry's bounding box (the range "object"), the
// volume's origin, spacing and dims (periods in voxels, 2D textures' layers), `step` the scene's step
// in world units (the default spacing), `step_scale` world units per unit of render.step_units (the
// spacing's units). Throws volref::Error naming render.profile.slices (or camera) for what cannot be
// placed: spherical with an orthographic camera, view_volume without near/far, too many levels.
SliceLattice make_slice_lattice(const Profile& p, const Camera& camera, const CameraSpec& spec, const glm::dvec3& box_lo,
                                const glm::dvec3& box_hi, const glm::dvec3& origin, const glm::dvec3& spacing,
                                const std::array<std::int64_t, 3>& dims, double step, double step_scale);

template <class Fn>
void SliceLattice::for_each_crossing(const Ray& ray, const std::vector<Interval>& intervals, Fn&& fn) const {
    if (intervals.empty() || levels.empty()) return;
    const double lo = intervals.front().t0, hi = intervals.back().t1;
    auto inside = [&](double t) {
        if (!(t >= 0.0 && t >= lo && t <= hi)) return false;
        bool in = false;
        for (const Interval& iv : intervals)
            if (t >= iv.t0 && t <= iv.t1) {
                in = true;
                break;
            }
        if (!in) return false;
        if (depth_clip) {
            const double z = glm::dot(ray.at(t) - eye, forward);
            if (!(z >= near && z <= far)) return false;
        }
        return true;
    };
    // The levels the chord [max(lo, 0), hi] can cross (levels fall by `spacing` from levels[0]), widened
    // by one each way; each is still tested exactly below.
    const std::size_t n = levels.size();
    std::size_t k0 = 0, k1 = n;  // [k0, k1)
    if (n > 1 && spacing > 0.0) {
        const double ta = std::max(lo, 0.0), tb = hi;
        double l_min = 0.0, l_max = 0.0;
        if (orientation == Orientation::Spherical) {
            const glm::dvec3 a = ray.at(ta) - eye, b = ray.at(tb) - eye;
            const double dd = glm::dot(ray.direction, ray.direction);
            const double tc = dd > 0.0 ? std::clamp(-glm::dot(ray.origin - eye, ray.direction) / dd, ta, tb) : ta;
            l_min = glm::length(ray.at(tc) - eye);
            l_max = std::max(glm::length(a), glm::length(b));
        } else {
            const double base = glm::dot(normal, ray.origin) + offset, rate = glm::dot(normal, ray.direction);
            l_min = std::min(base + ta * rate, base + tb * rate);
            l_max = std::max(base + ta * rate, base + tb * rate);
        }
        const double first = std::floor((levels[0] - l_max) / spacing) - 1.0, last = std::ceil((levels[0] - l_min) / spacing) + 2.0;
        if (std::isfinite(first) && std::isfinite(last)) {
            k0 = std::size_t(std::clamp(first, 0.0, double(n)));
            k1 = std::size_t(std::clamp(last, 0.0, double(n)));
        }
    }
    for (std::size_t j = k0; j < k1; ++j) {
        const std::size_t k = back_to_front ? j : k0 + k1 - 1 - j;
        double t = 0.0, d = 0.0;
        if (!crossing(ray, k, t, d) || !inside(t)) continue;
        if (!fn(t, d, k)) return;
    }
}

}  // namespace volref
