// The Python module `volref` (docs/python.md): render, compare, trace and explain, with the same
// functions and numbers as the command line (cli/*_command.cpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/compare/ComparedImage.h"
#include "core/compare/ConventionSearch.h"
#include "core/compare/HeatMap.h"
#include "core/compare/ImageMetrics.h"
#include "core/compare/MetricsJson.h"
#include "core/compare/Tolerance.h"
#include "core/explain/Explain.h"
#include "core/explain/ExplainArguments.h"
#include "core/explain/NumberFormat.h"
#include "core/explain/PixelTrace.h"
#include "core/film/Image.h"
#include "core/film/Background.h"
#include "core/film/ImageWriter.h"
#include "core/integrate/profiles/Profile.h"
#include "core/render/PreparedScene.h"
#include "core/render/PreparedVolume.h"
#include "core/render/Renderer.h"
#include "python/SceneInput.h"

#ifndef VOLREF_VERSION
#define VOLREF_VERSION "0"
#endif

namespace py = pybind11;
using namespace pybind11::literals;

namespace volref::python {

namespace {

std::string type_name(py::handle v) { return py::str(py::type::handle_of(v).attr("__name__")); }

// ---- the process-wide settings a call may change for its duration ------------------------------

// max_memory: None (the current limit: the machine's memory or VOLREF_MAX_MEMORY), a size in bytes
// (int) or a size text as --max-memory takes it ("4G", "512MiB"). Restored when the call returns.
class MemoryScope {
public:
    explicit MemoryScope(py::handle max_memory) {
        if (max_memory.is_none()) return;
        std::size_t bytes = 0;
        if (py::isinstance<py::str>(max_memory)) {
            bytes = parse_memory_size(max_memory.cast<std::string>(), "max_memory");
        } else if (py::isinstance<py::int_>(max_memory) && !py::isinstance<py::bool_>(max_memory)) {
            const long long v = PyLong_AsLongLong(max_memory.ptr());
            if (PyErr_Occurred() || v <= 0) {
                PyErr_Clear();
                throw Error("max_memory: expected a size > 0 in bytes or a text such as \"4G\", got " +
                            std::string(py::str(max_memory)));
            }
            bytes = std::size_t(v);
        } else {
            throw Error("max_memory: expected a size in bytes (int) or a text such as \"4G\", got a " + type_name(max_memory));
        }
        old_ = memory_limit();
        set_memory_limit(bytes);
        set_ = true;
    }
    ~MemoryScope() {
        if (set_) set_memory_limit(old_);
    }
    MemoryScope(const MemoryScope&) = delete;
    MemoryScope& operator=(const MemoryScope&) = delete;

private:
    std::size_t old_ = 0;
    bool set_ = false;
};

// Runs `work` on a worker thread with the GIL released, while this thread checks for Python signals
// every 50 ms. Ctrl-C (KeyboardInterrupt, or any exception a signal handler raises) requests a cancel
// (core/Cancellation.h: the renderer stops at its next tile), waits for the worker, forgets the
// request and raises the signal's exception. Otherwise the worker's exception, if any, is rethrown.
void run_cancellable(const std::function<void()>& work) {
    std::exception_ptr failure;
    std::mutex m;
    std::condition_variable cv;
    bool done = false;
    PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
    {
        py::gil_scoped_release release;
        std::thread worker([&] {
            try {
                work();
            } catch (...) {
                failure = std::current_exception();
            }
            {
                std::lock_guard<std::mutex> lock(m);
                done = true;
            }
            cv.notify_all();
        });
        bool interrupted = false;
        while (true) {
            {
                std::unique_lock<std::mutex> lock(m);
                if (cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
            }
            if (interrupted) continue;
            py::gil_scoped_acquire acquire;
            if (PyErr_CheckSignals() != 0) {
                PyErr_Fetch(&type, &value, &traceback);
                interrupted = true;
                request_cancel(SIGINT);
            }
        }
        worker.join();
    }
    if (type) {
        reset_cancel();
        PyErr_Restore(type, value, traceback);
        throw py::error_already_set();
    }
    if (failure) std::rethrow_exception(failure);
}

// Rethrows a volref::Error from `f` with the temporary files of numpy volumes named by their keys.
template <class F> auto with_scene_messages(const SceneInput& in, F&& f) {
    try {
        return f();
    } catch (const Cancelled&) {
        throw;
    } catch (const Error& e) {
        throw Error(in.rewrite(e.what()));
    }
}

int threads_of(py::handle threads) {
    if (threads.is_none()) return 0;
    if (!py::isinstance<py::int_>(threads) || py::isinstance<py::bool_>(threads))
        throw Error("threads: expected an integer in [1, 4096] or None (all cores), got a " + type_name(threads));
    const long long t = PyLong_AsLongLong(threads.ptr());
    if (PyErr_Occurred() || t < 1 || t > 4096) {
        PyErr_Clear();
        throw Error("threads: expected an integer in [1, 4096] or None (all cores), got " + std::string(py::str(threads)));
    }
    return int(t);
}

py::object json_loads(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

// ---- render -----------------------------------------------------------------------------------

struct RenderResult {
    std::shared_ptr<Image> image;
    py::object scene;
    std::size_t non_finite_voxels = 0;

    std::optional<std::size_t> channel(const std::string& name) const {
        for (std::size_t c = 0; c < image->channels.size(); ++c)
            if (image->channels[c] == name) return c;
        return std::nullopt;
    }
};

// A view of channels [first, first + count) of the result's pixels (no copy; `self` keeps them alive):
// shape (height, width, count), or (height, width) for count 0 (one channel).
py::array pixel_view(py::object self, std::size_t first, std::size_t count) {
    const RenderResult& r = self.cast<const RenderResult&>();
    const Image& im = *r.image;
    const auto d = py::ssize_t(sizeof(double));
    const auto C = py::ssize_t(im.channel_count());
    double* data = const_cast<double*>(im.pixels.data()) + first;
    if (count == 0)
        return py::array(py::dtype::of<double>(), {py::ssize_t(im.height), py::ssize_t(im.width)},
                         {C * im.width * d, C * d}, data, self);
    return py::array(py::dtype::of<double>(), {py::ssize_t(im.height), py::ssize_t(im.width), py::ssize_t(count)},
                     {C * im.width * d, C * d, d}, data, self);
}

RenderResult render(py::object scene, py::object threads, py::object overrides, bool error, bool skipping,
                    py::object max_memory) {
    const MemoryScope memory(max_memory);
    RenderOptions options;
    options.threads = threads_of(threads);
    options.error_estimate = error;
    options.empty_space_skipping = skipping;
    const std::unique_ptr<SceneInput> in = read_scene_input(scene, overrides);
    auto image = std::make_shared<Image>();
    RenderStats stats;
    with_scene_messages(*in, [&] {
        run_cancellable([&] { *image = render_scene(in->scene, options, &stats); });
        return 0;
    });
    RenderResult result{image, in->resolved(), stats.non_finite_voxels};
    for (const std::string& w : stats.warnings)
        if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
    if (stats.non_finite_voxels > 0)
        PyErr_WarnEx(PyExc_RuntimeWarning,
                     (std::to_string(stats.non_finite_voxels) + " non-finite voxels (NaN or Inf), rendered as transparent").c_str(),
                     1);
    return result;
}

// ---- compare ----------------------------------------------------------------------------------

// An input of compare(): a path, a numpy image or a RenderResult, as a ComparedImage.
compare::ComparedImage compared_input(py::handle v, const char* name, py::handle quantization,
                                      const std::optional<glm::dvec4>& background) {
    using compare::ComparedImage;
    const std::string arg = name;
    if (is_path_like(v) && !py::isinstance<RenderResult>(v)) {
        if (!quantization.is_none())
            throw Error("quantization: " + arg + " is an image file, whose quantisation comes from its format");
        return compare::read_compared_image(py::module_::import("os").attr("fspath")(v).cast<std::string>(), background);
    }
    ComparedImage out;
    py::array pixels;
    std::optional<py::array> error, fault;
    if (py::isinstance<RenderResult>(v)) {
        const RenderResult& r = v.cast<const RenderResult&>();
        pixels = pixel_view(py::reinterpret_borrow<py::object>(v), 0, 4);
        if (const auto e = r.channel("error")) error = pixel_view(py::reinterpret_borrow<py::object>(v), *e, 0);
        if (const auto f = r.channel("fault")) fault = pixel_view(py::reinterpret_borrow<py::object>(v), *f, 0);
        out.path = "<render " + arg + ">";
    } else if (py::isinstance<py::array>(v)) {
        pixels = py::reinterpret_borrow<py::array>(v);
        out.path = "<numpy array " + arg + ">";
    } else {
        throw Error(arg + ": expected an image file's path, a numpy array (height, width, 4 or 3) or a volref render, got a " +
                    type_name(v));
    }
    if (pixels.ndim() != 3 || (pixels.shape(2) != 4 && pixels.shape(2) != 3))
        throw Error(arg + ": expected a numpy array of shape (height, width, 4) (premultiplied RGBA) or (height, width, 3), got " +
                    std::to_string(pixels.ndim()) + " dimensions" +
                    (pixels.ndim() == 3 ? " with " + std::to_string(pixels.shape(2)) + " channels" : std::string()));
    if (pixels.shape(0) < 1 || pixels.shape(1) < 1) throw Error(arg + ": the image is empty");
    const char kind = pixels.dtype().kind();
    const auto size = pixels.dtype().itemsize();
    int bits = 0;
    double scale = 1.0;
    if (kind == 'u' && (size == 1 || size == 2)) {
        bits = int(size) * 8;  // stored integers, read as v / (2^bits - 1) in double (as image files)
        scale = size == 1 ? 255.0 : 65535.0;
    } else if (kind != 'f') {
        throw Error(arg + ": numpy dtype " + std::string(py::str(py::object(pixels.dtype()))) +
                    " is not an image type (expected a float type, uint8 or uint16)");
    }
    if (!quantization.is_none()) {
        if (!py::isinstance<py::int_>(quantization) || py::isinstance<py::bool_>(quantization))
            throw Error("quantization: expected the bits of an integer format (1 to 32), got a " + type_name(quantization));
        const long long q = PyLong_AsLongLong(quantization.ptr());
        if (PyErr_Occurred() || q < 1 || q > 32) {
            PyErr_Clear();
            throw Error("quantization: expected the bits of an integer format (1 to 32), got " + std::string(py::str(quantization)));
        }
        bits = int(q);
    }
    const int h = int(pixels.shape(0)), w = int(pixels.shape(1));
    const int n = int(pixels.shape(2));
    const py::array_t<double, py::array::forcecast> d(pixels);  // a copy in double (values as stored)
    const auto p = d.unchecked<3>();
    out.bits = bits;
    out.rgba = Image(w, h, {"R", "G", "B", "A"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double c[4] = {p(y, x, 0) / scale, p(y, x, 1) / scale, p(y, x, 2) / scale, n == 4 ? p(y, x, 3) / scale : 1.0};
            if (background) composite_over_background(c, *background);  // the associated input over it (as the CLI)
            for (int k = 0; k < 4; ++k) out.rgba.at(x, y, std::size_t(k)) = c[k];
        }
    if (fault) {  // the rays a mirrored program does not finish
        const py::array_t<double, py::array::forcecast> e(*fault);
        const auto q = e.unchecked<2>();
        out.fault.resize(std::size_t(w) * std::size_t(h));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) out.fault[std::size_t(y) * std::size_t(w) + std::size_t(x)] = q(y, x) != 0.0;
    }
    if (error) {
        const py::array_t<double, py::array::forcecast> e(*error);
        const auto q = e.unchecked<2>();
        out.error.resize(std::size_t(w) * std::size_t(h));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) out.error[std::size_t(y) * std::size_t(w) + std::size_t(x)] = q(y, x);
    }
    return out;
}

// An `error` channel given as an array for one input.
void set_error_channel(compare::ComparedImage& image, py::handle e, const char* name) {
    if (e.is_none()) return;
    if (!py::isinstance<py::array>(e) && !py::isinstance<py::list>(e))
        throw Error(std::string("error: expected True or an array of shape (height, width) for ") + name + ", got a " +
                    type_name(e));
    const py::array_t<double, py::array::forcecast> a(py::reinterpret_borrow<py::object>(e));
    if (a.ndim() != 2 || a.shape(0) != image.rgba.height || a.shape(1) != image.rgba.width)
        throw Error(std::string("error: the error array of ") + name + " must have shape (" +
                    std::to_string(image.rgba.height) + ", " + std::to_string(image.rgba.width) + ")");
    const auto q = a.unchecked<2>();
    image.error.assign(std::size_t(image.rgba.width) * std::size_t(image.rgba.height), 0.0);
    for (int y = 0; y < image.rgba.height; ++y)
        for (int x = 0; x < image.rgba.width; ++x)
            image.error[std::size_t(y) * std::size_t(image.rgba.width) + std::size_t(x)] = q(y, x);
}


// A pair (for a, for b) given as a 2-tuple, or one value for both.
std::pair<py::object, py::object> pair_of(py::handle v) {
    if (py::isinstance<py::tuple>(v) && py::len(v) == 2)
        return {py::reinterpret_borrow<py::object>(v[py::int_(0)]), py::reinterpret_borrow<py::object>(v[py::int_(1)])};
    return {py::reinterpret_borrow<py::object>(v), py::reinterpret_borrow<py::object>(v)};
}

// (r, g, b, a) in [0, 1], or None.
std::optional<glm::dvec4> background_of(py::handle background_arg) {
    if (background_arg.is_none()) return std::nullopt;
    std::vector<double> v;
    try {
        v = background_arg.cast<std::vector<double>>();
    } catch (const py::cast_error&) {
    }
    if (v.size() != 4 || !std::all_of(v.begin(), v.end(), [](double x) { return x >= 0.0 && x <= 1.0; }))
        throw Error("background: expected (r, g, b, a), four numbers in [0, 1]");
    return glm::dvec4(v[0], v[1], v[2], v[3]);
}

py::object compare_images(py::object a_arg, py::object b_arg, py::object tolerance, py::object error,
                          py::object quantization, py::object background_arg, py::object max_memory) {
    const MemoryScope memory(max_memory);
    double absolute = 0.0;
    if (!tolerance.is_none()) {
        if (!py::isinstance<py::float_>(tolerance) && !(py::isinstance<py::int_>(tolerance) && !py::isinstance<py::bool_>(tolerance)))
            throw Error("tolerance: expected a number >= 0, got a " + type_name(tolerance));
        absolute = tolerance.cast<double>();
        if (!std::isfinite(absolute) || absolute < 0.0)
            throw Error("tolerance: expected a number >= 0, got " + std::string(py::repr(tolerance)));
    }
    const std::optional<glm::dvec4> background = background_of(background_arg);
    // quantization: None, bits for both numpy inputs, or (bits_a, bits_b) with None for "from the input".
    const auto [qa, qb] = pair_of(quantization);
    // error: None/False, True (each input's own `error` channel), or arrays: one for both, or (error_a, error_b).
    bool from_error = false;
    py::object ea = py::none(), eb = py::none();
    if (py::isinstance<py::bool_>(error)) {
        from_error = error.cast<bool>();
    } else if (!error.is_none()) {
        from_error = true;
        std::tie(ea, eb) = pair_of(error);
    }

    compare::ComparedImage a = compared_input(a_arg, "a", qa, background);
    compare::ComparedImage b = compared_input(b_arg, "b", qb, background);
    if (a.rgba.width != b.rgba.width || a.rgba.height != b.rgba.height)
        throw Error(a.path.string() + " is " + std::to_string(a.rgba.width) + "x" + std::to_string(a.rgba.height) +
                    " but " + b.path.string() + " is " + std::to_string(b.rgba.width) + "x" +
                    std::to_string(b.rgba.height) + ": compare needs images of the same size");
    set_error_channel(a, ea, "a");
    set_error_channel(b, eb, "b");
    if (from_error && a.error.empty() && b.error.empty())
        throw Error("error: neither " + a.path.string() + " nor " + b.path.string() + " has an `error` channel");

    const std::vector<std::array<int, 2>> faults = compare::exclude_faults(a, b);
    const compare::ToleranceSpec tspec{absolute, from_error};
    compare::ImageMetrics m;
    {
        py::gil_scoped_release release;
        const std::vector<double> tol = compare::tolerance_map(a, b, tspec);
        m = compare::measure_difference(a.rgba, b.rgba, tol);
    }
    nlohmann::json j;
    j["a"] = {{"path", a.path.string()}, {"description", a.description()}};
    j["b"] = {{"path", b.path.string()}, {"description", b.description()}};
    j["width"] = a.rgba.width;
    j["height"] = a.rgba.height;
    j["tolerance"] = compare::describe_tolerance(a, b, tspec);
    for (const compare::ChannelMetrics& c : m.channels) j["channels"][c.name] = compare::channel_json(c, m.pixels);
    j["overall"] = compare::channel_json(m.overall, m.pixels);
    j["pixels"] = m.pixels;
    j["pixels_over"] = m.overall.over;
    j["non_finite"] = {{"a", m.non_finite_a}, {"b", m.non_finite_b}, {"disagree", m.non_finite_disagree}};
    j["fault"] = nlohmann::json::array();  // the pixels (x, y) where a mirrored program does not finish
    for (const auto& f : faults) j["fault"].push_back({f[0], f[1]});
    j["fraction_over"] = m.fraction_over();
    j["within_tolerance"] = m.overall.over == 0;
    return json_loads(j.dump());
}

// ---- fit, heatmap, write_image, profiles ------------------------------------------------------

// A (height, width) float64 array of `values` (row 0 on top).
py::array_t<double> image_plane(const std::vector<double>& values, int width, int height) {
    py::array_t<double> out({py::ssize_t(height), py::ssize_t(width)});
    std::copy(values.begin(), values.end(), out.mutable_data());
    return out;
}

py::object fit_conventions(py::object image, py::object scene, py::object tolerance, py::object threads, py::object overrides,
                           py::object background_arg, py::object heatmap, py::object max_memory) {
    const MemoryScope memory(max_memory);
    compare::SearchOptions so;
    if (!tolerance.is_none()) {
        so.tolerance = tolerance.cast<double>();
        if (!std::isfinite(so.tolerance) || so.tolerance < 0.0)
            throw Error("tolerance: expected a number >= 0, got " + std::string(py::repr(tolerance)));
    }
    if (!threads.is_none()) so.threads = threads.cast<int>();
    so.background = background_of(background_arg);
    std::filesystem::path heatmap_path;
    if (!heatmap.is_none()) {
        heatmap_path = py::module_::import("os").attr("fspath")(heatmap).cast<std::string>();
        compare::check_heatmap_path(heatmap_path);
    }
    compare::ComparedImage g = compared_input(image, "image", py::none(), so.background);
    const std::unique_ptr<SceneInput> in = read_scene_input(scene, overrides);
    compare::SearchResult r;
    with_scene_messages(*in, [&] {
        run_cancellable([&] {  // Ctrl-C stops the render in progress (as render's)
            r = compare::search_conventions(g, in->scene, so);
            if (!heatmap_path.empty()) {
                double largest = 0.0;
                for (double x : r.residual) largest = std::max(largest, x);
                compare::write_heatmap(r.residual, r.width, r.height, largest, heatmap_path);
            }
        });
        return 0;
    });
    py::object d = json_loads(r.to_json().dump());
    d["residual"] = image_plane(r.residual, r.width, r.height);
    return d;
}

py::array_t<double> heatmap_of(py::object a_arg, py::object b_arg, py::object path, py::object scale) {
    const compare::ComparedImage a = compared_input(a_arg, "a", py::none(), std::nullopt);
    const compare::ComparedImage b = compared_input(b_arg, "b", py::none(), std::nullopt);
    if (a.rgba.width != b.rgba.width || a.rgba.height != b.rgba.height)
        throw Error("b: the images differ in size (" + std::to_string(a.rgba.width) + "x" + std::to_string(a.rgba.height) + " and " +
                    std::to_string(b.rgba.width) + "x" + std::to_string(b.rgba.height) + ")");
    const std::vector<double> map = compare::max_abs_difference_map(a.rgba, b.rgba);
    if (!path.is_none()) {
        const std::filesystem::path p = py::module_::import("os").attr("fspath")(path).cast<std::string>();
        compare::check_heatmap_path(p);
        double s = 0.0;
        if (!scale.is_none()) {
            s = scale.cast<double>();
            if (!std::isfinite(s) || s < 0.0) throw Error("scale: expected a number >= 0");
        }
        if (s == 0.0)
            for (double x : map)
                if (std::isfinite(x)) s = std::max(s, x);
        compare::write_heatmap(map, a.rgba.width, a.rgba.height, s, p);
    }
    return image_plane(map, a.rgba.width, a.rgba.height);
}

// An image to write: a RenderResult (every channel) or a numpy array (height, width, 4 or 3) of
// premultiplied linear RGBA (3: alpha 1).
Image image_of(py::handle v, const char* name) {
    if (py::isinstance<RenderResult>(v)) return *v.cast<const RenderResult&>().image;
    if (!py::isinstance<py::array>(v))
        throw Error(std::string(name) + ": expected a volref render or a numpy array (height, width, 4), got a " + type_name(v));
    const py::array_t<double, py::array::forcecast> a(py::reinterpret_borrow<py::array>(v));
    if (a.ndim() != 3 || (a.shape(2) != 4 && a.shape(2) != 3) || a.shape(0) < 1 || a.shape(1) < 1)
        throw Error(std::string(name) + ": expected a numpy array of shape (height, width, 4) (premultiplied RGBA) or (height, width, 3)");
    const auto q = a.unchecked<3>();
    Image im(int(a.shape(1)), int(a.shape(0)), {"R", "G", "B", "A"});
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            for (int c = 0; c < 4; ++c) im.at(x, y, std::size_t(c)) = c < a.shape(2) ? q(y, x, c) : 1.0;
    return im;
}

// The background a RenderResult's scene names (image.background), else transparent.
glm::dvec4 scene_background(py::handle v) {
    glm::dvec4 bg(0.0);
    if (!py::isinstance<RenderResult>(v)) return bg;
    try {
        const py::list b = v.cast<const RenderResult&>().scene["image"]["background"];
        for (int c = 0; c < 4; ++c) bg[c] = b[std::size_t(c)].cast<double>();
    } catch (const std::exception&) {
    }
    return bg;
}

void write_image_file(py::object path, py::object image, py::object background_arg) {
    const std::filesystem::path p = py::module_::import("os").attr("fspath")(path).cast<std::string>();
    const Image im = image_of(image, "image");
    const glm::dvec4 bg = background_of(background_arg).value_or(scene_background(image));
    check_output_path(p);
    py::gil_scoped_release release;
    write_image(im, p, bg);
}

py::object profiles_dict() {
    nlohmann::json j = nlohmann::json::object();
    for (ProfileId id : preset_ids()) {
        RenderSpec r;
        r.profile = id;
        const nlohmann::json rules = profile_rules_json(resolve_profile(r));
        j[rules["base"].get<std::string>()] = rules;
    }
    return json_loads(j.dump());
}

// PNG bytes of the image composited over its scene's background (as volref render writes PNG):
// IHDR, one IDAT (Python's zlib) and IEND, 8-bit RGBA, non-interlaced.
py::bytes png_bytes(py::object self) {
    const RenderResult& r = self.cast<const RenderResult&>();
    const Image& im = *r.image;
    const glm::dvec4 bg = scene_background(self);
    std::string raw;
    raw.reserve(std::size_t(im.height) * (1 + 4 * std::size_t(im.width)));
    for (int y = 0; y < im.height; ++y) {
        raw.push_back(0);  // filter: none
        for (int x = 0; x < im.width; ++x) {
            double c[4];
            for (int k = 0; k < 4; ++k) c[k] = im.at(x, y, std::size_t(k));
            composite_over_background(c, bg);
            for (int k = 0; k < 4; ++k) {
                const double v = k < 3 ? (c[3] > 0.0 ? c[k] / c[3] : 0.0) : c[3];
                const double q = std::round(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0) * 255.0);
                raw.push_back(char(static_cast<unsigned char>(q)));
            }
        }
    }
    const py::module_ zlib = py::module_::import("zlib");
    auto be32 = [](std::uint32_t v) {
        return std::string{char(v >> 24), char((v >> 16) & 255), char((v >> 8) & 255), char(v & 255)};
    };
    auto chunk = [&](const std::string& type, const std::string& data) {
        const std::string td = type + data;
        const auto crc = zlib.attr("crc32")(py::bytes(td)).cast<std::uint32_t>();
        return be32(std::uint32_t(data.size())) + td + be32(crc);
    };
    const std::string ihdr = be32(std::uint32_t(im.width)) + be32(std::uint32_t(im.height)) + std::string{8, 6, 0, 0, 0};
    const std::string idat = zlib.attr("compress")(py::bytes(raw)).cast<std::string>();
    return py::bytes(std::string("\x89PNG\r\n\x1a\n") + chunk("IHDR", ihdr) + chunk("IDAT", idat) + chunk("IEND", ""));
}

// ---- trace ------------------------------------------------------------------------------------

std::array<int, 2> pixel_of(py::handle pixel, int width, int height, const char* name = "pixel") {
    std::vector<long long> v;
    bool ok = py::isinstance<py::sequence>(pixel) && !py::isinstance<py::str>(pixel) && py::len(pixel) == 2;
    if (ok) {
        for (py::handle e : pixel) {
            const py::object i = py::module_::import("operator").attr("index");
            try {
                v.push_back(i(e).cast<long long>());
            } catch (const py::error_already_set&) {
                ok = false;
            }
        }
    }
    if (!ok || v.size() != 2) throw Error(std::string(name) + ": expected (x, y), two integers, got " + std::string(py::repr(pixel)));
    if (v[0] < 0 || v[0] >= width || v[1] < 0 || v[1] >= height)
        throw Error(std::string(name) + ": (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ") is outside the " +
                    std::to_string(width) + " x " + std::to_string(height) + " image");
    return {int(v[0]), int(v[1])};
}

// The trace as a numpy structured array whose fields are the columns of `volref trace`'s CSV
// (docs/trace.md), in its order: int64 for sample and cell_i..cell_k, float64 for the rest (NaN where
// the CSV cell is empty: a value the sample did not compute). The numbers are read back from the CSV's
// shortest round-trip text, so they are the computed doubles bit for bit.
py::array trace_array(const explain::PixelTrace& t) {
    const std::vector<std::string> names = explain::trace_csv_header(t);
    std::ostringstream csv;
    explain::write_trace_csv(t, csv);
    auto is_int = [](const std::string& n) { return n == "sample" || n == "interval" || n == "segment" || n == "cell_i" || n == "cell_j" || n == "cell_k"; };
    py::list fields;
    for (const std::string& n : names) fields.append(py::make_tuple(n, is_int(n) ? "<i8" : "<f8"));
    const py::dtype dtype = py::module_::import("numpy").attr("dtype")(fields);
    py::array out(dtype, std::vector<py::ssize_t>{py::ssize_t(t.samples.size())}, std::vector<py::ssize_t>{});
    char* row = static_cast<char*>(out.mutable_data());
    std::istringstream lines(csv.str());
    std::string line;
    std::getline(lines, line);  // the header
    while (std::getline(lines, line)) {
        std::size_t start = 0;
        for (std::size_t c = 0; c < names.size(); ++c) {
            const std::size_t comma = line.find(',', start);
            const std::string cell = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
            start = comma == std::string::npos ? line.size() : comma + 1;
            if (is_int(names[c])) {
                const std::int64_t v = std::stoll(cell);
                std::memcpy(row + 8 * c, &v, 8);
            } else {
                double v = std::nan("");
                if (cell == "inf") v = INFINITY;
                else if (cell == "-inf") v = -INFINITY;
                else if (!cell.empty() && cell != "nan") {
                    const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), v);
                    if (r.ec != std::errc() || r.ptr != cell.data() + cell.size())
                        throw std::runtime_error("trace: cannot read back the number \"" + cell + "\"");
                }
                std::memcpy(row + 8 * c, &v, 8);
            }
        }
        row += 8 * names.size();
    }
    return out;
}

