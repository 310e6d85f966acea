// SceneWriter: a Scene written back in the scene format (docs/scene-format.md), the loader's inverse
// through the same names (SceneNames.h). What `volref.render(...).scene` returns (python/SceneInput.h),
// and what the convention search writes of a profile's rules.
//
// Every default is written out, file paths are absolute, `--set` overrides are already applied.
// Reading the result back (parse_scene) gives the same Scene (tests/unit/test_scene_writer.cpp), with
// two documented exceptions: a directional light's direction and a clip plane's normal are stored
// normalised, and the loader normalises them again (which may move their last bit); and the default
// camera (no "camera" key) is left out, because its placement depends on the volumes' bounds
// (core/camera/Camera.h). A volume held in memory (VolumeSourceSpec::memory) is written as the file
// that names it; python/SceneInput.cpp puts the array itself in its place.
#pragma once
#include <nlohmann/json.hpp>

#include "core/scene/Scene.h"

namespace volref {

// The whole scene. render.profile is the preset's name, or {"base": name, rules...} when the scene
// sets rules (profile_rules_object).
nlohmann::ordered_json scene_json(const Scene& scene);

// The rules set in `rules`, as render.profile's object writes them (no "base"): parse_profile_rules's
// inverse (SceneLoader.h).
nlohmann::json profile_rules_object(const ProfileRules& rules);

}  // namespace volref
