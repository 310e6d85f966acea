#include "core/sample/PreClassifiedVolume.h"

#include <algorithm>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace volref {

PreClassifiedVolume::PreClassifiedVolume(const VolumeSampler& sampler, const Classifier& classifier,
                                         const GradientSource* gradient) {
    const Volume& v = sampler.volume();
    for (Volume& c : channels_) c = v.same_grid();  // f64, whatever the volume's storage type
    double* out[4];
    for (std::size_t ch = 0; ch < 4; ++ch) out[ch] = channels_[ch].values.data<double>();
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, v.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
        v.values.visit([&](const auto* values) {  // one switch on the storage type per block of slices
            for (std::int64_t k = r.begin(); k != r.end(); ++k)
                for (std::int64_t j = 0; j < v.dims[1]; ++j)
                    for (std::int64_t i = 0; i < v.dims[0]; ++i) {
                        const std::size_t idx = v.index(i, j, k);
                        const double g = gradient ? glm::length(gradient->gradient(v.voxel_position(i, j, k))) : 0.0;
                        const Classified c = classifier.classify(double(values[idx]), g);
                        for (int ch = 0; ch < 3; ++ch) out[ch][idx] = c.opacity * c.color[ch];
                        out[3][idx] = c.opacity;
                    }
        });
    });
    for (std::size_t ch = 0; ch < 4; ++ch)
        samplers_[ch] = std::make_unique<VolumeSampler>(channels_[ch], sampler.interpolation());
}

PreClassifiedVolume::~PreClassifiedVolume() = default;

Classified PreClassifiedVolume::sample(const glm::dvec3& world) const {
    Classified out;
    const double a = samplers_[3]->value(world);
    if (a > 0.0) {
        out.color = glm::dvec3(samplers_[0]->value(world), samplers_[1]->value(world), samplers_[2]->value(world)) / a;
        out.opacity = std::min(a, 1.0);
    }
    return out;
}

}  // namespace volref