py::object trace(py::object scene, py::object pixel, py::object overrides, bool skipping, const std::string& format,
                 py::object max_memory) {
    if (format != "array" && format != "json") throw Error("format: expected \"array\" or \"json\", got \"" + format + "\"");
    const MemoryScope memory(max_memory);
    const std::unique_ptr<SceneInput> in = read_scene_input(scene, overrides);
    const auto p = pixel_of(pixel, in->scene.image.width, in->scene.image.height);
    if (is_first_hit(in->scene.render.projection)) throw Error("trace: first-hit is not supported yet");
    explain::PixelTrace t;
    with_scene_messages(*in, [&] {
        run_cancellable([&] {
            RenderOptions options;
            options.empty_space_skipping = skipping;
            const PreparedScene prepared(in->scene, options);
            t = explain::trace_pixel(prepared, p[0], p[1]);
        });
        return 0;
    });
    if (format == "json") return json_loads(explain::trace_json(t));
    return trace_array(t);
}

// ---- explain ----------------------------------------------------------------------------------

std::string number_token(py::handle v, const std::string& option) {
    if (py::isinstance<py::bool_>(v)) throw Error(option + ": expected a number, got " + std::string(py::repr(v)));
    if (py::isinstance<py::int_>(v)) return py::str(v);
    if (py::isinstance<py::float_>(v)) return explain::number(v.cast<double>());
    const py::module_ numpy = py::module_::import("numpy");
    if (py::isinstance(v, numpy.attr("generic"))) return number_token(v.attr("item")(), option);
    throw Error(option + ": expected a number, got the " + type_name(v) + " " + std::string(py::repr(v)));
}

