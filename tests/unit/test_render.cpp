// Whole renders: thread-count invariance, and the image files as written.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "TestScenes.h"
#include "core/film/ImageWriter.h"

using namespace volref;
using namespace volref::test;
namespace fs = std::filesystem;

namespace {
Scene marschner_lobb_scene() {
    FieldSpec ml;
    ml.kind = FieldSpec::Kind::MarschnerLobb;
    ml.dims = {41, 41, 41};
    Scene s = field_scene(ml);
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.5, 0.05}, {1.0, 0.5}};
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {1.0, 1.0, 0.9, 0.3}};
    s.image.width = 61;  // not a multiple of the tile size
    s.image.height = 47;
    return s;
}

fs::path temp_dir() {
    const fs::path d = fs::temp_directory_path() / ("volref-test-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}
}  // namespace

// Every pixel depends on its own ray only: 1 and 2 threads (and repeated runs) give the same bits.
TEST(Render, BitwiseIdenticalForAnyThreadCount) {
    for (auto proj : {Projection::Composite, Projection::Mip, Projection::FirstHit}) {
        Scene s = marschner_lobb_scene();
        s.render.projection = proj;
        s.render.isovalue = 0.5;
        const Image one = render_scene(s, {1, false});
        const Image two = render_scene(s, {2, false});
        const Image again = render_scene(s, {2, false});
        ASSERT_EQ(one.pixels.size(), two.pixels.size());
        EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(double)), 0);
        EXPECT_EQ(std::memcmp(one.pixels.data(), again.pixels.data(), one.pixels.size() * sizeof(double)), 0);
    }
}

// EXR keeps the float premultiplied RGBA and Z; PNG is composited over the background and stored
// with unassociated alpha, quantised by round(v * 255).
TEST(Render, WrittenFilesHoldThePixels) {
    Image im(2, 1, {"R", "G", "B", "A", "Z"});
    const double px[2][5] = {{0.25, 0.125, 0.0, 0.5, 3.5}, {0.0, 0.0, 0.0, 0.0, INFINITY}};
    for (int x = 0; x < 2; ++x)
        for (int c = 0; c < 5; ++c) im.at(x, 0, std::size_t(c)) = px[x][c];
    const fs::path dir = temp_dir();
    const glm::dvec4 bg(0.0, 0.0, 1.0, 0.5);
    write_image(im, dir / "a.exr", bg);
    write_image(im, dir / "a.png", bg);

    auto in = OIIO::ImageInput::open((dir / "a.exr").string());
    ASSERT_TRUE(in);
    ASSERT_EQ(in->spec().nchannels, 5);
    std::vector<float> f(10);
    ASSERT_TRUE(in->read_image(0, 0, 0, 5, OIIO::TypeDesc::FLOAT, f.data()));
    const auto& names = in->spec().channelnames;
    for (int c = 0; c < 5; ++c) {
        const auto it = std::find(names.begin(), names.end(), im.channels[std::size_t(c)]);
        ASSERT_NE(it, names.end());
        EXPECT_EQ(double(f[std::size_t(it - names.begin())]), px[0][c]);
    }
    in->close();

    auto png = OIIO::ImageInput::open((dir / "a.png").string());
    ASSERT_TRUE(png);
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    png->close();
    png = OIIO::ImageInput::open((dir / "a.png").string(), &config);
    std::vector<unsigned char> b(8);
    ASSERT_TRUE(png->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, b.data()));
    // Pixel 0: A' = 0.5 + 0.5 * 0.5 = 0.75; C' = (0.25, 0.125, 0 + 0.5 * 0.5 * 1) / 0.75.
    EXPECT_EQ(b[0], std::lround(0.25 / 0.75 * 255));
    EXPECT_EQ(b[1], std::lround(0.125 / 0.75 * 255));
    EXPECT_EQ(b[2], std::lround(0.25 / 0.75 * 255));
    EXPECT_EQ(b[3], std::lround(0.75 * 255));
    // Pixel 1 is the background: (0, 0, 1) at alpha 0.5.
    EXPECT_EQ(b[4], 0);
    EXPECT_EQ(b[6], 255);
    EXPECT_EQ(b[7], std::lround(0.5 * 255));
    // No temporary file is left behind.
    int files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 2);
    fs::remove_all(dir);
}
