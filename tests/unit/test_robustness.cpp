// Limits, faults and determinism (docs/robustness.md): the memory limit refuses work before
// allocating, SIGINT/SIGTERM leave no output, concurrent writers never mix a file, a read-only output
// folder is an error before rendering, and images do not depend on threads, tiles or runs.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <OpenImageIO/imageio.h>

#include "TestScenes.h"
#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/MemoryLimit.h"
#include "core/render/PreparedScene.h"
#include "core/render/Renderer.h"
#include "core/sample/MacrocellGrid.h"
#include "geometry/TriangleMesh.h"

namespace fs = std::filesystem;
using namespace volref;
using namespace volref::test;

namespace {

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// Restores the process-wide memory limit after a test.
struct MemoryLimitGuard {
    std::size_t saved = memory_limit();
    ~MemoryLimitGuard() { set_memory_limit(saved); }
};

class Robustness : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("volref-robust-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path write(const std::string& name, const std::string& text) const {
        std::ofstream(dir_ / name) << text;
        return dir_ / name;
    }
    // Starts `volref ARGS...` with stderr to dir_/stderr-N.txt; returns its pid.
    pid_t spawn(const std::vector<std::string>& args, int n = 0) const {
        const std::string err = (dir_ / ("stderr-" + std::to_string(n) + ".txt")).string();
        const pid_t pid = ::fork();
        if (pid == 0) {
            std::vector<char*> argv{const_cast<char*>(VOLREF_CLI)};
            for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
            argv.push_back(nullptr);
            std::freopen(err.c_str(), "w", stderr);
            std::freopen("/dev/null", "w", stdout);
            ::execv(VOLREF_CLI, argv.data());
            ::_exit(127);
        }
        return pid;
    }
    std::string stderr_of(int n = 0) const {
        std::ifstream in(dir_ / ("stderr-" + std::to_string(n) + ".txt"));
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    }
    // Exit status of pid (-signal if it was killed by one).
    static int wait_for(pid_t pid) {
        int raw = 0;
        ::waitpid(pid, &raw, 0);
        return WIFEXITED(raw) ? WEXITSTATUS(raw) : -WTERMSIG(raw);
    }
    int run(const std::vector<std::string>& args) const { return wait_for(spawn(args)); }
    bool has_temporary_files() const {
        for (const auto& e : fs::directory_iterator(dir_))
            if (e.path().filename().string().find(".volref-tmp") != std::string::npos) return true;
        return false;
    }
    fs::path dir_;
};

// A render of several seconds: 64^3 Marschner-Lobb, 1024^2 pixels, step 0.05 voxel, shaded.
const std::string kSlowScene = R"({
  "volume": { "source": { "field": "marschner-lobb", "dims": [64, 64, 64] },
              "transfer": { "opacity": [[0, 0.01], [1, 0.02]] },
              "shading": { "model": "blinn-phong" } },
  "image": { "width": 1024, "height": 1024 },
  "render": { "step": 0.05 }
})";

const std::string kSmallScene = R"({
  "volume": { "source": { "field": "gaussian", "dims": [9, 9, 9], "center": [4, 4, 4], "sigma": 2 },
              "transfer": { "opacity": [[0, 0], [1, 0.5]] } },
  "image": { "width": 8, "height": 8 }
})";

Scene ml_scene() {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {21, 19, 23};
    Scene s = field_scene(ml);
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.4, 0.0}, {0.6, 0.5}, {1.0, 0.9}};
    s.volume().transfer.color = {{0.0, 1.0, 0.2, 0.1}, {1.0, 0.1, 0.5, 1.0}};
    s.image.width = 37;
    s.image.height = 29;
    return s;
}

bool bitwise_equal(const Image& a, const Image& b) {
    return a.pixels.size() == b.pixels.size() &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(double)) == 0;
}

}  // namespace

TEST(MemoryLimit, ParsesSizes) {
    EXPECT_EQ(parse_memory_size("4096", "x"), 4096u);
    EXPECT_EQ(parse_memory_size("512M", "x"), 512u << 20);
    EXPECT_EQ(parse_memory_size("4g", "x"), std::size_t(4) << 30);
    EXPECT_EQ(parse_memory_size("1.5GiB", "x"), std::size_t(3) << 29);
    EXPECT_EQ(parse_memory_size("2 KB", "x"), 2048u);
    for (const char* bad : {"", "0", "-1G", "G", "4X", "1e3", "nan"})
        EXPECT_NE(error_of([&] { parse_memory_size(bad, "--max-memory"); }).find("--max-memory"), std::string::npos)
            << bad;
}

