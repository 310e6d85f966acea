// Real reference data (fetched from Debian's packages by scripts/fetch-reference-data.sh into
// reference_scenes/data/real/): each file read and checked against its own bytes, and each real
// reference scene rendered at 48 x 48 and compared with its golden EXR in tests/golden/.
//
// Golden tolerance (per pixel and channel R, G, B, A): the test renders the scene at its own step h
// and at h/2; the rendering at h must match the golden within
//     4 * |I(h) - I(h/2)| + 1e-9 + 2^-23 * |golden|
// i.e. four times the step-doubling estimate of the discretisation error at that pixel (a change of
// the renderer smaller than its own discretisation error passes; anything else fails), plus 1e-9,
// plus the rounding of the golden to the EXR's 32-bit floats. Regenerate the goldens (after a change
// that is meant to change them) with scripts/make-golden-images.sh.
//
// The tests skip (GTEST_SKIP) only when a data file is missing; scripts/setup.sh and scripts/test.sh
// (and so CI) fetch the data first.
#include <zlib.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "core/io/VolumeReader.h"
#include "core/render/Renderer.h"
#include "core/scene/SceneLoader.h"

namespace {

namespace fs = std::filesystem;

const fs::path kSource = VOLREF_SOURCE_DIR;
const fs::path kData = kSource / "reference_scenes" / "data" / "real";

std::string file_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A gzip file's decompressed bytes, through zlib's gz* interface (independent of volref's inflate).
std::string gunzip(const fs::path& p) {
    gzFile f = gzopen(p.c_str(), "rb");
    EXPECT_NE(f, nullptr);
    std::string out;
    char buf[1 << 16];
    int n = 0;
    while ((n = gzread(f, buf, sizeof buf)) > 0) out.append(buf, std::size_t(n));
    gzclose(f);
    return out;
}

#define REQUIRE_DATA(name)                                                                              \
    if (!fs::exists(kData / (name)))                                                                   \
    GTEST_SKIP() << (kData / (name)).string()                                                         \
                 << " is missing: run scripts/fetch-reference-data.sh (scripts/setup.sh and scripts/test.sh do)"

std::string num(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

// The reference scene NAME rendered at 48 x 48 (step h) against tests/golden/NAME.exr, within the
// tolerance stated at the top of this file.
void check_golden(const std::string& name) {
    const fs::path scene_path = kSource / "reference_scenes" / (name + ".json");
    const std::vector<std::string> size{"image.width=48", "image.height=48"};
    const volref::Scene scene = volref::load_scene(scene_path, size);
    std::vector<std::string> half = size;
    half.push_back("render.step=" + num(scene.render.step / 2));
    const volref::Image fine = volref::render_scene(volref::load_scene(scene_path, half));
    const volref::Image image = volref::render_scene(scene);

    const fs::path golden_path = kSource / "tests" / "golden" / (name + ".exr");
    auto in = OIIO::ImageInput::open(golden_path.string());
    ASSERT_TRUE(in) << golden_path << ": " << OIIO::geterror()
                    << " (regenerate with scripts/make-golden-images.sh)";
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.width, 48);
    ASSERT_EQ(spec.height, 48);
    ASSERT_GE(spec.nchannels, 4);
    std::vector<float> golden(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, golden.data()));
    in->close();
    ASSERT_EQ(spec.channelnames[0], "R");
    ASSERT_EQ(spec.channelnames[3], "A");

    int failures = 0;
    double worst = 0.0, visible = 0.0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x)
            for (std::size_t c = 0; c < 4; ++c) {
                const double g = golden[(std::size_t(y) * 48 + std::size_t(x)) * std::size_t(spec.nchannels) + c];
                const double v = image.at(x, y, c);
                const double tol = 4.0 * std::fabs(v - fine.at(x, y, c)) + 1e-9 + std::ldexp(std::fabs(g), -23);
                worst = std::max(worst, std::fabs(v - g));
                if (c == 3) visible += g;
                if (!(std::fabs(v - g) <= tol) && ++failures <= 5)
                    ADD_FAILURE() << name << ": pixel (" << x << ", " << y << ") channel " << c << ": " << v
                                  << " vs golden " << g << " (tolerance " << tol << ")";
            }
    EXPECT_EQ(failures, 0) << name << ": " << failures << " values outside the tolerance (largest difference " << worst
                           << ")";
    // The golden is not an empty image: the volume covers a good part of the 48 x 48 pixels.
    EXPECT_GT(visible, 48.0 * 48.0 * 0.1) << name;
}

}  // namespace

