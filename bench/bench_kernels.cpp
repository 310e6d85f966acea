// bench_kernels: samples per second of each stage of the sample pipeline on its own (docs/performance.md,
// "Kernels"), single-threaded, on fixed-seed inputs.
//
// The inputs come from the same Marschner-Lobb 256^3 volume (origin 0, spacing 1, doubles: 128 MiB) and
// the same "rays" point set as bench_gradient: 256 segments between random pairs of points in the domain
// (seed 20261122), 256 evenly spaced samples each, 65536 samples in all. Everything a stage needs is
// computed once, before timing, from those points: the trilinear value f, the central-difference gradient
// grad f and |grad f|, the ray direction and the distance along the ray. Each benchmark runs one stage
// over the 65536 inputs per iteration:
//
//   reconstruct/<kernel>        VolumeSampler::value at the points (nearest, trilinear, tricubic B-spline)
//   classify/tf_<n>_rows        TransferFunction::classify(f, |grad f|) with n colour rows and n opacity
//                               rows (n = 2, 8, 32), evenly spaced over [0, 1], no gradient opacity
//   classify/isovalue_3         IsovalueClassifier, 3 contours (f = 0.3, 0.5, 0.7; r = 1.5)
//   classify/boundary_3         BoundaryClassifier, 3 regions (f = 0, 0.5, 1)
//   shade/blinn_phong_<n>light  Shader::shade(m, grad f, V, d), Blinn-Phong with the default
//                               coefficients; one headlight, or a headlight and a directional light
//   composite/front_to_back     the front-to-back update alone, on precomputed (a, c, d) per sample:
//                               T = exp(-tau); tau_k = optical_depth(a, d, l); alpha = -expm1(-tau_k);
//                               C += T alpha c; tau += tau_k (Neumaier sum), restarted for each ray
//                               (a uniform in [0.001, 0.1], c uniform in [0, 1]^3, d = 0.5 except a
//                               shorter last segment per ray)
//   pipeline/trilinear_tf5      SamplePipeline::sample on the rays (value + classification, unshaded),
//                               trilinear, the 5-row transfer function of reference_scenes/default.json:
//                               what one sample of an unshaded whole render costs before compositing
//
// Counters: items_per_second (samples/s) and time_per_item (CPU time per sample). Inputs that fit in the
// caches (classify, shade, composite: a few MiB) run at compute speed; reconstruct and pipeline read
// the 128 MiB volume.
//
// Suggested run (about 1 min on 2 cores):
//   build/bench/bench_kernels --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//     --benchmark_enable_random_interleaving=true        (one command line)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/Conventions.h"
#include "core/camera/Ray.h"
#include "core/grid/ProceduralField.h"
#include "core/grid/Volume.h"
#include "core/integrate/march/CompensatedSum.h"
#include "core/integrate/march/SamplePipeline.h"
#include "core/sample/GradientField.h"
#include "core/sample/VolumeSampler.h"
#include "bench/BenchData.h"
#include "core/scene/Scene.h"
#include "transfer/BoundaryClassifier.h"
#include "transfer/IsovalueClassifier.h"
#include "transfer/OpacityCorrection.h"
#include "transfer/Shader.h"
#include "transfer/TransferFunction.h"

