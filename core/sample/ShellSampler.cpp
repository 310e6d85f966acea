#include "core/sample/ShellSampler.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "core/Error.h"
#include "core/sample/Tricubic.h"
#include "core/sample/Trilinear.h"

namespace volref {

namespace {

// u reduced into [0, n) (NaN and infinities read as 0).
double wrap_index(double u, std::int64_t n) {
    if (!std::isfinite(u)) return 0.0;
    const double dn = double(n);
    double w = std::fmod(u, dn);
    if (w < 0.0) w += dn;
    if (w >= dn) w = 0.0;
    return w + 0.0;
}

// u clamped to [0, n - 1] (NaN reads as 0).
double clamp_index(double u, std::int64_t n) {
    const double hi = double(n - 1);
    if (!(u > 0.0)) return 0.0;
    return u > hi ? hi : u;
}

// One axis of a trilinear lookup: the two corner indices and the fraction.
struct LinearAxis {
    std::int64_t i0 = 0, i1 = 0;
    double p = 0.0;
};

LinearAxis linear_axis(double u, std::int64_t n, bool periodic) {
    LinearAxis a;
    if (n <= 1) return a;
    if (periodic) {
        u = wrap_index(u, n);
        a.i0 = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 1);
        a.i1 = a.i0 + 1 == n ? 0 : a.i0 + 1;
        a.p = u - double(a.i0);
        return a;
    }
    u = clamp_index(u, n);
    a.i0 = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 2);
    a.i1 = a.i0 + 1;
    a.p = u - double(a.i0);
    return a;
}

// One axis of a tricubic lookup: the 4 weights and tap indices.
struct CubicAxis {
    std::array<double, 4> w{0.0, 1.0, 0.0, 0.0};
    std::array<std::int64_t, 4> idx{0, 0, 0, 0};
};

CubicAxis cubic_axis(CubicKernel k, double u, std::int64_t n, bool periodic) {
    CubicAxis a;
    if (n <= 1) return a;  // the single layer, exactly (as Tricubic.cpp)
    std::array<double, 4> dw;
    if (periodic) {
        u = wrap_index(u, n);
        const std::int64_t i = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 1);
        cubic_weights(k, u - double(i), a.w, dw);
        for (int m = 0; m < 4; ++m) {
            std::int64_t t = (i - 1 + m) % n;
            if (t < 0) t += n;
            a.idx[std::size_t(m)] = t;
        }
        return a;
    }
    u = clamp_index(u, n);
    const std::int64_t i = std::min<std::int64_t>(std::int64_t(std::floor(u)), n - 2);
    cubic_weights(k, u - double(i), a.w, dw);
    for (int m = 0; m < 4; ++m) a.idx[std::size_t(m)] = std::clamp<std::int64_t>(i - 1 + m, 0, n - 1);
    return a;
}

// ((w0 f0 + w1 f1) + w2 f2) + w3 f3, the summation order of Tricubic.cpp.
inline double dot4(const std::array<double, 4>& w, const double* f) {
    double s = w[0] * f[0];
    s += w[1] * f[1];
    s += w[2] * f[2];
    s += w[3] * f[3];
    return s;
}

}  // namespace

ShellSampler::ShellSampler(const Volume& volume, const CylindricalShell& shell, Interpolation interpolation,
                           double gradient_step)
    : volume_(volume), grid_(shell, volume.dims), interpolation_(interpolation), h_(gradient_step) {
    check();
}

ShellSampler::ShellSampler(const Volume& volume, const SphericalShell& shell, Interpolation interpolation,
                           double gradient_step)
    : volume_(volume), grid_(shell, volume.dims), interpolation_(interpolation), h_(gradient_step) {
    check();
}

void ShellSampler::check() {
    const std::size_t count = std::size_t(volume_.dims[0]) * std::size_t(volume_.dims[1]) * std::size_t(volume_.dims[2]);
    if (volume_.values.size() != count)
        throw Error("beam-space volume: " + std::to_string(volume_.values.size()) + " values for dims " +
                    std::to_string(volume_.dims[0]) + " x " + std::to_string(volume_.dims[1]) + " x " +
                    std::to_string(volume_.dims[2]));
    if (!(std::isfinite(h_) && h_ >= 0.0)) throw Error("shell sampler: the gradient step must be finite and >= 0");
    if (h_ == 0.0) h_ = grid_.default_gradient_step();
    for (int a = 0; a < 3; ++a) periodic_[std::size_t(a)] = grid_.axis(a).periodic;
}

