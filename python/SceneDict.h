// The scene as volref resolved it, as scene-format JSON (docs/scene-format.md): every default filled
// in, file paths absolute, `--set` overrides applied. What `volref.render(...).scene` returns.
//
// Reading the result back (parse_scene) gives the same Scene, with two documented exceptions: a
// directional light's direction and a clip plane's normal are stored normalised, and the loader
// normalises them again (which may move their last bit); the default camera (no "camera" key) is
// left out, because its placement depends on the volumes' bounds (core/camera/Camera.h).
#pragma once
#include <nlohmann/json.hpp>

#include "core/scene/Scene.h"

namespace volref::python {

nlohmann::ordered_json scene_to_json(const Scene& scene);

}  // namespace volref::python