namespace {

using volref::Interpolation;
using volref::Volume;
using volref::VolumeSampler;

using namespace bench;

// The rays point set of bench_gradient (same seed, same arithmetic, so the same points), and for each
// ray its origin, unit direction and sample spacing, for the stages that need a ray.
struct RaySet {
    std::vector<glm::dvec3> points;  // kRays * kSamplesPerRay, ray by ray
    std::vector<volref::Ray> rays;   // origin a, direction normalize(b - a)
    std::vector<double> spacing;     // |b - a| / (kSamplesPerRay - 1)
};

const RaySet& ray_set() {
    static const RaySet set = [] {
        RaySet s;
        s.points = ray_points();
        for (const auto& [a, b] : ray_endpoints()) {
            volref::Ray ray;
            ray.origin = a;
            ray.direction = glm::normalize(b - a);
            s.rays.push_back(ray);
            s.spacing.push_back(glm::length(b - a) / double(kSamplesPerRay - 1));
        }
        return s;
    }();
    return set;
}

// Per-sample inputs of the classification and shading stages, from the volume at the ray points.
struct StageInputs {
    std::vector<double> value;            // trilinear f
    std::vector<glm::dvec3> gradient;     // central grad f (on the fly, trilinear)
    std::vector<double> gradient_norm;    // |grad f|
    std::vector<glm::dvec3> view;         // -ray direction
    std::vector<double> depth;            // distance from the ray's origin
    std::vector<glm::dvec3> material;     // a colour in [0, 1]^3 (fixed seed)
};

const StageInputs& inputs() {
    static const StageInputs in = [] {
        const RaySet& rs = ray_set();
        const VolumeSampler& s = sampler(Interpolation::Trilinear);
        const volref::GradientField g(s, volref::GradientSpec{volref::GradientSpec::Scheme::Central, false});
        std::mt19937_64 rng(kSeed + 1);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        StageInputs out;
        for (std::size_t r = 0; r < kRays; ++r)
            for (std::size_t i = 0; i < kSamplesPerRay; ++i) {
                const glm::dvec3& p = rs.points[r * kSamplesPerRay + i];
                out.value.push_back(s.value(p));
                out.gradient.push_back(g.gradient(p));
                out.gradient_norm.push_back(glm::length(out.gradient.back()));
                out.view.push_back(-rs.rays[r].direction);
                out.depth.push_back(double(i) * rs.spacing[r]);
                out.material.push_back({unit(rng), unit(rng), unit(rng)});
            }
        return out;
    }();
    return in;
}

template <class F>
void item_loop(benchmark::State& state, std::size_t n, const F& f) {
    for (auto _ : state) {
        for (std::size_t k = 0; k < n; ++k) {
            auto r = f(k);
            benchmark::DoNotOptimize(r);
        }
    }
    const auto items = std::int64_t(state.iterations()) * std::int64_t(n);
    state.SetItemsProcessed(items);
    // kIsRate | kInvert: CPU seconds per item (printed with an SI prefix, e.g. "81.5ns").
    state.counters["time_per_item"] =
        benchmark::Counter(double(items), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// `make` returns the per-item callable f(k) for k in [0, kPoints); it runs before timing, so lazily
// built data (volume, samplers, inputs, classifiers) is never timed.
template <class Make>
void register_items(const std::string& name, Make make) {
    benchmark::RegisterBenchmark(name.c_str(), [make](benchmark::State& state) {
        const auto f = make();
        item_loop(state, kPoints, f);
    })->Unit(benchmark::kMicrosecond);
}

// n colour rows and n opacity rows, evenly spaced over [0, 1], values from a fixed seed.
volref::TransferSpec transfer_rows(int n) {
    std::mt19937_64 rng(kSeed + std::uint64_t(n));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    volref::TransferSpec t;
    for (int k = 0; k < n; ++k) {
        const double x = double(k) / double(n - 1);
        t.color.push_back({x, unit(rng), unit(rng), unit(rng)});
        t.opacity.push_back({x, unit(rng)});
    }
    return t;
}

// The transfer function of reference_scenes/default.json.
volref::TransferSpec default_transfer() {
    volref::TransferSpec t;
    t.color = {{0.0, 0.1, 0.2, 0.6}, {0.45, 0.25, 0.5, 0.95}, {0.5, 1.0, 0.85, 0.4}, {0.55, 1.0, 0.45, 0.15},
               {1.0, 0.9, 0.1, 0.05}};
    t.opacity = {{0.0, 0.0}, {0.42, 0.0}, {0.5, 0.7}, {0.58, 0.0}, {1.0, 0.0}};
    return t;
}

double zero_gradient_tolerance() {
    const auto [vmin, vmax] = volume().value_range();
    return volref::conventions::kZeroGradientRelative * std::max(std::fabs(vmin), std::fabs(vmax));  // spacing 1
}

// Compositing inputs: opacity a, colour c and segment length d per sample, kSamplesPerRay per ray.
struct CompositeInputs {
    std::vector<double> a, d;
    std::vector<glm::dvec3> c;
};

const CompositeInputs& composite_inputs() {
    static const CompositeInputs in = [] {
        std::mt19937_64 rng(kSeed + 2);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        CompositeInputs out;
        for (std::size_t r = 0; r < kRays; ++r)
            for (std::size_t i = 0; i < kSamplesPerRay; ++i) {
                out.a.push_back(0.001 + 0.099 * unit(rng));
                out.c.push_back({unit(rng), unit(rng), unit(rng)});
                out.d.push_back(i + 1 == kSamplesPerRay ? 0.5 * (1.0 - unit(rng)) : 0.5);
            }
        return out;
    }();
    return in;
}

void composite_front_to_back(benchmark::State& state) {
    const CompositeInputs& in = composite_inputs();
    const double l = 1.0;
    for (auto _ : state) {
        for (std::size_t r = 0; r < kRays; ++r) {
            volref::CompensatedSum tau;
            glm::dvec3 C(0.0);
            for (std::size_t k = r * kSamplesPerRay; k < (r + 1) * kSamplesPerRay; ++k) {
                const double T = std::exp(-tau.value());
                const double tau_k = volref::optical_depth(in.a[k], in.d[k], l);
                const double alpha = -std::expm1(-tau_k);
                C += (T * alpha) * in.c[k];
                tau.add(tau_k);
            }
            const double A = -std::expm1(-tau.value());
            benchmark::DoNotOptimize(C);
            benchmark::DoNotOptimize(A);
        }
    }
    const auto items = std::int64_t(state.iterations()) * std::int64_t(kPoints);
    state.SetItemsProcessed(items);
    state.counters["time_per_item"] =
        benchmark::Counter(double(items), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void register_all() {
    using I = Interpolation;
    for (const auto& [name, interpolation] :
         {std::pair{"nearest", I::Nearest}, std::pair{"trilinear", I::Trilinear}, std::pair{"tricubic_bspline", I::TricubicBSpline}}) {
        const I kernel = interpolation;
        register_items(std::string("reconstruct/") + name, [kernel] {
            const VolumeSampler* s = &sampler(kernel);
            const std::vector<glm::dvec3>* pts = &ray_set().points;
            return [s, pts](std::size_t k) { return s->value((*pts)[k]); };
        });
    }

    for (const int rows : {2, 8, 32}) {
        register_items("classify/tf_" + std::to_string(rows) + "_rows", [rows] {
            auto tf = std::make_shared<const volref::TransferFunction>(transfer_rows(rows), volume());
            const StageInputs* in = &inputs();
            return [tf, in](std::size_t k) { return tf->classify(in->value[k], in->gradient_norm[k]); };
        });
    }
    register_items("classify/isovalue_3", [] {
        std::vector<volref::IsovalueContour> contours{{0.3, 0.2, 1.5, {1.0, 0.2, 0.1}},
                                                      {0.5, 0.4, 1.5, {0.2, 1.0, 0.2}},
                                                      {0.7, 0.8, 1.5, {0.2, 0.3, 1.0}}};
        auto c = std::make_shared<const volref::IsovalueClassifier>(std::move(contours), 1.0);
        const StageInputs* in = &inputs();
        return [c, in](std::size_t k) { return c->classify(in->value[k], in->gradient_norm[k]); };
    });
    register_items("classify/boundary_3", [] {
        std::vector<volref::BoundaryRegion> regions{{0.0, 0.0, {0.0, 0.0, 0.0}},
                                                    {0.5, 0.3, {1.0, 0.8, 0.65}},
                                                    {1.0, 1.0, {1.0, 0.98, 0.9}}};
        auto c = std::make_shared<const volref::BoundaryClassifier>(std::move(regions), 1.0);
        const StageInputs* in = &inputs();
        return [c, in](std::size_t k) { return c->classify(in->value[k], in->gradient_norm[k]); };
    });

    for (const int lights : {1, 2}) {
        register_items("shade/blinn_phong_" + std::to_string(lights) + "light", [lights] {
            std::vector<volref::LightSpec> ls{volref::LightSpec{}};  // a white headlight
            if (lights == 2) {
                volref::LightSpec d;
                d.type = volref::LightSpec::Type::Directional;
                d.direction = glm::normalize(glm::dvec3(-0.3, -1.0, 1.0));
                d.color = glm::dvec3(0.6);
                ls.push_back(d);
            }
            auto shader = std::make_shared<const volref::Shader>(volref::ShadingSpec{}, ls, zero_gradient_tolerance());
            const StageInputs* in = &inputs();
            return [shader, in](std::size_t k) {
                return shader->shade(in->material[k], in->gradient[k], in->view[k], in->depth[k]);
            };
        });
    }

    benchmark::RegisterBenchmark("composite/front_to_back", composite_front_to_back)->Unit(benchmark::kMicrosecond);

    register_items("pipeline/trilinear_tf5", [] {
        auto tf = std::make_shared<const volref::TransferFunction>(default_transfer(), volume());
        auto pipeline = std::make_shared<const volref::SamplePipeline>(sampler(I::Trilinear), *tf, nullptr, nullptr, nullptr);
        const RaySet* rs = &ray_set();
        return [tf, pipeline, rs](std::size_t k) {
            const std::size_t r = k / kSamplesPerRay, i = k % kSamplesPerRay;
            return pipeline->sample(rs->rays[r], double(i) * rs->spacing[r], volref::SamplePipeline::Use::Composite);
        };
    });
}

}  // namespace

int main(int argc, char** argv) {
    register_all();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
