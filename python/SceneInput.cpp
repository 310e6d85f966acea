#include "python/SceneInput.h"

#include <cmath>
#include <filesystem>
#include <system_error>

#include "core/Conventions.h"
#include "core/Error.h"
#include "core/integrate/profiles/Profile.h"
#include "core/scene/SceneLoader.h"
#include "core/scene/SceneWriter.h"

namespace py = pybind11;

namespace volref::python {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

std::string child(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string index(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }
std::string where(const std::string& prefix, const std::string& path) {
    return path.empty() ? prefix.substr(0, prefix.size() >= 2 ? prefix.size() - 2 : 0) : prefix + path;
}

std::string type_name(py::handle v) { return py::str(py::type::handle_of(v).attr("__name__")); }

bool is_json_text(py::handle scene) {
    if (!py::isinstance<py::str>(scene)) return false;
    const std::string s = scene.cast<std::string>();
    const auto first = s.find_first_not_of(" \t\r\n");
    return first != std::string::npos && s[first] == '{';
}

std::string fspath(py::handle p) { return py::module_::import("os").attr("fspath")(p).cast<std::string>(); }

}  // namespace

bool is_path_like(py::handle scene) {
    if (py::isinstance<py::str>(scene)) return !is_json_text(scene);
    return py::hasattr(scene, "__fspath__");
}

json to_json(py::handle v, const std::string& prefix, const std::string& path, int depth) {
    // A dict or list that contains itself, or one nested too deep, would recurse without end:
    // the same limit as every JSON document volref reads (conventions::kMaxJsonDepth).
    if (depth > conventions::kMaxJsonDepth)
        throw Error(where(prefix, path.substr(0, 200)) + "...: nested deeper than " + std::to_string(conventions::kMaxJsonDepth) +
                    " dicts and lists (a dict or list that contains itself?)");
    if (v.is_none()) return nullptr;
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
    if (py::isinstance<py::int_>(v)) {
        int overflow = 0;
        const long long x = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
        if (overflow != 0) throw Error(where(prefix, path) + ": the integer " + std::string(py::str(v)) + " is too large");
        return x;
    }
    if (py::isinstance<py::float_>(v)) {
        const double x = v.cast<double>();
        if (!std::isfinite(x)) throw Error(where(prefix, path) + ": expected a finite number, got " + std::string(py::repr(v)));
        return x;
    }
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::isinstance<py::dict>(v)) {
        json j = json::object();
        for (auto item : py::reinterpret_borrow<py::dict>(v)) {
            if (!py::isinstance<py::str>(item.first))
                throw Error(where(prefix, path) + ": keys must be strings, got the " + type_name(item.first) + " " +
                            std::string(py::repr(item.first)));
            const std::string key = item.first.cast<std::string>();
            j[key] = to_json(item.second, prefix, child(path, key), depth + 1);
        }
        return j;
    }
    if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
        json j = json::array();
        std::size_t i = 0;
        for (py::handle e : v) j.push_back(to_json(e, prefix, index(path, i++), depth + 1));
        return j;
    }
    const py::module_ numpy = py::module_::import("numpy");
    if (py::isinstance(v, numpy.attr("ndarray")) || py::isinstance(v, numpy.attr("generic"))) {
        const char kind = v.attr("dtype").attr("kind").cast<std::string>().at(0);
        if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
            throw Error(where(prefix, path) + ": cannot use numpy dtype " + std::string(py::str(v.attr("dtype"))) +
                        " in a scene (expected numbers)");
        return to_json(v.attr("tolist")(), prefix, path, depth);  // an array as nested lists, a scalar as its value
    }
    if (py::hasattr(v, "__fspath__")) return fspath(v);
    throw Error(where(prefix, path) + ": cannot use a " + type_name(v) +
                " in a scene (expected numbers, strings, bools, None, lists or dicts)");
}

std::vector<std::string> override_strings(py::handle overrides) {
    std::vector<std::string> out;
    if (overrides.is_none()) return out;
    if (py::isinstance<py::dict>(overrides)) {
        for (auto item : py::reinterpret_borrow<py::dict>(overrides)) {
            if (!py::isinstance<py::str>(item.first))
                throw Error("overrides: expected keys PATH (strings), got " + std::string(py::repr(item.first)));
            const std::string key = item.first.cast<std::string>();
            out.push_back(key + "=" + to_json(item.second, "overrides: ", key).dump());
        }
        return out;
    }
    if (py::isinstance<py::str>(overrides))
        throw Error("overrides: expected a list of \"PATH=VALUE\" strings or a dict {PATH: VALUE}, got a str");
    if (!py::isinstance<py::sequence>(overrides))
        throw Error("overrides: expected a list of \"PATH=VALUE\" strings or a dict {PATH: VALUE}, got a " +
                    type_name(overrides));
    for (py::handle o : overrides) {
        if (!py::isinstance<py::str>(o))
            throw Error("overrides: expected \"PATH=VALUE\" strings, got " + std::string(py::repr(o)));
        out.push_back(o.cast<std::string>());
    }
    return out;
}