// A volume over the limit is refused by the same check that guards every reader (checked_voxel_count),
// naming what needed the memory.
TEST(MemoryLimit, RefusesAVolumeBeforeAllocating) {
    MemoryLimitGuard guard;
    set_memory_limit(1 << 20);  // 1 MiB: 64^3 doubles need 2 MiB
    Scene s = ml_scene();
    s.volume().source.field->dims = {64, 64, 64};
    const std::string e = error_of([&] { render_scene(s); });
    EXPECT_NE(e.find("64 x 64 x 64"), std::string::npos) << e;
    EXPECT_NE(e.find("memory limit of 1 MiB"), std::string::npos) << e;
    set_memory_limit(std::size_t(1) << 30);
    EXPECT_NO_THROW(render_scene(s));
}

TEST(MemoryLimit, RefusesAnImageAndAGradientCache) {
    MemoryLimitGuard guard;
    Scene s = ml_scene();  // 21 x 19 x 23 doubles = 73416 bytes
    s.image.width = s.image.height = 1000;  // 1e6 pixels x 6 channels x 8 bytes = 48e6 bytes
    set_memory_limit(40'000'000);
    EXPECT_NE(error_of([&] { render_scene(s); }).find("image: 1000 x 1000"), std::string::npos);
    s.image.width = s.image.height = 8;
    s.volume().shading = ShadingSpec{};
    s.volume().gradient.cache = true;  // 3 more volumes: 4 x 73416 + image > 200000
    set_memory_limit(200'000);
    EXPECT_NE(error_of([&] { render_scene(s); }).find("volume.gradient.cache"), std::string::npos);
    set_memory_limit(400'000);
    EXPECT_NO_THROW(render_scene(s));
}

// The macrocell grid of empty-space skipping is counted before it is built: 21 x 19 x 23 voxels are
// 20 x 18 x 22 cells, ceil(/ 8) = 3 x 3 x 3 = 27 macrocells of 16 (range) + 2 (flag, radius) + 9 (the
// construction's distance field) + 32 (the composite packets' 8 radii) = 59 bytes: 1593 bytes.
TEST(MemoryLimit, CountsTheMacrocellGrid) {
    MemoryLimitGuard guard;
    const std::int64_t dims[3] = {21, 19, 23};
    EXPECT_EQ(MacrocellGrid::bytes_for(dims, true), 27u * 59u);
    EXPECT_EQ(MacrocellGrid::bytes_for(dims, false), 27u * 27u);
    Scene s = ml_scene();
    s.image.width = s.image.height = 8;
    const std::size_t volume = 21 * 19 * 23 * sizeof(double), image = 8 * 8 * 6 * sizeof(double), grid = 27 * 59;
    set_memory_limit(volume + image + grid - 1);
    const std::string e = error_of([&] { render_scene(s); });
    EXPECT_NE(e.find("volume: the macrocell grid of empty-space skipping"), std::string::npos) << e;
    set_memory_limit(volume + image + grid);
    EXPECT_NO_THROW(render_scene(s));
    // Without skipping no grid is built, so nothing is asked for it.
    set_memory_limit(volume + image + grid - 1);
    EXPECT_NO_THROW(render_scene(s, {.empty_space_skipping = false}));
}

TEST_F(Robustness, MaxMemoryOnTheCommandLine) {
    const fs::path scene = write("s.json", kSmallScene), out = dir_ / "o.png";
    // 9^3 doubles = 5832 bytes > 4 KiB
    EXPECT_EQ(run({"render", scene.string(), "-o", out.string(), "--max-memory", "4K"}), 1);
    EXPECT_NE(stderr_of().find("memory limit of 4 KiB (--max-memory)"), std::string::npos) << stderr_of();
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(run({"--max-memory", "lots", "render", scene.string(), "-o", out.string()}), 1);
    EXPECT_EQ(stderr_of().rfind("volref: error: --max-memory", 0), 0u) << stderr_of();
    EXPECT_EQ(run({"render", scene.string(), "-o", out.string(), "--max-memory", "64M"}), 0) << stderr_of();
    EXPECT_TRUE(fs::exists(out));
}

// The library: a requested cancel stops render_scene with Cancelled.
TEST(Cancellation, StopsARender) {
    request_cancel(SIGINT);
    Scene s = ml_scene();
    try {
        render_scene(s);
        ADD_FAILURE() << "no Cancelled";
    } catch (const Cancelled& c) {
        EXPECT_EQ(c.signal(), SIGINT);
        EXPECT_NE(std::string(c.what()).find("SIGINT"), std::string::npos);
    }
    reset_cancel();
    EXPECT_NO_THROW(render_scene(s));
}

// SIGINT and SIGTERM during a render: exit status 128 + signal, one line on stderr, no output file
// and no temporary file. The signal is sent 0.7 s after the start; on a loaded machine the process may
// not have installed its handlers by then (it dies of the signal, status -sig, before rendering):
// that start is retried with 2 s and then 5 s.
TEST_F(Robustness, SignalsLeaveNoOutput) {
    const fs::path scene = write("slow.json", kSlowScene);
    for (int sig : {SIGINT, SIGTERM}) {
        const fs::path out = dir_ / ("o" + std::to_string(sig) + ".exr");
        int status = 0;
        double seconds = 0.0;
        for (const int delay_ms : {700, 2000, 5000}) {
            const auto start = std::chrono::steady_clock::now();
            const pid_t pid = spawn({"render", scene.string(), "-o", out.string(), "--threads", "2"});
            std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
            ::kill(pid, sig);
            status = wait_for(pid);
            seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - delay_ms / 1000.0;
            if (status != -sig) break;  // the handlers were installed: this is the case under test
        }
        EXPECT_EQ(status, 128 + sig) << stderr_of();
        EXPECT_NE(stderr_of().find(sig == SIGINT ? "interrupted by SIGINT; no output written"
                                                 : "interrupted by SIGTERM; no output written"),
                  std::string::npos)
            << stderr_of();
        EXPECT_FALSE(fs::exists(out));
        EXPECT_FALSE(has_temporary_files());
        EXPECT_LT(seconds, 4.3);  // after the signal: it stopped at the next tile, not at the end of the render
    }
}

// Two renders writing the same path at once: the file is always one of the two whole images
// (each writes a temporary file named by its pid and renames it into place).
TEST_F(Robustness, ConcurrentWritersNeverMixAFile) {
    const std::string red = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]},
      "transfer": {"color": [[0, 1, 0, 0]], "opacity": [[0, 1]]}}, "image": {"width": 300, "height": 300}})";
    const std::string blue = R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [4, 4, 4]},
      "transfer": {"color": [[0, 0, 0, 1]], "opacity": [[0, 1]]}}, "image": {"width": 300, "height": 300}})";
    const fs::path a = write("a.json", red), b = write("b.json", blue);
    const fs::path ref_a = dir_ / "ref-a.png", ref_b = dir_ / "ref-b.png", out = dir_ / "same.png";
    ASSERT_EQ(run({"render", a.string(), "-o", ref_a.string()}), 0);
    ASSERT_EQ(run({"render", b.string(), "-o", ref_b.string()}), 0);
    // The decoded pixels (a file may carry metadata that differs between runs).
    auto bytes = [](const fs::path& p) {
        auto in = OIIO::ImageInput::open(p.string());
        if (!in) return std::string("unreadable");
        std::string pixels(std::size_t(in->spec().image_bytes()), '\0');
        in->read_image(0, 0, 0, -1, OIIO::TypeDesc::UINT8, pixels.data());
        return pixels;
    };
    const std::string A = bytes(ref_a), B = bytes(ref_b);
    ASSERT_NE(A, B);
    for (int round = 0; round < 3; ++round) {
        const pid_t p1 = spawn({"render", a.string(), "-o", out.string()}, 1);
        const pid_t p2 = spawn({"render", b.string(), "-o", out.string()}, 2);
        EXPECT_EQ(wait_for(p1), 0) << stderr_of(1);
        EXPECT_EQ(wait_for(p2), 0) << stderr_of(2);
        const std::string got = bytes(out);
        EXPECT_TRUE(got == A || got == B) << "round " << round;
        EXPECT_FALSE(has_temporary_files());
    }
}

