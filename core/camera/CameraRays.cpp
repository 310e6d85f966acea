// Camera::pixel_rays for the perspective and orthographic cameras: CameraRay-inl.h's formula on SIMD
// lanes (SimdLanes<double>), the same rays as Camera::pixel_ray one by one. Highway's per-target
// compilation: this file is compiled once per instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/camera/CameraRays.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include <algorithm>

#include "core/Conventions.h"
#include "core/SimdLanes-inl.h"
#include "core/camera/Camera.h"

HWY_BEFORE_NAMESPACE();
namespace volref {
namespace HWY_NAMESPACE {

#include "core/camera/CameraRay-inl.h"

void CameraPixelRays(const CameraRayConstants& k, const int* x, const int* y, int count, Ray* out) {
    using L = SimdLanes<double>;
    const L::D d;
    const std::size_t n = hn::Lanes(d);
    HWY_ALIGN double fx[hn::MaxLanes(L::D())], fy[hn::MaxLanes(L::D())];
    HWY_ALIGN double o[3][hn::MaxLanes(L::D())], dir[3][hn::MaxLanes(L::D())];
    for (int first = 0; first < count; first += int(n)) {
        const int m = std::min(int(n), count - first);
        // Film points of the pixels (the last one repeated past the end).
        for (std::size_t l = 0; l < n; ++l) {
            const int i = first + std::min(int(l), m - 1);
            fx[l] = double(x[i]) + conventions::kPixelCentre;
            fy[l] = double(y[i]) + conventions::kPixelCentre;
        }
        L::V O[3], Dir[3];
        camera_ray_lanes<L>(k, hn::Load(d, fx), hn::Load(d, fy), O, Dir);
        for (int a = 0; a < 3; ++a) {
            hn::Store(O[a], d, o[a]);
            hn::Store(Dir[a], d, dir[a]);
        }
        for (int l = 0; l < m; ++l) {
            out[first + l].origin = {o[0][l], o[1][l], o[2][l]};
            out[first + l].direction = {dir[0][l], dir[1][l], dir[2][l]};
        }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace volref
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace volref {
HWY_EXPORT(CameraPixelRays);

void camera_pixel_rays(const CameraRayConstants& k, const int* x, const int* y, int count, Ray* out) {
    HWY_DYNAMIC_DISPATCH(CameraPixelRays)(k, x, y, count, out);
}
}  // namespace volref
#endif
