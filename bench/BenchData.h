// The data both kernel benchmarks read (bench_gradient.cpp, bench_kernels.cpp), so they measure on
// the same volume and the same points: a Marschner-Lobb 256^3 volume (origin 0, spacing 1) and, from
// one fixed seed, uniform random points in its domain and the "rays" set (kRays chords between pairs
// of random points, kSamplesPerRay evenly spaced samples on each, ray by ray).
#pragma once
#include <cstddef>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "core/grid/ProceduralField.h"
#include "core/grid/Volume.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/Scene.h"

namespace bench {

constexpr std::int64_t kDim = 256;
constexpr std::size_t kPoints = std::size_t(1) << 16;
constexpr std::size_t kRays = 256;
constexpr std::size_t kSamplesPerRay = kPoints / kRays;
constexpr std::uint64_t kSeed = 20261122;

inline const volref::Volume& volume() {
    static const volref::Volume v = [] {
        volref::FieldSpec f;
        f.kind = volref::FieldSpec::Kind::MarschnerLobb;
        f.dims = {kDim, kDim, kDim};
        return volref::make_procedural_volume(f, glm::dvec3(0.0), glm::dvec3(1.0));
    }();
    return v;
}

inline const volref::VolumeSampler& sampler(volref::Interpolation interpolation) {
    using volref::Interpolation;
    static const volref::VolumeSampler nearest(volume(), Interpolation::Nearest);
    static const volref::VolumeSampler trilinear(volume(), Interpolation::Trilinear);
    static const volref::VolumeSampler bspline(volume(), Interpolation::TricubicBSpline);
    static const volref::VolumeSampler catmull_rom(volume(), Interpolation::TricubicCatmullRom);
    switch (interpolation) {
        case Interpolation::Nearest: return nearest;
        case Interpolation::TricubicBSpline: return bspline;
        case Interpolation::TricubicCatmullRom: return catmull_rom;
        default: return trilinear;
    }
}

// Uniform random points in the volume's domain, from a generator seeded with kSeed.
class DomainPoints {
public:
    DomainPoints() : rng_(kSeed), lo_(volume().domain_min()), hi_(volume().domain_max()) {}
    glm::dvec3 next() {
        glm::dvec3 p;
        for (int a = 0; a < 3; ++a) p[a] = lo_[a] + unit_(rng_) * (hi_[a] - lo_[a]);
        return p;
    }

private:
    std::mt19937_64 rng_;
    std::uniform_real_distribution<double> unit_{0.0, 1.0};
    glm::dvec3 lo_, hi_;
};

// The rays' end points (a, b): consecutive pairs of a fresh DomainPoints.
inline const std::vector<std::pair<glm::dvec3, glm::dvec3>>& ray_endpoints() {
    static const auto ends = [] {
        DomainPoints points;
        std::vector<std::pair<glm::dvec3, glm::dvec3>> e;
        for (std::size_t r = 0; r < kRays; ++r) {
            const glm::dvec3 a = points.next(), b = points.next();
            e.emplace_back(a, b);
        }
        return e;
    }();
    return ends;
}

// The samples along the rays: a + (b - a) i / (kSamplesPerRay - 1), ray by ray.
inline const std::vector<glm::dvec3>& ray_points() {
    static const auto pts = [] {
        std::vector<glm::dvec3> p;
        p.reserve(kPoints);
        for (const auto& [a, b] : ray_endpoints())
            for (std::size_t i = 0; i < kSamplesPerRay; ++i)
                p.push_back(a + (b - a) * (double(i) / double(kSamplesPerRay - 1)));
        return p;
    }();
    return pts;
}

}  // namespace bench
