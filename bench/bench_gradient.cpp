// bench_gradient: the cost of gradients on a 256^3 volume (docs/performance.md, "Gradients on a 256^3
// volume").
//
// The volume is Marschner-Lobb 256^3 (origin 0, spacing 1, so the domain is [0, 255]^3), held as
// doubles like every volref volume (128 MiB). Two kinds of benchmark:
//
//   sample/<what>/<points>   the per-sample cost of one reconstruction call, over 65536 points per
//                            iteration, single-threaded. <what> is a value (trilinear, tricubic) or a
//                            gradient through GradientField (central / forward on the fly, the cached
//                            gradient, the analytic tricubic gradient). <points> is
//                              random: uniform random points in the domain (fixed seed), so nearly
//                                      every sample misses the caches (worst case);
//                              rays:   256 segments between random pairs of points, 256 evenly spaced
//                                      samples each (mean step ~0.66 voxel), the access pattern of a
//                                      ray caster.
//                            Counters: items_per_second (samples/s) and time_per_sample (CPU).
//   cache_build/<scheme>/threads:<n>
//                            GradientField construction with cache = true (evaluate the scheme at
//                            every voxel in parallel, 3 doubles per voxel = 384 MiB), with TBB limited
//                            to n threads (tbb::global_control). Wall-clock time; the allocation and
//                            release of the cache are included.
//
// The lookup cost of a cached gradient does not depend on the scheme the cache was built with (three
// trilinear lookups in the per-axis gradient volumes), so sample/gradient_cached is measured once.
//
// Suggested run (about 1 min 45 s on 2 cores):
//   build/bench/bench_gradient --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//     --benchmark_enable_random_interleaving=true        (one command line)
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/vec3.hpp>
#include <tbb/global_control.h>

#include "bench/BenchData.h"
#include "core/grid/ProceduralField.h"
#include "core/grid/Volume.h"
#include "core/sample/GradientField.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/Scene.h"

namespace {

using volref::GradientField;
using volref::GradientSpec;
using volref::Interpolation;
using volref::Volume;
using volref::VolumeSampler;

using namespace bench;

// On-the-fly gradient fields, built on first use (cheap: no cache).
const GradientField& on_the_fly(Interpolation interpolation, GradientSpec::Scheme scheme) {
    static std::unique_ptr<GradientField> fields[4][4];
    auto& f = fields[int(interpolation)][int(scheme)];
    if (!f) f = std::make_unique<GradientField>(sampler(interpolation), GradientSpec{scheme, false});
    return *f;
}

// The cached (central, trilinear) gradient field, built once on first use, outside any timing.
const GradientField& cached() {
    static const GradientField f(sampler(Interpolation::Trilinear), GradientSpec{GradientSpec::Scheme::Central, true});
    return f;
}

enum class PointSet { Random, Rays };

const std::vector<glm::dvec3>& points(PointSet set) {
    static const std::vector<glm::dvec3> random = [] {
        DomainPoints generator;
        std::vector<glm::dvec3> pts;
        pts.reserve(kPoints);
        for (std::size_t i = 0; i < kPoints; ++i) pts.push_back(generator.next());
        return pts;
    }();
    return set == PointSet::Random ? random : ray_points();
}

template <class F>
void sample_loop(benchmark::State& state, const std::vector<glm::dvec3>& pts, const F& f) {
    for (auto _ : state) {
        for (const glm::dvec3& p : pts) {
            auto r = f(p);
            benchmark::DoNotOptimize(r);
        }
    }
    const auto samples = std::int64_t(state.iterations()) * std::int64_t(pts.size());
    state.SetItemsProcessed(samples);
    // kIsRate | kInvert: CPU seconds per sample (printed with an SI prefix, e.g. "81.5ns").
    state.counters["time_per_sample"] =
        benchmark::Counter(double(samples), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// `make` returns the per-point callable; it is called before timing, so lazily built data (samplers,
// the gradient cache, the point sets) is never timed.
template <class Make>
void register_sample(const std::string& what, Make make) {
    for (const PointSet set : {PointSet::Random, PointSet::Rays}) {
        const std::string name = "sample/" + what + (set == PointSet::Random ? "/random" : "/rays");
        benchmark::RegisterBenchmark(name.c_str(), [make, set](benchmark::State& state) {
            const auto& pts = points(set);
            const auto f = make();
            sample_loop(state, pts, f);
        })->Unit(benchmark::kMillisecond);
    }
}

void register_cache_build(const std::string& what, Interpolation interpolation, GradientSpec::Scheme scheme) {
    for (const int threads : {1, 2}) {
        const std::string name = "cache_build/" + what + "/threads:" + std::to_string(threads);
        benchmark::RegisterBenchmark(name.c_str(), [interpolation, scheme, threads](benchmark::State& state) {
            const VolumeSampler& s = sampler(interpolation);
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
            for (auto _ : state) {
                const GradientField g(s, GradientSpec{scheme, true});
                benchmark::DoNotOptimize(&g);
                benchmark::ClobberMemory();
            }
            const auto voxels = std::int64_t(volume().values.size());
            state.SetItemsProcessed(std::int64_t(state.iterations()) * voxels);
            state.counters["cache_MiB"] = double(3 * sizeof(double)) * double(voxels) / double(1 << 20);
        })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->Iterations(1);
    }
}

void register_all() {
    using S = GradientSpec::Scheme;
    using I = Interpolation;
    register_sample("value_trilinear", [] {
        const VolumeSampler* s = &sampler(I::Trilinear);
        return [s](const glm::dvec3& p) { return s->value(p); };
    });
    register_sample("gradient_central", [] {
        const GradientField* g = &on_the_fly(I::Trilinear, S::Central);
        return [g](const glm::dvec3& p) { return g->gradient(p); };
    });
    register_sample("gradient_forward", [] {
        const GradientField* g = &on_the_fly(I::Trilinear, S::Forward);
        return [g](const glm::dvec3& p) { return g->gradient(p); };
    });
    register_sample("gradient_cached", [] {
        const GradientField* g = &cached();
        return [g](const glm::dvec3& p) { return g->gradient(p); };
    });
    for (const I interpolation : {I::TricubicBSpline, I::TricubicCatmullRom}) {
        const std::string kernel = interpolation == I::TricubicBSpline ? "bspline" : "catmull_rom";
        register_sample("value_" + kernel, [interpolation] {
            const VolumeSampler* s = &sampler(interpolation);
            return [s](const glm::dvec3& p) { return s->value(p); };
        });
        register_sample("gradient_analytic_" + kernel, [interpolation] {
            const GradientField* g = &on_the_fly(interpolation, S::Analytic);
            return [g](const glm::dvec3& p) { return g->gradient(p); };
        });
    }
    register_cache_build("central", I::Trilinear, S::Central);
    register_cache_build("analytic_bspline", I::TricubicBSpline, S::Analytic);
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
