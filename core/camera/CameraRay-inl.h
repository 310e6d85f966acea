// Camera::ray's arithmetic for the perspective and orthographic cameras as a template over a lane type
// L (core/Lanes.h), so that one ray (Camera::ray, scalar lanes) and a row of pixels' rays
// (Camera::pixel_rays, SIMD lanes: CameraRays.cpp) share one formula, evaluated operation by operation
// as glm did before (conventions section 10; -ffp-contract=off, so nothing is fused):
//   nx = (2 fx) / W - 1,  ny = 1 - (2 fy) / H,
//   perspective:  v = (f + ((nx tan) aspect) r) + (ny tan) u,  direction = v (1 / sqrt((v.x v.x + v.y v.y) + v.z v.z)),
//                 origin = eye;
//   orthographic: origin = (eye + ((nx h/2) aspect) r) + (ny h/2) u,  direction = f.
// Included inside namespace volref (Camera.cpp) and inside each Highway target's namespace
// (CameraRays.cpp); hence no include guard and no includes.

// The normalised device coordinates of film point (fx, fy) on a W x H film.
template <class L>
inline void camera_ndc_lanes(double width, double height, typename L::V fx, typename L::V fy, typename L::V& nx,
                             typename L::V& ny) {
    nx = L::splat(2.0) * fx / L::splat(width) - L::splat(1.0);
    ny = L::splat(1.0) - L::splat(2.0) * fy / L::splat(height);
}

template <class L>
inline void camera_ray_lanes(const CameraRayConstants& k, typename L::V fx, typename L::V fy, typename L::V origin[3],
                             typename L::V direction[3]) {
    using V = typename L::V;
    V nx, ny;
    camera_ndc_lanes<L>(k.width, k.height, fx, fy, nx, ny);
    if (k.perspective) {
        const V s = nx * L::splat(k.tan_half_fov) * L::splat(k.aspect), t = ny * L::splat(k.tan_half_fov);
        V v[3];
        for (int a = 0; a < 3; ++a) v[a] = L::splat(k.forward[a]) + s * L::splat(k.right[a]) + t * L::splat(k.up[a]);
        const V inv = L::splat(1.0) / L::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int a = 0; a < 3; ++a) {
            origin[a] = L::splat(k.eye[a]);
            direction[a] = v[a] * inv;
        }
    } else {
        const V s = nx * L::splat(k.half_height) * L::splat(k.aspect), t = ny * L::splat(k.half_height);
        for (int a = 0; a < 3; ++a) {
            origin[a] = L::splat(k.eye[a]) + s * L::splat(k.right[a]) + t * L::splat(k.up[a]);
            direction[a] = L::splat(k.forward[a]);
        }
    }
}
