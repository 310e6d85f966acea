#include "core/sample/GradientField.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Error.h"

namespace volref {

#include "core/sample/GradientDifference-inl.h"

struct GradientField::Cache {
    Volume components[3];
    std::unique_ptr<VolumeSampler> samplers[3];
};

GradientField::GradientField(const VolumeSampler& sampler, GradientSpec spec) : sampler_(sampler) {
    scheme_ = spec.scheme;
    if (scheme_ == GradientSpec::Scheme::Default)
        scheme_ = sampler.is_tricubic() ? GradientSpec::Scheme::Analytic : GradientSpec::Scheme::Central;
    if (scheme_ == GradientSpec::Scheme::Analytic && !sampler.is_tricubic())
        throw Error("volume.gradient.scheme: analytic gradients need a tricubic interpolation");
    const Volume& v = sampler.volume();
    lo_ = v.domain_min();
    hi_ = v.domain_max();
    if (!spec.cache) return;

    cache_ = std::make_unique<Cache>();
    for (auto& c : cache_->components) c = v.same_grid();  // f64, whatever the volume's storage type
    double* out[3] = {cache_->components[0].values.data<double>(), cache_->components[1].values.data<double>(),
                      cache_->components[2].values.data<double>()};
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, v.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
        for (std::int64_t k = r.begin(); k != r.end(); ++k)
            for (std::int64_t j = 0; j < v.dims[1]; ++j)
                for (std::int64_t i = 0; i < v.dims[0]; ++i) {
                    const glm::dvec3 g = on_the_fly(v.voxel_position(i, j, k));
                    for (int a = 0; a < 3; ++a) out[a][v.index(i, j, k)] = g[a];
                }
    });
    for (int a = 0; a < 3; ++a)
        cache_->samplers[a] = std::make_unique<VolumeSampler>(cache_->components[a], Interpolation::Trilinear);
}

GradientField::~GradientField() = default;

const Volume* GradientField::cached_component(int a) const { return cache_ ? &cache_->components[a] : nullptr; }

glm::dvec3 GradientField::gradient(const glm::dvec3& world) const {
    if (cache_)
        return {cache_->samplers[0]->trilinear(world), cache_->samplers[1]->trilinear(world),
                cache_->samplers[2]->trilinear(world)};
    return on_the_fly(world);
}

glm::dvec3 GradientField::on_the_fly(const glm::dvec3& x) const {
    if (scheme_ == GradientSpec::Scheme::Analytic) return sampler_.tricubic_gradient(x);
    // GradientDifference-inl.h on one lane (the SIMD packets run the same template).
    const Volume& v = sampler_.volume();
    const double X[3] = {x.x, x.y, x.z};
    auto f = [&](const double P[3]) { return sampler_.value(glm::dvec3(P[0], P[1], P[2])); };
    auto fx = [&] { return sampler_.value(x); };
    const bool central = scheme_ == GradientSpec::Scheme::Central;
    glm::dvec3 g(0.0);
    for (int a = 0; a < 3; ++a)
        if (v.dims[a] > 1) g[a] = difference<Scalar>(central, X, a, v.spacing[a], lo_[a], hi_[a], f, fx);
    return g;
}

}  // namespace volref
