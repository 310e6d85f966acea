// The `scene` argument of volref.render / trace / explain: a path, JSON text or a dict (docs/python.md).
//
//   - a str or os.PathLike that is not JSON text: a scene file, read by load_scene (messages start
//     with the path, relative files are relative to the scene file's folder), exactly as the CLI;
//   - a str whose first non-blank character is '{': JSON text, read by parse_scene (messages start
//     with "scene: "; relative files are relative to the current working directory);
//   - a dict in the scene format: converted to JSON (numbers, strings, bools, None, lists, tuples,
//     dicts with str keys, numpy scalars and arrays as lists), except that a volume's "source" may
//     be a 3-D numpy array (NumpyVolumes.h); then read as JSON text.
// `overrides`: None, a list of "PATH=VALUE" strings (the CLI's --set) or a dict {PATH: VALUE} (VALUE
// converted to JSON as above).
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include "core/scene/Scene.h"
#include "python/NumpyVolumes.h"

namespace volref::python {

struct SceneInput {
    Scene scene;
    bool from_file = false;  // given as a path (volref explain can then take it as it is)
    std::string file;        // that path
    // The numpy volumes: the name the scene's source holds (VolumeSourceSpec::file; no such file exists),
    // the array, the scene key it came from and its copy in memory (VolumeSourceSpec::memory).
    struct Array {
        std::string file;
        pybind11::object array;
        std::string key;  // "volume.source", "volumes[1].source"
        std::shared_ptr<Volume> volume;  // origin and spacing set from the parsed scene
    };
    std::vector<Array> arrays;

    // `message` with each numpy volume's name replaced by the scene key of its array, so that an
    // error about it names the key ("scene: volume.source (numpy array): ...").
    std::string rewrite(const std::string& message) const;
    // The resolved scene (core/scene/SceneWriter.h) as a Python dict, with each numpy volume's "source" the array
    // itself (instead of its temporary file). Needs the GIL.
    pybind11::object resolved() const;
};

// Reads `scene` (with `overrides` applied). Needs the GIL. Throws volref::Error.
std::unique_ptr<SceneInput> read_scene_input(pybind11::handle scene, pybind11::handle overrides);

// The overrides as --set strings ("PATH=VALUE"). Throws volref::Error naming `overrides`.
std::vector<std::string> override_strings(pybind11::handle overrides);

// A Python value as JSON (the conversions listed above); messages name it as `prefix` + `path`
// ("scene: " + "camera.eye"). Throws volref::Error.
nlohmann::ordered_json to_json(pybind11::handle value, const std::string& prefix, const std::string& path, int depth = 0);

// True for a str or os.PathLike naming a file (not JSON text).
bool is_path_like(pybind11::handle scene);

}  // namespace volref::python