std::string SceneInput::rewrite(const std::string& message) const {
    std::string m = message;
    for (const Array& a : arrays) {
        const std::string name = "scene: " + a.key + " (numpy array)";
        for (const std::string& file : {a.file + ".json", a.file})  // the sidecar's path, then the data's
            for (std::size_t at = m.find(file); at != std::string::npos; at = m.find(file, at + name.size()))
                m.replace(at, file.size(), name);
    }
    return m;
}

py::object SceneInput::resolved() const {
    // The scene in its own format (SceneWriter.h), with render.profile's rules resolved (every rule the
    // base fills in) where the scene sets any.
    nlohmann::ordered_json j = scene_json(scene);
    if (!scene.render.profile_rules.empty()) j["render"]["profile"] = resolved_profile_json(scene.render);
    py::object d = py::module_::import("json").attr("loads")(j.dump());
    if (arrays.empty()) return d;
    py::list volumes;
    if (d.contains("volume"))
        volumes.append(d["volume"]);
    else
        volumes = py::list(d["volumes"]);
    for (py::handle v : volumes) {
        py::object source = v["source"];
        if (!py::isinstance<py::dict>(source) || !source.contains("file")) continue;
        const std::string file = source["file"].cast<std::string>();
        for (const Array& a : arrays)
            if (a.file == file) v["source"] = a.array;
    }
    return d;
}

std::unique_ptr<SceneInput> read_scene_input(py::handle scene, py::handle overrides_arg) {
    auto in = std::make_unique<SceneInput>();
    const std::vector<std::string> overrides = override_strings(overrides_arg);
    if (is_path_like(scene)) {
        in->from_file = true;
        in->file = fspath(scene);
        in->scene = load_scene(in->file, overrides);
        return in;
    }
    if (py::isinstance<py::str>(scene)) {
        in->scene = parse_scene(scene.cast<std::string>(), fs::current_path(), "scene", overrides);
        return in;
    }
    if (!py::isinstance<py::dict>(scene))
        throw Error("scene: expected a scene file's path, JSON text or a dict, got a " + type_name(scene));

    // A volume object: its "source" may be a numpy array, written to a temporary raw file.
    auto volume = [&](py::handle v, const std::string& path) -> json {
        if (!py::isinstance<py::dict>(v)) return to_json(v, "scene: ", path, 1);
        json j = json::object();
        for (auto item : py::reinterpret_borrow<py::dict>(v)) {
            const std::string key = py::isinstance<py::str>(item.first) ? item.first.cast<std::string>() : "";
            if (key == "source" && is_ndarray(item.second)) {
                const std::string source = child(path, "source");
                // In memory: the source names a file that is never opened; the parsed scene's
                // volume then holds the array's copy (VolumeSourceSpec::memory).
                const std::string name = "numpy-volume-" + std::to_string(in->arrays.size()) + ".raw";
                in->arrays.push_back({name, py::reinterpret_borrow<py::object>(item.second), source,
                                      numpy_volume(item.second, "scene: " + source)});
                j["source"] = {{"file", name}, {"format", "raw"}};
            } else {
                if (key.empty())
                    throw Error("scene: " + path + ": keys must be strings, got " + std::string(py::repr(item.first)));
                j[key] = to_json(item.second, "scene: ", child(path, key), 2);
            }
        }
        return j;
    };
    json root = json::object();
    for (auto item : py::reinterpret_borrow<py::dict>(scene)) {
        if (!py::isinstance<py::str>(item.first))
            throw Error("scene: keys must be strings, got " + std::string(py::repr(item.first)));
        const std::string key = item.first.cast<std::string>();
        if (key == "volume") {
            root[key] = volume(item.second, key);
        } else if (key == "volumes" && (py::isinstance<py::list>(item.second) || py::isinstance<py::tuple>(item.second))) {
            json list = json::array();
            std::size_t i = 0;
            for (py::handle v : item.second) {
                list.push_back(volume(v, index(key, i)));
                ++i;
            }
            root[key] = std::move(list);
        } else {
            root[key] = to_json(item.second, "scene: ", key);
        }
    }
    try {
        in->scene = parse_scene(root.dump(), fs::current_path(), "scene", overrides);
    } catch (const Error& e) {
        throw Error(in->rewrite(e.what()));
    }
    for (VolumeSpec& vs : in->scene.volumes)
        for (SceneInput::Array& a : in->arrays)
            if (vs.source.file && vs.source.file->filename() == a.file) {
                // A volume in memory is complete (VolumeSourceSpec::memory): the scene's origin and
                // spacing go into it here (the defaults, 0 and 1, where the scene gives none).
                a.volume->origin = vs.origin.value_or(glm::dvec3(0.0));
                a.volume->spacing = vs.spacing.value_or(glm::dvec3(1.0));
                vs.source.memory = a.volume;
                a.file = vs.source.file->string();  // as the resolved scene and messages write it
            }
    return in;
}

}  // namespace volref::python