// An output folder that cannot be written (here /proc, where even root cannot create files) is an
// error before rendering: the slow scene would otherwise take seconds.
TEST_F(Robustness, UnwritableOutputFolderFailsBeforeRendering) {
    const fs::path scene = write("slow.json", kSlowScene);
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(run({"render", scene.string(), "-o", "/proc/volref-test.exr"}), 1);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(stderr_of().find("/proc/volref-test.exr: the output folder /proc is not writable"), std::string::npos)
        << stderr_of();
    EXPECT_LT(seconds, 3.0);  // the render itself takes tens of seconds
}

// Every pixel is computed from its own ray alone: the image is bitwise the same for any thread
// count, tile size and run, on the SIMD path and on the scalar path.
TEST(Determinism, ThreadsTilesAndRuns) {
    std::vector<Scene> scenes;
    scenes.push_back(ml_scene());
    Scene shaded = ml_scene();
    shaded.volume().shading = ShadingSpec{};
    scenes.push_back(shaded);
    Scene mip = ml_scene();
    mip.render.projection = Projection::Mip;
    scenes.push_back(mip);
    Scene hit = ml_scene();
    hit.render.projection = Projection::FirstHit;
    hit.render.isovalue = 0.5;
    scenes.push_back(hit);
    Scene btf = shaded;
    btf.render.order = CompositeOrder::BackToFront;
    scenes.push_back(btf);
    for (const Scene& s : scenes)
        for (bool simd : {true, false}) {
            const Image first = render_scene(s, {.threads = 1, .simd = simd});
            for (int threads : {1, 2})
                for (int tile : {1, 5, 16, 64}) {
                    const Image im = render_scene(s, {.threads = threads, .simd = simd, .tile_size = tile});
                    EXPECT_TRUE(bitwise_equal(im, first)) << "threads " << threads << " tile " << tile << " simd " << simd;
                }
        }
}

