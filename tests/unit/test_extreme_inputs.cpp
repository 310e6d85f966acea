// Issue 32 (docs/robustness.md, "Extreme numbers", "Special files", "Limits: memory"): inputs that once
// crashed, hung, exhausted memory or rendered NaN with exit 0. Each gives one line naming its key or file,
// in-process (these tests run under the sanitizers too); tests/robustness/bad_inputs.py feeds the same
// classes to the command line, the Python module and volref-mpi and checks exit status, output, time and
// memory.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "TestScenes.h"
#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/compare/ComparedImage.h"
#include "core/explain/PixelTrace.h"
#include "core/render/PreparedScene.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"
#include "geometry/TriangleMesh.h"

namespace fs = std::filesystem;
using namespace volref;
using ::testing::HasSubstr;

namespace {

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        return m;
    }
    return "";
}

struct MemoryLimitGuard {
    std::size_t saved = memory_limit();
    ~MemoryLimitGuard() { set_memory_limit(saved); }
};

// An 8 x 8 render of a small Marschner-Lobb volume, `patch` spliced into its JSON (a "key": value
// text replacing the placeholder of its object).
std::string ml_json(const std::string& volume_extra, const std::string& camera, const std::string& render_extra) {
    return R"({"volume": {"source": {"field": "marschner-lobb", "dims": [9, 9, 9]},
                          "transfer": {"color": [[0, 1, 1, 1], [1, 1, 1, 1]], "opacity": [[0, 0], [1, 0.5]]})" +
           volume_extra + R"(},
              "camera": )" + camera + R"(,
              "image": {"width": 8, "height": 8},
              "render": {"projection": "composite")" + render_extra + "}}";
}
const std::string kCamera = R"({"type": "perspective", "eye": [4, 4, 30], "target": [4, 4, 4], "up": [0, 1, 0]})";

std::string render_error(const std::string& json) {
    return error_of([&] { render_scene(parse_scene(json, ".", "s.json"), {1, false}); });
}

}  // namespace

// Numbers beyond [1e-100, 1e100] in magnitude (0 aside): refused naming the key, wherever they are.
TEST(ExtremeInputs, NumbersBeyondTheRangeNameTheirKey) {
    struct Case {
        std::string json, key;
    };
    const Case cases[] = {
        {ml_json(R"(, "spacing": [1e200, 1e200, 1e200])", kCamera, ""), "volume.spacing[0]"},
        {ml_json(R"(, "bounds": {"type": "box", "max": [1e-300, 8, 8]})", kCamera, ""), "volume.bounds.max[0]"},
        {ml_json("", R"({"type": "perspective", "eye": [4, 4, 1e300], "target": [4, 4, 4], "up": [0, 1, 0]})", ""), "camera.eye[2]"},
        {ml_json("", R"({"type": "perspective", "eye": [4, 4, 30], "target": [4, 4, 4], "up": [1e-200, 1e-200, 0]})", ""), "camera.up[0]"},
        {ml_json(R"(, "transform": {"translate": [1e308, 0, 0]})", kCamera, ""), "volume.transform.translate[0]"},
        {ml_json("", kCamera, R"(, "step_units": "world", "step": 1e-300)"), "render.step"},
        {ml_json("", kCamera, R"(, "step": 5e-324)"), "render.step"},
    };
    for (const Case& c : cases) {
        const std::string m = render_error(c.json);
        EXPECT_THAT(m, HasSubstr(c.key)) << c.json;
        EXPECT_THAT(m, HasSubstr("beyond volref's range")) << m;
    }
    // the transfer function's unit distance, and a shell's radius (Embree asserted on 5e-324)
    std::string j = ml_json("", kCamera, "");
    j.replace(j.find("\"opacity\": [[0, 0], [1, 0.5]]"), 29, R"("opacity": [[0, 0], [1, 0.5]], "opacity_unit_distance": 5e-324)");
    EXPECT_THAT(render_error(j), HasSubstr("volume.transfer.opacity_unit_distance"));
    EXPECT_THAT(render_error(ml_json(R"(, "bounds": {"type": "spherical", "radius": [0, 5e-324]})", kCamera, "")),
                HasSubstr("volume.bounds.radius[1]"));
    // 0 and the range's ends are legal: an exact, finite image
    const Image im = render_scene(parse_scene(ml_json(R"(, "origin": [0, 0, 1e-100])", kCamera, ""), ".", "s"), {1, false});
    for (double v : im.pixels) EXPECT_TRUE(std::isfinite(v));
}

// A step that would take more than 2^32 samples along the volume's diagonal is refused before any ray
// (ceil(L / h) once overflowed int64: step 1e-300 rendered the same pixels as 1e300).
TEST(ExtremeInputs, StepCountsAreBoundedUpFront) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string m = render_error(ml_json("", kCamera, R"(, "step_units": "world", "step": 1e-90)"));
    EXPECT_THAT(m, HasSubstr("render.step: a step of 1e-90 world units takes"));
    EXPECT_THAT(m, HasSubstr("at most 2^32 per ray"));
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
    // 1e100 world units: one sample per interval, an exact image
    const Image im = render_scene(parse_scene(ml_json("", kCamera, R"(, "step_units": "world", "step": 1e100)"), ".", "s"), {1, false});
    for (double v : im.pixels) EXPECT_TRUE(std::isfinite(v));
}

