#include "core/sample/Tricubic.h"

#include "core/sample/IndexSpace.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace volref {

void cubic_weights(CubicKernel k, double t, std::array<double, 4>& w, std::array<double, 4>& dw) {
    const double t2 = t * t, t3 = t2 * t, s = 1.0 - t;
    if (k == CubicKernel::BSpline) {
        // w0 = (1-t)^3/6, w1 = (3t^3 - 6t^2 + 4)/6, w2 = (-3t^3 + 3t^2 + 3t + 1)/6, w3 = t^3/6.
        w[0] = s * s * s / 6.0;
        w[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
        w[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
        w[3] = t3 / 6.0;
        // d/dt: -(1-t)^2/2, (3t^2 - 4t)/2, (-3t^2 + 2t + 1)/2, t^2/2.
        dw[0] = -(s * s) / 2.0;
        dw[1] = (3.0 * t2 - 4.0 * t) / 2.0;
        dw[2] = (-3.0 * t2 + 2.0 * t + 1.0) / 2.0;
        dw[3] = t2 / 2.0;
    } else {
        // w0 = (-t^3 + 2t^2 - t)/2, w1 = (3t^3 - 5t^2 + 2)/2, w2 = (-3t^3 + 4t^2 + t)/2, w3 = (t^3 - t^2)/2.
        w[0] = (-t3 + 2.0 * t2 - t) / 2.0;
        w[1] = (3.0 * t3 - 5.0 * t2 + 2.0) / 2.0;
        w[2] = (-3.0 * t3 + 4.0 * t2 + t) / 2.0;
        w[3] = (t3 - t2) / 2.0;
        // d/dt: (-3t^2 + 4t - 1)/2, (9t^2 - 10t)/2, (-9t^2 + 8t + 1)/2, (3t^2 - 2t)/2.
        dw[0] = (-3.0 * t2 + 4.0 * t - 1.0) / 2.0;
        dw[1] = (9.0 * t2 - 10.0 * t) / 2.0;
        dw[2] = (-9.0 * t2 + 8.0 * t + 1.0) / 2.0;
        dw[3] = (3.0 * t2 - 2.0 * t) / 2.0;
    }
}

namespace {

// ((w0 f0 + w1 f1) + w2 f2) + w3 f3: the one summation order used everywhere.
inline double dot4(const std::array<double, 4>& w, const double* f) {
    double s = w[0] * f[0];
    s += w[1] * f[1];
    s += w[2] * f[2];
    s += w[3] * f[3];
    return s;
}

// The nested 1-D passes of the header. With Gradient = false only the value is formed (by the same
// operations as with Gradient = true, so the values agree bit for bit).
// T: the storage type (one instantiation per type; evaluate() dispatches once per sample).
template <bool Gradient, class T>
double evaluate_typed(const Volume& v, const T* data, const CubicAxis& ax, const CubicAxis& ay, const CubicAxis& az,
                      glm::dvec3* gradient) {
    const std::int64_t nx = v.dims[0], ny = v.dims[1];

    // Pass 1 (along i) for the 16 rows, k outer, j inner.
    double row_v[4][4];                       // [k][j]: sum_i wx f
    [[maybe_unused]] double row_dx[4][4];     // [k][j]: sum_i wx' f
    for (int c = 0; c < 4; ++c) {
        for (int b = 0; b < 4; ++b) {
            const std::int64_t base = nx * (ay.idx[b] + ny * az.idx[c]);
            const double f[4] = {double(data[std::size_t(base + ax.idx[0])]), double(data[std::size_t(base + ax.idx[1])]),
                                 double(data[std::size_t(base + ax.idx[2])]), double(data[std::size_t(base + ax.idx[3])])};
            row_v[c][b] = dot4(ax.w, f);
            if constexpr (Gradient) row_dx[c][b] = dot4(ax.dw, f);
        }
    }

    // Pass 2 (along j) for each k.
    double plane_v[4];
    [[maybe_unused]] double plane_dx[4], plane_dy[4];
    for (int c = 0; c < 4; ++c) {
        plane_v[c] = dot4(ay.w, row_v[c]);
        if constexpr (Gradient) {
            plane_dx[c] = dot4(ay.w, row_dx[c]);
            plane_dy[c] = dot4(ay.dw, row_v[c]);
        }
    }

    // Pass 3 (along k).
    const double value = dot4(az.w, plane_v);
    if constexpr (Gradient) {
        *gradient = glm::dvec3(dot4(az.w, plane_dx), dot4(az.w, plane_dy), dot4(az.dw, plane_v));
    } else {
        (void)gradient;
    }
    return value;
}

template <bool Gradient>
double evaluate(const Volume& v, const CubicAxis& ax, const CubicAxis& ay, const CubicAxis& az, glm::dvec3* gradient) {
    return v.values.visit([&](const auto* data) { return evaluate_typed<Gradient>(v, data, ax, ay, az, gradient); });
}

// Clamped axes (the Cartesian grid).
template <bool Gradient>
double evaluate(const Volume& v, CubicKernel k, const glm::dvec3& u, glm::dvec3* gradient) {
    return evaluate<Gradient>(v, cubic_axis(k, u.x, v.dims[0], false), cubic_axis(k, u.y, v.dims[1], false),
                              cubic_axis(k, u.z, v.dims[2], false), gradient);
}

}  // namespace

double tricubic(const Volume& v, const CubicAxis& x, const CubicAxis& y, const CubicAxis& z) {
    return evaluate<false>(v, x, y, z, nullptr);
}

double tricubic(const Volume& v, CubicKernel k, const glm::dvec3& u) {
    return evaluate<false>(v, k, u, nullptr);
}

glm::dvec3 tricubic_index_gradient(const Volume& v, CubicKernel k, const glm::dvec3& u) {
    glm::dvec3 g;
    evaluate<true>(v, k, u, &g);
    return g;
}

double tricubic_value_and_index_gradient(const Volume& v, CubicKernel k, const glm::dvec3& u,
                                         glm::dvec3& gradient) {
    return evaluate<true>(v, k, u, &gradient);
}

}  // namespace volref
