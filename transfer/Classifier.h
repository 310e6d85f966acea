// Classifier: a sample's value (and gradient magnitude) -> colour (RGB, not premultiplied) and
// opacity per unit distance (conventions sections 3 and 7). Implementations: TransferFunction
// (piecewise-linear rows, optional gradient-magnitude modulation), IsovalueClassifier and
// BoundaryClassifier (Levoy 1988).
#pragma once
#include <memory>

#include <glm/vec3.hpp>

#include "core/grid/Volume.h"
#include "core/scene/Scene.h"

namespace volref {

struct Classified {
    glm::dvec3 color{0.0};
    double opacity = 0.0;
};

class Classifier {
public:
    virtual ~Classifier() = default;
    // `gradient_magnitude` is |grad f| in value per world unit; ignored unless needs_gradient().
    virtual Classified classify(double value, double gradient_magnitude) const = 0;
    virtual bool needs_gradient() const = 0;
    // The length over which `opacity` is accumulated (world units).
    virtual double unit_distance() const = 0;
    // The value that average and x-ray projections integrate (the transfer function's coordinate).
    virtual double coordinate(double value) const { return value; }
    // Can a value in [lo, hi], with any finite gradient magnitude, have opacity > 0? False only when
    // classify() gives opacity exactly 0 (or -0) for every such value; true when unsure (also for an
    // empty or NaN range). Empty-space skipping (MacrocellGrid) relies on it. The default (true)
    // never skips; IsovalueClassifier keeps it: its tent av (1 - |fv - f| / (r g)) is > 0 for every
    // f once g >= |fv - f| / r, so no value range is transparent (unless every av is 0).
    virtual bool may_have_opacity(double lo, double hi) const {
        (void)lo;
        (void)hi;
        return true;
    }
};

// The classifier a volume names: its `classification`, else its `transfer`.
std::unique_ptr<Classifier> make_classifier(const VolumeSpec& spec, const Volume& volume);

}  // namespace volref
