#include "core/camera/Camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/Conventions.h"

namespace volref {

namespace {
double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }
}  // namespace

Camera::Camera(const CameraSpec& spec, int width, int height, const glm::dvec3& bounds_min,
               const glm::dvec3& bounds_max)
    : width_(width), height_(height), aspect_(double(width) / double(height)) {
    CameraSpec s = spec;
    if (s.type == CameraSpec::Type::Default) {
        const glm::dvec3 c = 0.5 * (bounds_min + bounds_max);
        const double radius = 0.5 * glm::length(bounds_max - bounds_min);
        const double half_v = radians(s.fov_y) / 2.0;
        const double half_h = std::atan(std::tan(half_v) * aspect_);
        const double theta = std::min(half_v, half_h);
        s.type = CameraSpec::Type::Perspective;
        s.target = c;
        s.eye = c + glm::dvec3(0.0, 0.0, radius / std::sin(theta));
        s.up = glm::dvec3(0.0, 1.0, 0.0);
    }
    switch (s.type) {
        case CameraSpec::Type::Perspective:
        case CameraSpec::Type::Orthographic:
            kind_ = s.type == CameraSpec::Type::Perspective ? Kind::Perspective : Kind::Orthographic;
            eye_ = s.eye;
            forward_ = glm::normalize(s.target - s.eye);
            right_ = glm::normalize(glm::cross(forward_, s.up));
            up_ = glm::cross(right_, forward_);
            tan_half_fov_ = std::tan(radians(s.fov_y) / 2.0);
            half_height_ = s.height / 2.0;
            break;
        default:
            kind_ = Kind::Matrices;
            view_ = s.view;
            inverse_view_ = glm::inverse(s.view);
            inverse_view_projection_ = glm::inverse(s.projection * s.view);
            break;
    }
}

Ray Camera::ray(double fx, double fy) const {
    const glm::dvec2 device = ndc(fx, fy);
    const double nx = device.x, ny = device.y;
    Ray r;
    switch (kind_) {
        case Kind::Perspective:
            r.origin = eye_;
            r.direction = glm::normalize(forward_ + (nx * tan_half_fov_ * aspect_) * right_ + (ny * tan_half_fov_) * up_);
            break;
        case Kind::Orthographic:
            r.origin = eye_ + (nx * half_height_ * aspect_) * right_ + (ny * half_height_) * up_;
            r.direction = forward_;
            break;
        case Kind::Matrices: {
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

}  // namespace volref
