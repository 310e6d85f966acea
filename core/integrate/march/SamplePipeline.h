// SamplePipeline: what one sample point of a ray becomes, stage by stage (the pipeline of Levoy 1988):
//   value f = sampler(x)  ->  gradient grad f (only when shading or the classifier needs it)
//   -> classification (c, a): post = classify(f, |grad f|); pre = the pre-classified volume at x
//   -> shading c' = shader(c, grad f, V, d) (only when the scene asks for shading).
// Integrators ask it for samples; they never build a stage themselves.
#pragma once
#include <cmath>

#include <glm/geometric.hpp>

#include "core/camera/Ray.h"
#include "core/integrate/march/SampleRecorder.h"
#include "core/sample/GradientField.h"
#include "core/sample/PreClassifiedVolume.h"
#include "core/sample/VolumeSampler.h"
#include "core/sample/VolumeView.h"
#include "transfer/Classifier.h"
#include "geometry/VolumeTransform.h"
#include "transfer/Shader.h"

namespace volref {


struct PipelineSample {
    double value = 0.0;
    glm::dvec3 color{0.0};  // shaded when the scene is shaded; not premultiplied
    double opacity = 0.0;   // per unit distance
};

class SamplePipeline {
public:
    // `gradient`, `preclassified` and `shader` may be null (not used by the scene). `transform` (null:
    // none) places a volume in the world: the rays given to this pipeline are then the volume's local
    // rays (VolumeTransform::local_ray: positions in its own space, t a world distance), and the
    // gradient (for classification and shading) and the view direction are turned back into world
    // vectors, grad_world = A^-T grad_local, V = -A d_local. `view` (VolumeView.h; null: none, a
    // pipeline of the stages alone) describes the same stages as plain data, for the SIMD packet kernels
    // and for the paths that cut rays at a grid's cells and a transfer function's rows.
    SamplePipeline(const FieldSampler& sampler, const Classifier& classifier, const GradientSource* gradient,
                   const PreClassifiedVolume* preclassified, const Shader* shader,
                   const VolumeTransform* transform = nullptr, const VolumeView* view = nullptr)
        : sampler_(sampler), classifier_(classifier), gradient_(gradient), pre_(preclassified), shader_(shader),
          transform_(transform), view_(view ? view : &kNoView) {}

    double value(const Ray& ray, double t) const { return sampler_.value(ray.at(t)); }

    // What the caller needs: compositing ignores the colour of transparent samples (so they are not
    // shaded), a surface (first hit) always needs its shaded colour, projections of values never shade.
    enum class Use { Composite, Surface, Unshaded };

    // Value, classification and shading at ray(t). The gradient is computed at most once, and only
    // when the classifier or the shader needs it.
    PipelineSample sample(const Ray& ray, double t, Use use) const { return sample_impl<false>(ray, t, use, nullptr); }
    // The same computation (the same instructions, so the same bits), also reporting every stage:
    // position, gradient (when computed), classification and the shading terms (SampleRecorder.h).
    PipelineSample sample_detailed(const Ray& ray, double t, Use use, SampleDetail& detail) const {
        return sample_impl<true>(ray, t, use, &detail);
    }

    const Classifier& classifier() const { return classifier_; }
    const FieldSampler& sampler() const { return sampler_; }
    // The volume's description (VolumeView.h): its Cartesian sampler or shell grid, transfer function
    // and gradient field (null where the scene uses another kind, or the pipeline has no view).
    const VolumeView& view() const { return *view_; }
    bool shaded() const { return shader_ != nullptr; }
    const Shader* shader() const { return shader_; }
    const GradientSource* gradient_source() const { return gradient_; }
    bool preclassified() const { return pre_ != nullptr; }
    const VolumeTransform* transform() const { return transform_; }

private:
    template <bool kDetail>
    PipelineSample sample_impl(const Ray& ray, double t, Use use, SampleDetail* detail) const {
        const glm::dvec3 x = ray.at(t);
        PipelineSample s;
        s.value = sampler_.value(x);
        glm::dvec3 g(0.0);
        bool have_gradient = false;
        auto gradient = [&]() -> const glm::dvec3& {
            if (!have_gradient) g = transform_ ? transform_->gradient_to_world(gradient_->gradient(x)) : gradient_->gradient(x);
            have_gradient = true;
            return g;
        };
        const Classified c = pre_ ? pre_->sample(x)
                                  : classifier_.classify(s.value, classifier_.needs_gradient() ? glm::length(gradient()) : 0.0);
        s.opacity = c.opacity;
        const bool shade = shader_ && (use == Use::Surface || (use == Use::Composite && c.opacity > 0.0));
        if constexpr (kDetail) {
            s.color = shade ? shader_->shade(c.color, gradient(), -view_direction(ray), t, detail->shading) : c.color;
            detail->position = transform_ ? transform_->to_world(x) : x;
            detail->value = s.value;
            detail->has_gradient = have_gradient;
            detail->gradient = g;
            detail->classified = true;
            detail->classified_color = c.color;
            detail->shaded = shade;
        } else {
            s.color = shade ? shader_->shade(c.color, gradient(), -view_direction(ray), t) : c.color;
        }
        // A non-finite value (a NaN or +-Inf voxel read by the sample) or colour is transparent
        // (docs/accuracy.md, "Non-finite voxels").
        if (!std::isfinite(s.value) || !std::isfinite(s.opacity) || !std::isfinite(s.color.r + s.color.g + s.color.b)) {
            s.opacity = 0.0;
            s.color = glm::dvec3(0.0);
        }
        if constexpr (kDetail) {  // what the integrator uses (after the non-finite rule)
            detail->opacity = s.opacity;
            detail->color = s.color;
        }
        return s;
    }

    // The world direction of the ray (the local ray's mapped back for a transformed volume).
    glm::dvec3 view_direction(const Ray& ray) const {
        return transform_ ? transform_->direction_to_world(ray.direction) : ray.direction;
    }

    const FieldSampler& sampler_;
    const Classifier& classifier_;
    const GradientSource* gradient_;
    const PreClassifiedVolume* pre_;
    const Shader* shader_;
    const VolumeTransform* transform_;
    const VolumeView* view_;
    static inline const VolumeView kNoView{};
};

}  // namespace volref