double ShellSampler::index_value(const glm::dvec3& u) const {
    switch (interpolation_) {
        case Interpolation::Nearest: return nearest(u);
        case Interpolation::Trilinear: return trilinear(u);
        default: return tricubic(u);
    }
}

double ShellSampler::nearest(const glm::dvec3& u) const {
    std::array<std::int64_t, 3> idx;
    for (int a = 0; a < 3; ++a) {
        const std::int64_t n = volume_.dims[std::size_t(a)];
        if (periodic_[std::size_t(a)]) {
            const std::int64_t i = std::int64_t(std::floor(wrap_index(u[a], n) + 0.5));
            idx[std::size_t(a)] = i >= n ? i - n : i;
        } else {
            idx[std::size_t(a)] = std::min<std::int64_t>(std::int64_t(std::floor(clamp_index(u[a], n) + 0.5)), n - 1);
        }
    }
    return volume_.at(idx[0], idx[1], idx[2]);
}

double ShellSampler::trilinear(const glm::dvec3& u) const {
    const LinearAxis x = linear_axis(u.x, volume_.dims[0], periodic_[0]);
    const LinearAxis y = linear_axis(u.y, volume_.dims[1], periodic_[1]);
    const LinearAxis z = linear_axis(u.z, volume_.dims[2], periodic_[2]);
    const Volume& v = volume_;
    const std::size_t n[8] = {v.index(x.i0, y.i0, z.i0), v.index(x.i1, y.i0, z.i0), v.index(x.i1, y.i1, z.i0),
                              v.index(x.i0, y.i1, z.i0), v.index(x.i0, y.i0, z.i1), v.index(x.i1, y.i0, z.i1),
                              v.index(x.i1, y.i1, z.i1), v.index(x.i0, y.i1, z.i1)};
    // One switch on the storage type per sample, then typed loads (exact conversions to double).
    const std::array<double, 8> f = v.values.visit([&](const auto* p) -> std::array<double, 8> {
        return {double(p[n[0]]), double(p[n[1]]), double(p[n[2]]), double(p[n[3]]),
                double(p[n[4]]), double(p[n[5]]), double(p[n[6]]), double(p[n[7]])};
    });
    return volref::trilinear(f, x.p, y.p, z.p);
}

double ShellSampler::tricubic(const glm::dvec3& u) const {
    const CubicKernel k =
        interpolation_ == Interpolation::TricubicCatmullRom ? CubicKernel::CatmullRom : CubicKernel::BSpline;
    const CubicAxis ax = cubic_axis(k, u.x, volume_.dims[0], periodic_[0]);
    const CubicAxis ay = cubic_axis(k, u.y, volume_.dims[1], periodic_[1]);
    const CubicAxis az = cubic_axis(k, u.z, volume_.dims[2], periodic_[2]);
    const Volume& v = volume_;
    return v.values.visit([&](const auto* p) {  // one switch on the storage type per sample
        double plane[4];
        for (int c = 0; c < 4; ++c) {
            double row[4];
            for (int b = 0; b < 4; ++b) {
                const std::int64_t jb = ay.idx[std::size_t(b)], kc = az.idx[std::size_t(c)];
                const double f[4] = {double(p[v.index(ax.idx[0], jb, kc)]), double(p[v.index(ax.idx[1], jb, kc)]),
                                     double(p[v.index(ax.idx[2], jb, kc)]), double(p[v.index(ax.idx[3], jb, kc)])};
                row[b] = dot4(ax.w, f);
            }
            plane[c] = dot4(ay.w, row);
        }
        return dot4(az.w, plane);
    });
}

glm::dvec3 ShellSampler::gradient(const glm::dvec3& world) const {
    glm::dvec3 g(0.0);
    bool have_center = false;
    double f_center = 0.0;
    auto center = [&]() {
        if (!have_center) {
            f_center = value(world);
            have_center = true;
        }
        return f_center;
    };
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 plus = world, minus = world;
        plus[a] += h_;
        minus[a] -= h_;
        const bool in_plus = grid_.contains(plus), in_minus = grid_.contains(minus);
        if (in_plus && in_minus) g[a] = (value(plus) - value(minus)) / (plus[a] - minus[a]);
        else if (in_plus) g[a] = (value(plus) - center()) / (plus[a] - world[a]);
        else if (in_minus) g[a] = (center() - value(minus)) / (world[a] - minus[a]);
    }
    return g;
}

}  // namespace volref