// The film (Renderer.cpp, write_tile: a tile's pixels, then its rows into the image by streaming stores where
// a row starts on 16 bytes, else copied): every pixel's channels land where its own ray's value is. Checked
// against PreparedScene::render_pixel (one ray, the scalar path) on the scalar path's image, with 4 channels
// (R G B A: the streaming rows) and 5 (first-hit Z, on an odd width: rows off 16 bytes, copied), at tile
// sides whose rows end mid-line (1, 5) and the default.
TEST(Film, TilesWriteEachPixelWhereItsRayIs) {
    Scene composite = ml_scene();
    Scene hit = ml_scene();
    hit.render.projection = Projection::FirstHit;
    hit.render.isovalue = 0.5;
    for (const Scene& s : {composite, hit}) {
        const PreparedScene prepared(s, {.threads = 1});
        for (int tile : {0, 1, 5}) {
            const Image im = render_scene(s, {.threads = 2, .simd = false, .tile_size = tile});
            const std::size_t C = im.channel_count();
            ASSERT_EQ(C, s.render.projection == Projection::FirstHit ? 5u : 4u);
            int lit = 0;
            for (int y = 0; y < im.height; ++y)
                for (int x = 0; x < im.width; ++x) {
                    const PixelValue v = prepared.render_pixel(x, y);
                    for (int c = 0; c < 4; ++c) ASSERT_EQ(im.at(x, y, std::size_t(c)), v.rgba[c]) << x << " " << y << " tile " << tile;
                    if (C == 5) ASSERT_EQ(im.at(x, y, 4), v.depth) << x << " " << y;
                    lit += v.rgba[3] > 0.0;
                }
            EXPECT_GT(lit, im.width * im.height / 8);  // (255 of 1,073 lit here)
        }
    }
}