bool is_scalar(py::handle v) {
    return py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v) ||
           py::isinstance(v, py::module_::import("numpy").attr("generic"));
}

bool is_sequence(py::handle v) {
    return (py::isinstance<py::sequence>(v) && !py::isinstance<py::str>(v) && !py::isinstance<py::bytes>(v)) ||
           py::isinstance<py::array>(v);
}

// One value of an option: a str, a number, or numbers joined by commas.
std::string value_token(py::handle v, const std::string& option) {
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::hasattr(v, "__fspath__")) return py::module_::import("os").attr("fspath")(v).cast<std::string>();
    if (is_sequence(v)) {
        std::string s;
        for (py::handle e : v) {
            if (!s.empty()) s += ',';
            s += number_token(e, option);
        }
        if (s.empty()) throw Error(option + ": expected numbers, got an empty sequence");
        return s;
    }
    return number_token(v, option);
}

// The tokens of one keyword argument: True -> the flag alone; a str, a number or a sequence of
// numbers -> one value; a sequence of strs or of sequences -> one value each (options that repeat).
void append_tokens(std::vector<std::string>& tokens, const std::string& option, py::handle value) {
    if (value.is_none()) return;
    const py::object v = py::isinstance<py::array>(value) ? py::object(value.attr("tolist")())
                                                           : py::reinterpret_borrow<py::object>(value);
    if (py::isinstance<py::bool_>(v)) {
        if (v.cast<bool>()) tokens.push_back(option);
        return;
    }
    tokens.push_back(option);
    if (is_sequence(v)) {
        bool nested = false;
        for (py::handle e : v) nested = nested || !is_scalar(e);
        if (nested) {
            for (py::handle e : v) tokens.push_back(value_token(e, option));
            return;
        }
    }
    tokens.push_back(value_token(v, option));
}

