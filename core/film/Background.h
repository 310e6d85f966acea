// The background behind a premultiplied pixel (conventions section 10): C' = C + (1 - A) bg_a bg_rgb,
// A' = A + (1 - A) bg_a, bg not premultiplied. It is the opacity-sum rule of the one accumulator
// (core/integrate/march/Accumulators.h) continued behind the pixel; the film (PNG / TIFF output), compare
// (--background), the convention search and Python all put a background behind a pixel through it.
#pragma once
#include <glm/vec4.hpp>

#include "core/integrate/march/Accumulators.h"

namespace volref {

// rgba: a premultiplied R, G, B, A, replaced by the pixel over `bg`.
inline void composite_over_background(double* rgba, const glm::dvec4& bg) {
    FrontToBack<Scalar, TransmittanceRule::OpacitySum> over;
    over.resume(rgba, rgba[3]);
    const double c[3] = {bg.r, bg.g, bg.b};
    over.add(true, false, 0.0, bg.a, c);
    for (int i = 0; i < 3; ++i) rgba[i] = over.color(i);
    rgba[3] = over.alpha();
}

}  // namespace volref
