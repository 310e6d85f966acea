// Camera: the primary ray of each pixel (conventions section 10).
//
// Film coordinates: pixel (x, y), x to the right, y downwards, row 0 at the top; the ray goes through
// (x + 0.5, y + 0.5). With W x H pixels, aspect = W / H and the normalised device coordinates
//   nx = 2 (x + 0.5) / W - 1,   ny = 1 - 2 (y + 0.5) / H            (both in (-1, 1)):
// - perspective (eye, target, up, fov_y): forward f = normalize(target - eye), right
//   r = normalize(f x up), true up u = r x f; direction = normalize(f + nx tan(fov_y/2) aspect r
//   + ny tan(fov_y/2) u), origin = eye.
// - orthographic (eye, target, up, height h): direction = f, origin = eye + nx (h/2) aspect r +
//   ny (h/2) u.
// - matrices (view V, projection P, OpenGL): the points N = (PV)^-1 (nx, ny, -1, 1) and
//   F = (PV)^-1 (nx, ny, 1, 1) (dehomogenised) give direction = normalize(F - N); the origin is the
//   point of that line on the eye's plane (view-space z = 0): the eye itself for a perspective P.
// - default: perspective, fov_y 30, looking along -z at the centre c of the bounds, up +y, at the
//   distance d = R / sin(theta) from c, where R is the bounds' half diagonal and theta is half the
//   smaller of the vertical and horizontal fields of view (as VTK's ResetCamera; the whole bounding
//   sphere is in view).
// Rays are integrated for t >= 0 only (there is no near plane).
#pragma once
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/camera/Ray.h"
#include "core/scene/Scene.h"

namespace volref {

// The film's size and the constants of the perspective and orthographic cameras' rays (CameraRay-inl.h's
// formula).
struct CameraRayConstants {
    bool perspective = true;  // else orthographic
    double width = 1.0, height = 1.0, aspect = 1.0;
    double tan_half_fov = 0.0, half_height = 0.0;
    double eye[3] = {}, forward[3] = {}, right[3] = {}, up[3] = {};
};

class Camera {
public:
    // `bounds_min`/`bounds_max` are used by the default camera only.
    Camera(const CameraSpec& spec, int width, int height, const glm::dvec3& bounds_min,
           const glm::dvec3& bounds_max);

    // The ray through film point (fx, fy) (pixel centres at integer + 0.5).
    Ray ray(double fx, double fy) const;
    Ray pixel_ray(int x, int y) const;
    // pixel_ray(x[i], y[i]) for i < count, the same rays; on SIMD lanes for the perspective and
    // orthographic cameras (CameraRays.cpp).
    void pixel_rays(const int* x, const int* y, int count, Ray* out) const;
    // The normalised device coordinates (nx, ny) of film point (fx, fy) that ray() uses.
    glm::dvec2 ndc(double fx, double fy) const;
    // The eye E and the forward unit vector f (a `matrices` camera: the view's origin and -z axis), and
    // whether rays start at the eye (perspective) or on its plane (orthographic): the slicers' surfaces
    // (core/integrate/profiles/Slices.h) are placed from them.
    glm::dvec3 eye() const;
    glm::dvec3 forward() const;
    bool perspective() const;
    int width() const { return int(rays_.width); }
    int height() const { return int(rays_.height); }

private:
    enum class Kind { Perspective, Orthographic, Matrices } kind_;
    CameraRayConstants rays_;  // the film (every kind) and the perspective and orthographic rays
    glm::dmat4 inverse_view_projection_{1.0}, inverse_view_{1.0}, view_{1.0};
};

}  // namespace volref
