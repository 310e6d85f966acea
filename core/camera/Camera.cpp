#include "core/camera/Camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/Conventions.h"
#include "core/Lanes.h"

namespace volref {

#include "core/camera/CameraRay-inl.h"

// CameraRays.cpp: the same rays on SIMD lanes.
void camera_pixel_rays(const CameraRayConstants& k, const int* x, const int* y, int count, Ray* out);

namespace {
double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }
}  // namespace

Camera::Camera(const CameraSpec& spec, int width, int height, const glm::dvec3& bounds_min,
               const glm::dvec3& bounds_max) {
    rays_.width = double(width);
    rays_.height = double(height);
    rays_.aspect = rays_.width / rays_.height;
    CameraSpec s = spec;
    if (s.type == CameraSpec::Type::Default) {
        const glm::dvec3 c = 0.5 * (bounds_min + bounds_max);
        const double radius = 0.5 * glm::length(bounds_max - bounds_min);
        const double half_v = radians(s.fov_y) / 2.0;
        const double half_h = std::atan(std::tan(half_v) * rays_.aspect);
        const double theta = std::min(half_v, half_h);
        s.type = CameraSpec::Type::Perspective;
        s.target = c;
        s.eye = c + glm::dvec3(0.0, 0.0, radius / std::sin(theta));
        s.up = glm::dvec3(0.0, 1.0, 0.0);
    }
    switch (s.type) {
        case CameraSpec::Type::Perspective:
        case CameraSpec::Type::Orthographic:
        {
            kind_ = s.type == CameraSpec::Type::Perspective ? Kind::Perspective : Kind::Orthographic;
            const glm::dvec3 forward = glm::normalize(s.target - s.eye);
            const glm::dvec3 right = glm::normalize(glm::cross(forward, s.up));
            const glm::dvec3 up = glm::cross(right, forward);
            rays_.perspective = kind_ == Kind::Perspective;
            rays_.tan_half_fov = std::tan(radians(s.fov_y) / 2.0);
            rays_.half_height = s.height / 2.0;
            for (int a = 0; a < 3; ++a) {
                rays_.eye[a] = s.eye[a];
                rays_.forward[a] = forward[a];
                rays_.right[a] = right[a];
                rays_.up[a] = up[a];
            }
            break;
        }
        default:
            kind_ = Kind::Matrices;
            view_ = s.view;
            inverse_view_ = glm::inverse(s.view);
            inverse_view_projection_ = glm::inverse(s.projection * s.view);
            break;
    }
}

glm::dvec3 Camera::eye() const {
    if (kind_ == Kind::Matrices) return glm::dvec3(inverse_view_ * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    return glm::dvec3(rays_.eye[0], rays_.eye[1], rays_.eye[2]);
}

glm::dvec3 Camera::forward() const {
    if (kind_ == Kind::Matrices) return glm::normalize(glm::dvec3(inverse_view_ * glm::dvec4(0.0, 0.0, -1.0, 0.0)));
    return glm::dvec3(rays_.forward[0], rays_.forward[1], rays_.forward[2]);
}

// A `matrices` camera is perspective when two pixels' rays start at the same point (the eye).
bool Camera::perspective() const {
    if (kind_ != Kind::Matrices) return kind_ == Kind::Perspective;
    const Ray a = ray(0.0, 0.0), b = ray(rays_.width, rays_.height);
    return glm::length(a.origin - b.origin) <= 1e-9 * (1.0 + glm::length(a.origin));
}

glm::dvec2 Camera::ndc(double fx, double fy) const {
    glm::dvec2 n;
    camera_ndc_lanes<Scalar>(rays_.width, rays_.height, fx, fy, n.x, n.y);
    return n;
}

Ray Camera::ray(double fx, double fy) const {
    Ray r;
    switch (kind_) {
        case Kind::Perspective:
        case Kind::Orthographic: {
            double o[3], d[3];
            camera_ray_lanes<Scalar>(rays_, fx, fy, o, d);
            r.origin = {o[0], o[1], o[2]};
            r.direction = {d[0], d[1], d[2]};
            break;
        }
        case Kind::Matrices: {
            const glm::dvec2 device = ndc(fx, fy);
            const double nx = device.x, ny = device.y;
            const glm::dvec4 n4 = inverse_view_projection_ * glm::dvec4(nx, ny, -1.0, 1.0);
            const glm::dvec4 f4 = inverse_view_projection_ * glm::dvec4(nx, ny, 1.0, 1.0);
            const glm::dvec3 n = glm::dvec3(n4) / n4.w, f = glm::dvec3(f4) / f4.w;
            r.direction = glm::normalize(f - n);
            // Move N along the line to view-space z = 0 (the eye's plane).
            const double zn = (view_ * glm::dvec4(n, 1.0)).z;
            const double dz = (view_ * glm::dvec4(r.direction, 0.0)).z;
            r.origin = n - (zn / dz) * r.direction;
            break;
        }
    }
    return r;
}

Ray Camera::pixel_ray(int x, int y) const {
    return ray(double(x) + conventions::kPixelCentre, double(y) + conventions::kPixelCentre);
}

void Camera::pixel_rays(const int* x, const int* y, int count, Ray* out) const {
    if (kind_ == Kind::Matrices) {
        for (int i = 0; i < count; ++i) out[i] = pixel_ray(x[i], y[i]);
        return;
    }
    camera_pixel_rays(rays_, x, y, count, out);
}

}  // namespace volref