// Growing allocations are counted against --max-memory before they are made.
TEST(ExtremeInputs, TessellationAndTraceCountAgainstTheLimit) {
    MemoryLimitGuard guard;
    set_memory_limit(std::size_t(64) << 20);
    const std::string shell = R"(, "bounds": {"type": "cylindrical", "radius": [0, 4], "angle": [0, 360], "height": [0, 8], "tessellate": 1000000})";
    EXPECT_THAT(render_error(ml_json(shell, kCamera, "")), HasSubstr("volume.bounds.tessellate: 1000000 segments per turn"));
    const Scene s = parse_scene(ml_json("", kCamera, R"(, "step_units": "world", "step": 1e-6)"), ".", "s");
    const PreparedScene prepared(s, RenderOptions{1, false});
    const std::string m = error_of([&] { explain::trace_pixel(prepared, 4, 4); });
    EXPECT_THAT(m, HasSubstr("trace: "));
    EXPECT_THAT(m, HasSubstr("memory limit"));
}

// A ray of millions of samples stops within a poll (kCancellationPollSamples) of SIGTERM: one 8 x 8 tile
// at 1e-7 voxel (about 1.5e8 samples per ray, seconds each), the cancel requested 0.2 s into it.
TEST(ExtremeInputs, CancellationInsideOneRay) {
    const Scene s = parse_scene(ml_json("", kCamera, R"(, "step": 1e-7)"), ".", "s");
    std::chrono::steady_clock::time_point asked;
    std::thread canceller([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        asked = std::chrono::steady_clock::now();
        request_cancel(15);
    });
    EXPECT_THROW(render_scene(s, {1, false}), Cancelled);
    const auto stopped = std::chrono::steady_clock::now();
    canceller.join();
    reset_cancel();
    EXPECT_LT(std::chrono::duration<double>(stopped - asked).count(), 1.0);  // the tile loop alone: seconds
}

// Special files: refused by type (a FIFO scene once blocked, /dev/zero as an image or scene grew memory).
TEST(ExtremeInputs, SpecialFilesAreRefusedByType) {
    const fs::path dir = fs::temp_directory_path() / ("volref-extreme-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path fifo = dir / "scene.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_THAT(error_of([&] { load_scene(fifo.string()); }), HasSubstr("it is a FIFO"));
    EXPECT_THAT(error_of([&] { load_scene("/dev/zero"); }), HasSubstr("it is a character device"));
    EXPECT_THAT(error_of([&] { compare::read_compared_image("/dev/zero", std::nullopt); }), HasSubstr("it is a character device"));
    const fs::path mesh_fifo = dir / "m.obj";
    ASSERT_EQ(::mkfifo(mesh_fifo.c_str(), 0600), 0);
    EXPECT_THAT(error_of([&] { read_mesh(mesh_fifo.string()); }), HasSubstr("it is a FIFO"));
    fs::remove_all(dir);
}

// OBJ: what tinyobjloader let pass (a NaN vertex read as 0, a 20-digit index wrapped), and its mtllib (a
// material file is never opened).
TEST(ExtremeInputs, ObjVerticesAndIndicesAreChecked) {
    const fs::path dir = fs::temp_directory_path() / ("volref-obj-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    auto obj = [&](const std::string& text) {
        std::ofstream(dir / "m.obj") << text;
        return (dir / "m.obj").string();
    };
    const std::string tet = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    EXPECT_NO_THROW(read_closed_mesh(obj("mtllib /dev/zero\n" + tet)));
    EXPECT_THAT(error_of([&] { read_mesh(obj("v nan 0 0\n" + tet)); }), HasSubstr("line 1: vertex coordinate 'nan' is not a finite number"));
    EXPECT_THAT(error_of([&] { read_mesh(obj(tet + "f 1 2 99999999999999999999\n")); }),
                HasSubstr("line 9: face vertex index '99999999999999999999' is not one of the 4 vertices"));
    EXPECT_THAT(error_of([&] { read_mesh(obj(tet + "f 1 2 4294967298\n")); }), HasSubstr("line 9"));
    EXPECT_THAT(error_of([&] { read_mesh(obj(tet + std::string(1, '\0'))); }), HasSubstr("NUL byte"));
    fs::remove_all(dir);
}

// A scene file with bytes after a NUL.
TEST(ExtremeInputs, NulInAScene) {
    const std::string m = error_of([&] { parse_scene(ml_json("", kCamera, "") + std::string(1, '\0') + "  ", ".", "s.json"); });
    EXPECT_THAT(m, HasSubstr("s.json: byte "));
    EXPECT_THAT(m, HasSubstr("a NUL byte"));
}
