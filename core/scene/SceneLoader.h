// Loading and validating scene files. Every error is a volref::Error whose one-line message names the
// file and the JSON path at fault, e.g. "scene.json: volume.transfer.opacity[2][1]: expected a number
// in [0, 1], got 1.5".
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/scene/Scene.h"

namespace volref {

// Reads `path`, applies each override "PATH=VALUE" in order (VALUE is JSON if it parses as JSON,
// otherwise a string; PATH like `render.step` or `volume.transfer.opacity[2][1]`), then validates.
Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});

// The same from JSON text; relative file paths are resolved against `base_dir`; `name` is used in
// messages in place of the file name.
Scene parse_scene(const std::string& json_text, const std::filesystem::path& base_dir,
                  const std::string& name, const std::vector<std::string>& overrides = {});

// A curvilinear shell on its own (`volref resample --shell`, the `volref_bounds` key of its NRRD files):
// the scene's volume.bounds object with "type" "cylindrical" or "spherical" (required here), read by the
// same function and rules as in a scene. `name` is used in messages: "--shell: radius: required".
// Returns type, cylinder or sphere, and tessellate.
BoundsSpec parse_shell(const std::string& json_text, const std::string& name);

// render.profile's rules from a JSON object of its keys ("base" ignored), over the preset
// `base`, as a scene's render.profile object is read; `name` starts messages.
ProfileRules parse_profile_rules(const nlohmann::json& object, ProfileId base, const std::string& name);
// Its inverse: profile_rules_object (SceneWriter.h).

}  // namespace volref