py::object explain_topic(const std::string& topic, py::kwargs kwargs) {
    py::object scene = py::none(), sets = py::none(), max_memory = py::none();
    std::vector<std::string> tokens;
    for (auto item : kwargs) {
        const std::string key = item.first.cast<std::string>();
        if (key == "scene") {
            scene = py::reinterpret_borrow<py::object>(item.second);
            continue;
        }
        if (key == "set" || key == "overrides") {
            sets = py::reinterpret_borrow<py::object>(item.second);
            continue;
        }
        if (key == "max_memory") {
            max_memory = py::reinterpret_borrow<py::object>(item.second);
            continue;
        }
        std::string option = "--" + key;
        std::replace(option.begin(), option.end(), '_', '-');
        append_tokens(tokens, option, item.second);
    }
    const MemoryScope memory(max_memory);
    const std::vector<std::string> set_strings = override_strings(sets);
    explain::Explanation e;
    if (scene.is_none() || is_path_like(scene)) {
        // As `volref explain TOPIC ...`: the same parser and calculators.
        if (!scene.is_none()) {
            tokens.push_back("--scene");
            tokens.push_back(py::module_::import("os").attr("fspath")(scene).cast<std::string>());
        }
        for (const std::string& s : set_strings) {
            tokens.push_back("--set");
            tokens.push_back(s);
        }
        run_cancellable([&] { e = explain::from_arguments(topic, tokens); });
        return json_loads(explain::to_json(e));
    }
    // A dict or JSON text: the topics that read a scene (ray; trilinear --at) are called here on the
    // scene read by read_scene_input, with the calculators `volref explain` calls.
    const std::unique_ptr<SceneInput> in = read_scene_input(scene, sets);
    auto option = [&](const std::string& name) -> py::object {
        for (auto item : kwargs)
            if (item.first.cast<std::string>() == name) return py::reinterpret_borrow<py::object>(item.second);
        return py::none();
    };
    auto allow = [&](std::initializer_list<const char*> allowed) {
        for (auto item : kwargs) {
            const std::string k = item.first.cast<std::string>();
            bool ok = k == "scene" || k == "set" || k == "overrides" || k == "max_memory";
            for (const char* a : allowed) ok = ok || k == a;
            if (!ok) {
                std::string list = "scene, set";
                for (const char* a : allowed) list += std::string(", ") + a;
                throw Error("--" + k + ": not an option of explain " + topic + " with a scene given as a dict or JSON text (allowed: " + list + ")");
            }
        }
    };
    if (topic == "ray") {
        allow({"pixel", "no_skipping"});
        if (option("pixel").is_none()) throw Error("--pixel: required by explain ray");
        const auto p = pixel_of(option("pixel"), in->scene.image.width, in->scene.image.height, "--pixel");
        if (is_first_hit(in->scene.render.projection)) throw Error("trace: first-hit is not supported yet");
        const py::object skip = option("no_skipping");
        const bool no_skipping = !skip.is_none() && skip.cast<bool>();
        with_scene_messages(*in, [&] {
            run_cancellable([&] {
                RenderOptions options;
                options.empty_space_skipping = !no_skipping;
                const PreparedScene prepared(in->scene, options);
                e = explain::ray(prepared, p[0], p[1]);
            });
            return 0;
        });
    } else if (topic == "trilinear") {
        allow({"at"});
        const py::object at_arg = option("at");
        if (at_arg.is_none()) throw Error("--at: required by explain trilinear");
        std::vector<double> at;
        try {
            at = at_arg.cast<std::vector<double>>();
        } catch (const py::cast_error&) {
        }
        if (at.size() != 3 || !std::all_of(at.begin(), at.end(), [](double x) { return std::isfinite(x); }))
            throw Error("--at: expected 3 numbers X,Y,Z (finite numbers separated by commas), got " + std::string(py::repr(at_arg)));
        with_scene_messages(*in, [&] {
            run_cancellable([&] {
                VolumeModel model;
                build_volume_model(in->scene.volume(), model);
                if (!model.cartesian) throw Error("--scene: explain trilinear --at needs a Cartesian grid (box or mesh bounds)");
                e = explain::trilinear_at(*model.cartesian, {at[0], at[1], at[2]});
            });
            return 0;
        });
    } else {
        throw Error("--scene: not an option of explain " + topic);
    }
    return json_loads(explain::to_json(e));
}

}  // namespace

}  // namespace volref::python

