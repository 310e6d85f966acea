// PreClassifiedVolume: pre-classification (`volume.classify: "pre"`, conventions section 7).
// Every voxel i is classified first, (c_i, a_i) = classify(v_i, |grad f| at the voxel), then a sample
// interpolates (with the volume's own interpolation) the opacity a_i and the opacity-weighted colour
// a_i c_i (Wittenbrink et al. 1998, which keeps colour from bleeding out of transparent voxels):
//   a = clamp(interp(a_i), 0, 1),   c = interp(a_i c_i) / interp(a_i)  (0 where interp(a_i) <= 0).
// It agrees with post-classification when a(v) c(v) and a(v) are both affine in v on the data's
// range (e.g. constant colour with linear opacity, or constant opacity with linear colour) and
// differs otherwise.
#pragma once
#include <array>
#include <memory>

#include "core/grid/Volume.h"
#include "core/sample/GradientField.h"
#include "core/sample/VolumeSampler.h"
#include "transfer/Classifier.h"

namespace volref {

class PreClassifiedVolume {
public:
    // `gradient` may be null when the classifier does not need it.
    PreClassifiedVolume(const VolumeSampler& sampler, const Classifier& classifier, const GradientSource* gradient);
    ~PreClassifiedVolume();
    Classified sample(const glm::dvec3& world) const;

private:
    std::array<Volume, 4> channels_;  // a c_r, a c_g, a c_b, a
    std::array<std::unique_ptr<VolumeSampler>, 4> samplers_;
};

}  // namespace volref
