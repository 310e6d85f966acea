#include "core/integrate/profiles/Slices.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <glm/geometric.hpp>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/camera/Camera.h"
#include "core/integrate/profiles/Profile.h"

namespace volref {

bool SliceLattice::crossing(const Ray& ray, std::size_t k, double& t, double& d) const {
    const double level = levels[k];
    if (orientation == Orientation::Spherical) {
        // |w + t d|^2 = level^2, w = o - E: the larger root (the shell crossed outwards).
        const glm::dvec3 w = ray.origin - eye;
        const double a = glm::dot(ray.direction, ray.direction), b = glm::dot(w, ray.direction);
        const double c = glm::dot(w, w) - level * level;
        const double disc = b * b - a * c;
        if (!(disc >= 0.0) || !(a > 0.0)) return false;
        t = (-b + std::sqrt(disc)) / a;
        const double rate = std::fabs(glm::dot(w + t * ray.direction, ray.direction)) / level;  // dlambda/dt
        d = rate > 0.0 ? spacing / rate : 0.0;
        return true;
    }
    const double rate = glm::dot(normal, ray.direction);  // dlambda/dt along the ray
    if (rate == 0.0) return false;
    t = (level - (glm::dot(normal, ray.origin) + offset)) / rate;
    d = spacing / std::fabs(rate);
    return true;
}

namespace {

[[noreturn]] void fail(const std::string& key, const std::string& why) { throw Error("render.profile.slices." + key + ": " + why); }

std::array<glm::dvec3, 8> corners(const glm::dvec3& lo, const glm::dvec3& hi) {
    std::array<glm::dvec3, 8> c;
    for (int i = 0; i < 8; ++i) c[std::size_t(i)] = glm::dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    return c;
}

// The distance from p to the box (0 inside).
double box_distance(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 q = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return glm::length(q);
}

}  // namespace

SliceLattice make_slice_lattice(const Profile& p, const Camera& camera, const CameraSpec& spec, const glm::dvec3& box_lo,
                                const glm::dvec3& box_hi, const glm::dvec3& origin, const glm::dvec3& spacing,
                                const std::array<std::int64_t, 3>& dims, double step, double step_scale) {
    using O = ProfileRules::Slices::Orientation;
    using Range = ProfileRules::Slices::Range;
    const ProfileRules::Slices& s = p.slices;
    SliceLattice L;
    L.orientation = s.orientation;
    L.eye = camera.eye();
    L.forward = camera.forward();
    L.back_to_front = s.order == ProfileRules::Slices::Order::BackToFront;
    const bool perspective = camera.perspective();
    if (s.orientation == O::Spherical && !perspective)
        fail("orientation", "\"spherical\" shells about the eye need a perspective camera");
    if (s.range == Range::ViewVolume && !(spec.near && spec.far))
        fail("range", "\"view_volume\" needs camera.near and camera.far");
    if (spec.near && spec.far) {
        L.depth_clip = true;
        L.near = *spec.near;
        L.far = *spec.far;
    }
    const bool layers = p.texture == ProfileRules::Texture::Texture2d;
    if (layers && s.orientation != O::Axis)
        throw Error("render.profile.texture: \"2d\" textures are sliced along a grid axis (slices.orientation \"axis\")");

    // lambda and its normal.
    const glm::dvec3 centre = 0.5 * (box_lo + box_hi);
    if (s.orientation == O::Viewport) {
        L.normal = L.forward;
        L.offset = -glm::dot(L.forward, L.eye);
    } else if (s.orientation == O::Axis) {
        const glm::dvec3 w = perspective ? glm::normalize(centre - L.eye) : L.forward;
        int a = 0;
        for (int b = 1; b < 3; ++b)
            if (std::fabs(w[b]) > std::fabs(w[a])) a = b;  // ties: the first of x, y, z
        L.axis = a;
        L.normal = glm::dvec3(0.0);
        L.normal[a] = w[a] >= 0.0 ? 1.0 : -1.0;
        L.offset = 0.0;
    }
    auto lambda = [&](const glm::dvec3& x) {
        return s.orientation == O::Spherical ? glm::length(x - L.eye) : glm::dot(L.normal, x) + L.offset;
    };

    // The range [b_near, b_far].
    double b_near = std::numeric_limits<double>::infinity(), b_far = -b_near;
    if (s.range == Range::Object) {
        for (const glm::dvec3& c : corners(box_lo, box_hi)) {
            b_near = std::min(b_near, lambda(c));
            b_far = std::max(b_far, lambda(c));
        }
        if (s.orientation == O::Spherical) b_near = box_distance(L.eye, box_lo, box_hi);
    } else {
        // The frustum's corners at the near and far depths: the corner pixels' rays (film corners).
        const double W = camera.width(), H = camera.height();
        std::array<Ray, 4> rays{camera.ray(0.0, 0.0), camera.ray(W, 0.0), camera.ray(0.0, H), camera.ray(W, H)};
        for (const Ray& r : rays)
            for (double z : {*spec.near, *spec.far}) {
                const double t = (z - glm::dot(r.origin - L.eye, L.forward)) / glm::dot(r.direction, L.forward);
                const glm::dvec3 x = r.at(t);
                b_near = std::min(b_near, lambda(x));
                b_far = std::max(b_far, lambda(x));
            }
        if (s.orientation == O::Viewport) {
            b_near = *spec.near;
            b_far = *spec.far;
        } else if (s.orientation == O::Spherical) {
            b_near = *spec.near;  // far: the corner's distance, far / cos(theta_corner), found above
        }
    }
    const double extent = b_far - b_near;

    // The levels.
    const double half = s.first == ProfileRules::Slices::First::Half ? 0.5 : 0.0;
    auto check_count = [&](double n, const char* key) {
        if (!(n <= double(conventions::kMaxSamplesPerRay)))
            fail(key, "places " + std::to_string(n) + " slices, past the per-ray sample limit of 2^32");
    };
    if (layers) {  // the data's own layers along the axis, far to near
        const int a = L.axis;
        const std::int64_t n = dims[std::size_t(a)];
        L.spacing = spacing[a];
        for (std::int64_t i = 0; i < n; ++i) {
            const std::int64_t layer = L.normal[a] > 0.0 ? n - 1 - i : i;
            L.levels.push_back(L.normal[a] * (origin[a] + double(layer) * spacing[a]));
        }
        return L;
    }
    std::int64_t n = 0;
    double ds = 0.0;
    std::optional<std::int64_t> count = s.count;
    if (s.period) {
        // E / D in voxel units along the surfaces' normal (conventions: Volumizer's samplingPeriod).
        double e = 0.0, dvox = 0.0;
        if (s.orientation == O::Axis) {
            e = extent / spacing[L.axis];
            dvox = (*s.period)[L.axis];
        } else {
            const glm::dvec3 g = L.forward / spacing;  // G f
            const double gl = glm::length(g);
            const glm::dvec3 w = g / gl;
            e = extent * gl;
            dvox = 1.0 / glm::length(w / *s.period);
        }
        const double c = std::ceil(e / dvox - conventions::kSliceSlack);
        check_count(c, "period");
        count = std::max<std::int64_t>(1, std::int64_t(c));
        if (s.max_count) count = std::min(*count, *s.max_count);
    }
    if (count) {
        n = *count;
        if (s.max_count) n = std::min(n, *s.max_count);
        check_count(double(n), "count");
        ds = half > 0.0 ? extent / double(n) : (n > 1 ? extent / double(n - 1) : extent);
    } else {
        ds = (s.spacing ? *s.spacing * step_scale : step);
        const double c = std::floor(extent / ds - half + conventions::kSliceSlack) + 1.0;
        check_count(c, "spacing");
        n = std::max<std::int64_t>(0, std::int64_t(c));
        if (s.max_count) n = std::min(n, *s.max_count);
    }
    L.spacing = ds;
    L.levels.resize(std::size_t(n));
    for (std::int64_t k = 0; k < n; ++k) L.levels[std::size_t(k)] = b_far - (double(k) + half) * ds;
    return L;
}

}  // namespace volref
