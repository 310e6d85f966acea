// Scenes built in code for the tests.
#pragma once
#include "core/render/Renderer.h"
#include "core/scene/Scene.h"

namespace volref::test {

// An orthographic camera looking along -z at (cx, cy), from z = eye_z, with view height h.
inline CameraSpec ortho_down_z(double cx, double cy, double eye_z, double h) {
    CameraSpec c;
    c.type = CameraSpec::Type::Orthographic;
    c.eye = {cx, cy, eye_z};
    c.target = {cx, cy, 0.0};
    c.up = {0.0, 1.0, 0.0};
    c.height = h;
    return c;
}

inline Scene field_scene(FieldSpec field, glm::dvec3 origin = glm::dvec3(0.0), glm::dvec3 spacing = glm::dvec3(1.0)) {
    Scene s;
    s.volume().source.field = std::move(field);
    s.volume().origin = origin;
    s.volume().spacing = spacing;
    return s;
}

inline FieldSpec constant_field(double value, std::array<std::int64_t, 3> dims) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Constant;
    f.value = value;
    f.dims = dims;
    return f;
}

inline FieldSpec linear_field(std::array<double, 4> coefficients, std::array<std::int64_t, 3> dims) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Linear;
    f.coefficients = coefficients;
    f.dims = dims;
    return f;
}

// f = z on [0, 4]^3 (data range [0, 4]); colour white, opacity a(v) = v / 4; one pixel looking down z
// through (2, 2), the step in world units.
inline Scene ramp_scene(ProfileId profile, Projection projection, double step = 0.5) {
    Scene s = field_scene(linear_field({0, 0, 1, 0}, {5, 5, 5}));
    s.volume().transfer.color = {{0, 1, 1, 1}, {4, 1, 1, 1}};
    s.volume().transfer.opacity = {{0, 0}, {4, 1}};
    s.camera = ortho_down_z(2.0, 2.0, 14.0, 1.0);
    s.image.width = s.image.height = 1;
    s.render.projection = projection;
    s.render.step = step;
    s.render.step_units = StepUnits::World;
    s.render.profile = profile;
    return s;
}

inline glm::dvec4 rgba(const Image& im, int x, int y) {
    return {im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2), im.at(x, y, 3)};
}

}  // namespace volref::test