// tile_side (Renderer.h; conventions::kTilesPerThread) by hand: 32 unless the image has fewer than 16
// tiles per thread, then halved down to 4.
TEST(Tiles, SideByHand) {
    EXPECT_EQ(tile_side(512, 512, 2), 32);   // 256 tiles >= 32
    EXPECT_EQ(tile_side(512, 512, 16), 32);  // 256 >= 256
    EXPECT_EQ(tile_side(512, 512, 17), 16);  // 256 < 272; 1024 of 16
    EXPECT_EQ(tile_side(128, 128, 2), 16);   // 16 < 32; 64 of 16
    EXPECT_EQ(tile_side(128, 128, 16), 8);   // 64 < 256; 256 of 8
    EXPECT_EQ(tile_side(128, 128, 32), 4);   // 256 < 512; 1024 of 4
    EXPECT_EQ(tile_side(48, 48, 2), 8);      // 4, 9 < 32; 36 of 8
    EXPECT_EQ(tile_side(1, 1, 1), 4);        // never below a packet block
    EXPECT_EQ(tile_side(100, 3, 0), 4);      // threads 0 counts as 1: 4 tiles of 32, 7 of 16 < 16
}

// Fuzzing found PLY files on which assimp aborted, looped forever or allocated gigabytes; volref's
// own PLY reader reports each as a one-line error naming the file (docs/robustness.md, findings).
TEST(FuzzRegressions, PlyFilesThatBrokeAssimpAreErrors) {
    const std::string dir = std::string(VOLREF_SOURCE_DIR) + "/tests/fuzz/regressions/fuzz_ply/";
    for (const char* name : {"assimp-triangulate-abort.ply", "assimp-hang-list-in-vertex.ply", "assimp-leak-on-error.ply",
                             "assimp-oom-huge-list.ply", "ub-list-count-beyond-2-64.ply"}) {
        const std::string e = error_of([&] { read_closed_mesh(dir + name); });
        EXPECT_NE(e.find(name), std::string::npos) << name << ": " << e;
    }
}

// The PLY reader on hand-written files: ASCII with a quad (fanned) and a big-endian binary cube whose
// double coordinates are kept exactly.
TEST(FuzzRegressions, PlyReaderReadsAsciiAndBinary) {
    const fs::path dir = fs::temp_directory_path() / ("volref-ply-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const glm::dvec3 v[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    std::ostringstream ascii;
    ascii << "ply\nformat ascii 1.0\ncomment quads\nelement vertex 8\nproperty double x\nproperty double y\n"
             "property double z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto& p : v) ascii << p.x << " " << p.y << " " << p.z << "\n";
    for (const auto& q : quads) ascii << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << "\n";
    std::ofstream(dir / "a.ply") << ascii.str();
    const TriangleMesh a = read_closed_mesh((dir / "a.ply").string());
    EXPECT_EQ(a.vertices.size(), 8u);
    EXPECT_EQ(a.triangles.size(), 12u);  // 6 quads, 2 triangles each
    EXPECT_NEAR(signed_volume(a), 1.0, 1e-15);

    // Binary big-endian: x y z as doubles (0.1 is kept exactly), faces as uchar count + uint indices.
    std::string bin = "ply\nformat binary_big_endian 1.0\nelement vertex 8\nproperty double x\nproperty double y\n"
                      "property double z\nelement face 6\nproperty list uchar uint vertex_indices\nend_header\n";
    auto put_be = [&bin](const void* p, int n) {
        const unsigned char* b = static_cast<const unsigned char*>(p);
        for (int i = n - 1; i >= 0; --i) bin.push_back(char(b[i]));
    };
    for (const auto& p : v)
        for (int c = 0; c < 3; ++c) {
            const double x = p[c] * 0.1;
            put_be(&x, 8);
        }
    for (const auto& q : quads) {
        bin.push_back(char(4));
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t i = std::uint32_t(q[k]);
            put_be(&i, 4);
        }
    }
    std::ofstream(dir / "b.ply", std::ios::binary) << bin;
    const TriangleMesh b = read_closed_mesh((dir / "b.ply").string());
    EXPECT_NEAR(signed_volume(b), 0.001, 1e-18);
    bool has_tenth = false;
    for (const auto& p : b.vertices) has_tenth = has_tenth || (p.x == 0.1 && p.y == 0.1 && p.z == 0.1);
    EXPECT_TRUE(has_tenth);
    // Truncated data and a count the file cannot hold are errors naming the file.
    std::ofstream(dir / "c.ply", std::ios::binary) << bin.substr(0, bin.size() - 7);
    EXPECT_NE(error_of([&] { read_closed_mesh((dir / "c.ply").string()); }).find("c.ply: the PLY data end inside face 5"),
              std::string::npos);
    fs::remove_all(dir);
}