// ch2.nii.gz: the NIfTI reader against the file's own bytes (u8 after the 352-byte header; sform identity
// placing voxel (0,0,0) at (-90, -125, -71)).
TEST(RealData, Ch2NiftiMatchesItsBytes) {
    REQUIRE_DATA("ch2.nii.gz");
    const volref::Volume v = volref::read_volume(kData / "ch2.nii.gz");
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{181, 217, 181}));
    EXPECT_EQ(v.type, volref::ScalarType::U8);
    EXPECT_EQ(v.spacing, glm::dvec3(1.0, 1.0, 1.0));
    EXPECT_EQ(v.origin, glm::dvec3(-90.0, -125.0, -71.0));
    const std::string bytes = gunzip(kData / "ch2.nii.gz");
    ASSERT_EQ(bytes.size(), 352u + 181u * 217u * 181u);
    for (const auto& [i, j, k] : std::vector<std::array<int, 3>>{{0, 0, 0}, {90, 125, 71}, {100, 150, 120}, {180, 216, 180}, {45, 60, 90}})
        EXPECT_EQ(v.at(i, j, k), double(static_cast<unsigned char>(bytes[352 + std::size_t(i + 181 * (j + 217 * k))])))
            << i << "," << j << "," << k;
}

// brainsmall.den: 62-byte header (little endian here: map_version bytes 01 00), then u8 samples.
TEST(RealData, BrainsmallDenMatchesItsBytes) {
    REQUIRE_DATA("brainsmall.den");
    const volref::Volume v = volref::read_volume(kData / "brainsmall.den");
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{128, 128, 84}));
    EXPECT_EQ(v.type, volref::ScalarType::U8);
    const std::string bytes = file_bytes(kData / "brainsmall.den");
    ASSERT_EQ(bytes.size(), 62u + 128u * 128u * 84u);
    for (const auto& [i, j, k] : std::vector<std::array<int, 3>>{{0, 0, 0}, {64, 64, 42}, {127, 127, 83}, {30, 90, 10}})
        EXPECT_EQ(v.at(i, j, k), double(static_cast<unsigned char>(bytes[62 + std::size_t(i + 128 * (j + 128 * k))])));
}

// heart.vtk (legacy ASCII) and heart.vti (XML, ascii DataArray) hold the same scan: two readers agree,
// and the first samples are those printed at the top of heart.vtk's data (16 15 16 18 14).
TEST(RealData, HeartVtkAndVtiAgree) {
    REQUIRE_DATA("heart.vtk");
    REQUIRE_DATA("heart.vti");
    const volref::Volume a = volref::read_volume(kData / "heart.vtk");
    const volref::Volume b = volref::read_volume(kData / "heart.vti");
    EXPECT_EQ(a.dims, (std::array<std::int64_t, 3>{32, 32, 12}));
    EXPECT_EQ(a.spacing, glm::dvec3(1.0, 1.0, 4.0));
    EXPECT_EQ(a.origin, glm::dvec3(0.0));
    EXPECT_EQ(a.type, volref::ScalarType::F32);
    EXPECT_EQ(b.dims, a.dims);
    EXPECT_EQ(b.spacing, a.spacing);
    EXPECT_EQ(b.origin, a.origin);
    EXPECT_EQ(b.values, a.values);
    EXPECT_EQ(a.at(0, 0, 0), 16.0);
    EXPECT_EQ(a.at(1, 0, 0), 15.0);
    EXPECT_EQ(a.at(3, 0, 0), 18.0);
    EXPECT_EQ(a.at(4, 0, 0), 14.0);
}

TEST(RealData, MriHeadMatchesGolden) {
    REQUIRE_DATA("ch2.nii.gz");
    check_golden("mri-head");
}

TEST(RealData, CtHeartMatchesGolden) {
    REQUIRE_DATA("heart.vtk");
    check_golden("ct-heart");
}

TEST(RealData, MriBrainVolpackMatchesGolden) {
    REQUIRE_DATA("brainsmall.den");
    check_golden("mri-brain-volpack");
}