// ---- the module -------------------------------------------------------------------------------

PYBIND11_MODULE(volref, m) {
    using namespace volref::python;
    m.doc() = R"doc(volref: the pure-CPU reference volume ray caster, from Python (docs/python.md).

Functions:
  render(scene, ...)   render a scene to numpy arrays (the numbers of `volref render`'s EXR)
  compare(a, b, ...)   the metrics of `volref compare --json` for two images (numpy or files)
  trace(scene, pixel)  every sample of one pixel's ray (`volref trace`), as a numpy structured array
  explain(topic, ...)  a formula worked step by step (`volref explain TOPIC --json`), as a dict
Errors in the input raise volref.Error (a ValueError) with volref's one-line message.
A scene is a scene file's path, JSON text, or a dict in the scene format (docs/scene-format.md) whose
volumes' "source" may be a 3-D numpy array indexed [k, j, i] (shape (nz, ny, nx), x fastest).)doc";
    m.attr("__version__") = VOLREF_VERSION;

    static py::exception<volref::Error> error(m, "Error", PyExc_ValueError);
    error.attr("__doc__") = "Bad input to volref: the one-line message names the file, scene key or argument at fault.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const volref::Error& e) {
            error(e.what());
        }
    });
    // The memory limit of VOLREF_MAX_MEMORY, as the command line takes it (docs/robustness.md).
    if (const char* limit = std::getenv("VOLREF_MAX_MEMORY"); limit && *limit)
        volref::set_memory_limit(volref::parse_memory_size(limit, "VOLREF_MAX_MEMORY"));

    py::class_<RenderResult>(m, "RenderResult", R"doc(What volref.render returns: the image as numpy views (no copy) of
one float64 buffer, row 0 at the top.)doc")
        .def_property_readonly(
            "rgba", [](py::object self) { return pixel_view(self, 0, 4); },
            "float64 array (height, width, 4): premultiplied linear R, G, B, A, the numbers the CLI writes to EXR (as float)")
        .def_property_readonly(
            "depth",
            [](py::object self) -> py::object {
                const auto c = self.cast<const RenderResult&>().channel("Z");
                return c ? py::object(pixel_view(self, *c, 0)) : py::none();
            },
            "float64 array (height, width): the first-hit depth (EXR channel Z; inf where no hit), or None for other projections")
        .def_property_readonly(
            "error",
            [](py::object self) -> py::object {
                const auto c = self.cast<const RenderResult&>().channel("error");
                return c ? py::object(pixel_view(self, *c, 0)) : py::none();
            },
            "float64 array (height, width): the estimated bound on each pixel's error (render(..., error=True), or the "
            "adaptive integrator), or None")
        .def_property_readonly(
            "pixels",
            [](py::object self) {
                return pixel_view(self, 0, self.cast<const RenderResult&>().image->channel_count());
            },
            "float64 array (height, width, len(channels)): every channel, as the EXR holds them")
        .def_property_readonly(
            "channels", [](const RenderResult& r) { return r.image->channels; },
            "the channel names, as in the EXR: ['R', 'G', 'B', 'A'] and 'Z' (first-hit), 'error'")
        .def_property_readonly("width", [](const RenderResult& r) { return r.image->width; })
        .def_property_readonly("height", [](const RenderResult& r) { return r.image->height; })
        .def_readonly("scene", &RenderResult::scene,
                      "the scene as volref resolved it (a dict: every default filled in, overrides applied, file paths "
                      "absolute; a numpy volume's source is the array)")
        .def_readonly("non_finite_voxels", &RenderResult::non_finite_voxels,
                      "the number of NaN or infinite voxels (rendered transparent; a RuntimeWarning says so)")
        .def("_repr_png_", &png_bytes, "PNG bytes of the image over its scene's background (Jupyter shows it)")
        .def("__repr__", [](const RenderResult& r) {
            std::string ch;
            for (const std::string& c : r.image->channels) ch += (ch.empty() ? "" : ",") + c;
            return "<volref.RenderResult " + std::to_string(r.image->width) + "x" + std::to_string(r.image->height) +
                   " channels " + ch + ">";
        });

    m.def("render", &render, py::arg("scene"), py::kw_only(), py::arg("threads") = py::none(),
          py::arg("overrides") = py::none(), py::arg("error") = false, py::arg("skipping") = true,
          py::arg("max_memory") = py::none(),
          R"doc(Render a scene; returns a RenderResult (.rgba, .depth, .error, .channels, .scene).

Arguments:
  scene       a scene file's path (str or os.PathLike), JSON text (a str starting with '{'), or a dict in
              the scene format (docs/scene-format.md). In a dict, a volume's "source" may be a 3-D numpy
              array indexed [k, j, i] (shape (nz, ny, nx), C order: x fastest) of dtype uint8, int8, uint16,
              int16, uint32, int32, float32 or float64; give its placement with the volume's "origin" and
              "spacing" (default 0 and 1). Relative files in a dict or JSON text are relative to the
              current working directory.
  threads     worker threads (1 to 4096); None: all cores. The image does not depend on it.
  overrides   a list of "PATH=VALUE" strings (the CLI's --set, e.g. "render.step=0.25") or a dict
              {"render.step": 0.25}.
  error       also estimate each pixel's error by step doubling (the CLI's --error): adds .error.
  skipping    empty-space skipping (False: the CLI's --no-skipping; the image is the same).
  max_memory  refuse volumes, images and caches needing more memory: bytes (int) or a size such as "4G"
              (the CLI's --max-memory); None: the current limit. Restored when the call returns.

The render runs with the GIL released; Ctrl-C stops it at the next tile and raises KeyboardInterrupt.
Bad input raises volref.Error with volref's one-line message naming the file or key at fault.)doc");

    m.def("compare", &compare_images, py::arg("a"), py::arg("b"), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("error") = py::none(), py::arg("quantization") = py::none(), py::arg("background") = py::none(),
          py::arg("max_memory") = py::none(),
          R"doc(Compare two images as `volref compare A B --json` does; returns its JSON as a dict.

Arguments:
  a, b          each an image file's path (any format OpenImageIO reads, as the CLI), a volref RenderResult
                (its .rgba and .error), or a numpy array (height, width, 4) of premultiplied linear RGBA
                (or (height, width, 3): alpha 1). Float arrays are taken as they are; uint8 / uint16
                arrays are v / 255, v / 65535 and count as 8- / 16-bit quantised.
  tolerance     the absolute tolerance per pixel and channel (the CLI's --tolerance); default 0.
  error         True: add each input's error channel to the tolerance (--tolerance-from-error; a file's
                `error` channel, a RenderResult's .error); or an array (height, width) of error bounds
                for both numpy inputs, or a pair (error_a, error_b) with None for "none".
  quantization  the bits of integer quantisation a numpy input went through (e.g. 8 for an RGBA8
                framebuffer read back as float): adds 0.5 / (2^bits - 1) per channel; an int for both
                numpy inputs or a pair (bits_a, bits_b); None: from the dtype.
  background    (r, g, b, a) in [0, 1]: composite every premultiplied input over it (--background).
  max_memory    as for render.

Returns {"a", "b", "width", "height", "tolerance", "channels": {"R": {...}, ...}, "overall": {"max_abs",
"mean_abs", "rmse", "psnr_db", "ssim", "pixels_over", "fraction_over"}, "pixels", "pixels_over",
"non_finite": {"a", "b", "disagree"}, "fraction_over", "within_tolerance"}; +inf PSNR and missing SSIM are None, as in the CLI's JSON.)doc");

    m.def("fit", &fit_conventions, py::arg("image"), py::arg("scene"), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("threads") = py::none(), py::arg("overrides") = py::none(), py::arg("background") = py::none(),
          py::arg("heatmap") = py::none(), py::arg("max_memory") = py::none(),
          R"doc(Which conventions explain another renderer's image of a scene: `volref compare IMAGE --fit --scene SCENE`.

The scene is re-rendered with its profile's rules changed (render.profile: placement, ray_box, table,
step_voxel, correction, termination, normal, gradient, clamp_shaded), one and then two at a time, and each
render read under the image models (vertical flip, unpremultiplied, double-premultiplied, BGRA,
sRGB-encoded). A pixel is explained when every channel is within tolerance (default 1e-4) plus the
render's error channel and the image's quantisation (docs/compare.md, "Convention search").

Arguments: image (a path, numpy array (height, width, 4) of premultiplied RGBA, or a RenderResult), scene
(as for render), tolerance, threads, overrides (as for render), background (as for compare), heatmap (a
PNG path: the residual the best set leaves), max_memory (as for render). tolerance None: 1e-4; 0 is 0.
Returns {"explained", "rules" (the render.profile keys that explain, {} when not explained),
"image_model" (None when not explained), "unexplained_pixels", "residual_max", "residual_rms", "pixels",
"explained_fraction", "unexplained_before" (under the scene's own profile), "tolerance", "closest":
{"rules", "image_model"}, "alpha_agrees_colour_differs", "alpha_explained_by" (when it is true),
"verdict", "tried": [{"rules", "image_model", "unexplained_pixels", "residual_max", "residual_rms"}],
"residual": numpy (height, width)}. Ctrl-C stops it (KeyboardInterrupt).)doc");

    m.def("heatmap", &heatmap_of, py::arg("a"), py::arg("b"), py::kw_only(), py::arg("path") = py::none(),
          py::arg("scale") = py::none(),
          R"doc(The per-pixel max abs difference of two images over R, G, B, A, as a numpy array (height, width);
with `path`, also written as `volref compare --heatmap` writes it (black 0 -> white `scale`, default the
largest difference). a, b: as for compare.)doc");

    m.def("write_image", &write_image_file, py::arg("path"), py::arg("image"), py::kw_only(), py::arg("background") = py::none(),
          R"doc(Write an image as `volref render` does: .exr (linear float, premultiplied, every channel of a
RenderResult), .png / .tif (composited over `background`, default transparent, unassociated alpha).
image: a RenderResult or a numpy array (height, width, 4) of premultiplied linear RGBA (3: alpha 1).
background None: a RenderResult's own image.background (as volref render), else transparent.)doc");

    m.def("profiles", &profiles_dict,
          R"doc(The presets of render.profile and their rules, as dicts in render.profile's object form
({"reference": {"base": "reference", "placement": "midpoints", ...}, "vtk-gpu": {...}, ...}); vtk-cpu,
vtk-js and fast are renderers of their own ({"base": name} only). Any of these dicts, changed, is a
valid render.profile.)doc");

    m.def("trace", &trace, py::arg("scene"), py::arg("pixel"), py::kw_only(), py::arg("overrides") = py::none(),
          py::arg("skipping") = true, py::arg("format") = "array", py::arg("max_memory") = py::none(),
          R"doc(Every sample along one pixel's ray, as `volref trace SCENE --pixel X,Y` lists them.

Arguments:
  scene       as for render.
  pixel       (x, y): x to the right, y down from the top-left corner.
  overrides   as for render.
  skipping    False: also list the segments empty-space skipping passes over (--no-skipping).
  format      "array" (default): a numpy structured array, one row per sample, whose fields are the
              CSV columns of docs/trace.md (sample, t0, t1, t, length, x, y, z, u0..u2, cell_i..cell_k,
              local_p..local_r, value, [grad_x..grad_z], class_r..class_b, opacity or coordinate,
              [shading], tau, alpha, transmittance_before, transmittance_after or running, acc_r, acc_g,
              acc_b, acc_a); NaN where a sample did not compute a value. The last row's acc_* is the pixel.
              "json": the dict of `volref trace --format json` (also the ray, intervals, pixel_value).
  max_memory  as for render.)doc");

    m.def("explain", &explain_topic, py::arg("topic"),
          R"doc(A formula worked step by step, as `volref explain TOPIC ... --json`; returns that JSON as a dict.

Each keyword is the CLI option of the same name (underscores for dashes): True is a flag, a number or
a sequence of numbers is one value (joined by commas), a sequence of strings or of sequences gives the
option once per element. Examples:
  explain("trilinear", corners=[5.0, 5.1, 5.2, 4.6, 4.9, 5.1, 5.3, 4.7], point=(0.2, 0.3, 0.8))
  explain("composite", samples=[(1, 0, 0, 0.5), (0, 0, 1, 0.5)], order="back-to-front")
  explain("opacity-correction", opacity=0.5, length=0.25)
  explain("ray", scene="reference_scenes/levoy-lecture.json", pixel=(32, 32))
The scene (ray, trilinear at=...) may also be a dict or JSON text as for render; set= (or overrides=)
takes the overrides. Topics: trilinear, composite, opacity-correction, classify-isovalue,
classify-boundary, shade, coords, intersect, ray (docs/explain.md).)doc");
}
