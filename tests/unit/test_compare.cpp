// volref compare: metrics, tolerances, the heat map and --fit against hand-made image pairs whose
// numbers are computed by hand (closed forms) in the test; the command's exit statuses and errors.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>

#include "core/compare/ComparedImage.h"
#include "core/compare/Fits.h"
#include "core/compare/ImageMetrics.h"
#include "core/compare/Tolerance.h"

namespace fs = std::filesystem;
using namespace volref;
using namespace volref::compare;

namespace {

// A w x h RGBA image whose every value is f(x, y, c).
template <typename F>
Image make_image(int w, int h, F f) {
    Image im(w, h, {"R", "G", "B", "A"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (std::size_t c = 0; c < 4; ++c) im.at(x, y, c) = f(x, y, int(c));
    return im;
}

// Writes float channels (interleaved) as EXR; the first four are R, G, B, A.
void write_exr(const fs::path& path, int w, int h, const std::vector<std::string>& names, const std::vector<float>& v) {
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(w, h, int(names.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.alpha_channel = 3;
    ASSERT_TRUE(out->open(path.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, v.data()));
    out->close();
}

// Writes 8-bit RGBA bytes as a PNG with unassociated alpha (as volref writes PNG).
void write_png(const fs::path& path, int w, int h, const std::vector<std::uint8_t>& v) {
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::UINT8);
    spec.alpha_channel = 3;
    spec.attribute("oiio:UnassociatedAlpha", 1);
    ASSERT_TRUE(out->open(path.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, v.data()));
    out->close();
}

std::vector<float> to_floats(const Image& im) { return std::vector<float>(im.pixels.begin(), im.pixels.end()); }

struct CmdResult {
    int status;
    std::string out, err;
};

class CompareCli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("volref-compare-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    CmdResult run(const std::string& args) const {
        const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
        const std::string cmd =
            std::string(VOLREF_CLI) + " compare " + args + " > " + out.string() + " 2> " + err.string();
        const int raw = std::system(cmd.c_str());
        auto slurp = [](const fs::path& p) {
            std::ifstream in(p);
            std::stringstream ss;
            ss << in.rdbuf();
            return ss.str();
        };
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
    }
    std::string p(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

// A smooth, non-trivial test image in [0.1, 0.9]: channel c is a different mix of sines.
double smooth(double x, double y, int c) {
    return 0.5 + 0.2 * std::sin(0.31 * x + 0.7 * c) * std::cos(0.23 * y - 0.4 * c) + 0.15 * std::sin(0.11 * (x + y));
}

}  // namespace

// ---- metrics --------------------------------------------------------------------------------------

// A constant offset d = 0.01: max abs = mean abs = RMSE = 0.01, PSNR = 10 log10(1 / 1e-4) = 40 dB; SSIM of
// constant images a = 0.5, b = 0.51 (sigma = 0): (2 a b + C1) / (a^2 + b^2 + C1), C1 = 1e-4.
TEST(CompareMetrics, ConstantOffset) {
    const Image a = make_image(16, 16, [](int, int, int) { return 0.5; });
    const Image b = make_image(16, 16, [](int, int, int) { return 0.51; });
    const ImageMetrics m = measure_difference(a, b);
    const double ssim_expected = (2 * 0.5 * 0.51 + 1e-4) / (0.25 + 0.51 * 0.51 + 1e-4);  // 0.999804...
    for (const ChannelMetrics& c : m.channels) {
        EXPECT_NEAR(c.max_abs, 0.01, 1e-15);
        EXPECT_NEAR(c.mean_abs, 0.01, 1e-15);
        EXPECT_NEAR(c.rmse, 0.01, 1e-15);
        EXPECT_NEAR(c.psnr, 40.0, 1e-11);
        ASSERT_TRUE(c.ssim);
        EXPECT_NEAR(*c.ssim, ssim_expected, 1e-12);
    }
    EXPECT_NEAR(m.overall.rmse, 0.01, 1e-15);
    EXPECT_NEAR(m.overall.psnr, 40.0, 1e-11);
    EXPECT_NEAR(*m.overall.ssim, ssim_expected, 1e-12);
    EXPECT_EQ(m.overall.over, 256);  // tolerance 0
    EXPECT_TRUE(std::isinf(measure_difference(a, a).overall.psnr));
}

// Mixed differences in one channel: |d| = 0.1 on 1 pixel, 0.02 on 3 pixels, 0 elsewhere (4x4 = 16 pixels):
// max 0.1, mean (0.1 + 0.06) / 16 = 0.01, RMSE sqrt((0.01 + 3 * 4e-4) / 16) = sqrt(7e-4).
TEST(CompareMetrics, MixedDifferencesAndToleranceCounts) {
    const Image a = make_image(4, 4, [](int, int, int) { return 0.25; });
    Image b = a;
    b.at(0, 0, 1) += 0.1;
    b.at(1, 0, 1) -= 0.02;
    b.at(2, 3, 1) += 0.02;
    b.at(3, 3, 1) += 0.02;
    b.at(3, 3, 2) += 0.005;  // a second channel of an already counted pixel
    const std::vector<double> tol(16 * 4, 0.01);
    const ImageMetrics m = measure_difference(a, b, tol);
    const ChannelMetrics& g = m.channels[1];
    EXPECT_NEAR(g.max_abs, 0.1, 1e-15);
    EXPECT_NEAR(g.mean_abs, 0.01, 1e-15);
    EXPECT_NEAR(g.rmse, std::sqrt(7e-4), 1e-15);
    EXPECT_EQ(g.over, 4);
    EXPECT_EQ(m.channels[2].over, 0);  // 0.005 <= 0.01
    EXPECT_EQ(m.overall.over, 4);
    EXPECT_DOUBLE_EQ(m.fraction_over(), 4.0 / 16.0);
    EXPECT_FALSE(g.ssim);  // 4x4 is smaller than the 11x11 window
}

// SSIM on a ramp a(x, y) = s x and b = g a. Under a symmetric window every position has mu_a = s xc,
// sigma_a^2 = s^2 V (V = the window's variance along x), so
//   SSIM = (2 g mu^2 + C1)(2 g s^2 V + C2) / ((1 + g^2) mu^2 + C1)((1 + g^2) s^2 V + C2), averaged over xc.
// V is computed here from the Gaussian's definition (sigma 1.5, taps -5..5).
TEST(CompareMetrics, SsimOfAGainOnARampMatchesTheClosedForm) {
    const int w = 16, h = 14;
    const double s = 0.05, gain = 0.8;
    const Image a = make_image(w, h, [&](int x, int, int) { return s * x; });
    const Image b = make_image(w, h, [&](int x, int, int) { return gain * s * x; });
    double sum = 0.0, m2 = 0.0;
    for (int k = -5; k <= 5; ++k) {
        const double wk = std::exp(-k * k / (2 * 1.5 * 1.5));
        sum += wk;
        m2 += wk * k * k;
    }
    const double V = m2 / sum;
    const double c1 = 1e-4, c2 = 9e-4;
    double expected = 0.0;
    for (int xc = 5; xc <= w - 6; ++xc) {  // "valid" centres; all rows alike
        const double mu = s * xc, var = s * s * V;
        expected += (2 * gain * mu * mu + c1) * (2 * gain * var + c2) /
                    (((1 + gain * gain) * mu * mu + c1) * ((1 + gain * gain) * var + c2));
    }
    expected /= double(w - 10);
    const ImageMetrics m = measure_difference(a, b);
    ASSERT_TRUE(m.channels[0].ssim);
    EXPECT_NEAR(*m.channels[0].ssim, expected, 1e-12);
    EXPECT_LT(expected, 0.99);  // the test distinguishes windows: not a trivial 1
}

// ---- reading and tolerance ------------------------------------------------------------------------------

// An 8-bit PNG with unassociated alpha becomes premultiplied: R = (200/255)(100/255). An EXR is taken as
// premultiplied; --background composites it: C' = C + (1 - A) bg_a bg_rgb, A' = A + (1 - A) bg_a.
TEST_F(CompareCli, ReadsPngAsPremultipliedAndCompositesExrOverBackground) {
    write_png(dir_ / "a.png", 1, 1, {200, 50, 0, 100});
    const ComparedImage png = read_compared_image(dir_ / "a.png");
    EXPECT_EQ(png.bits, 8);
    EXPECT_TRUE(png.unassociated);
    EXPECT_NEAR(png.rgba.at(0, 0, 0), (200.0 / 255) * (100.0 / 255), 1e-15);
    EXPECT_NEAR(png.rgba.at(0, 0, 1), (50.0 / 255) * (100.0 / 255), 1e-15);
    EXPECT_NEAR(png.rgba.at(0, 0, 3), 100.0 / 255, 1e-15);

    // A grey 8-bit PNG without alpha: Y becomes R, G and B; alpha is 1; quantisation q on every channel.
    {
        auto out = OIIO::ImageOutput::create((dir_ / "y.png").string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(1, 1, 1, OIIO::TypeDesc::UINT8);
        const std::uint8_t v = 51;
        ASSERT_TRUE(out->open((dir_ / "y.png").string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, &v));
        out->close();
    }
    const ComparedImage grey = read_compared_image(dir_ / "y.png");
    EXPECT_FALSE(grey.unassociated);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(grey.rgba.at(0, 0, c), 51.0 / 255);
    EXPECT_EQ(grey.rgba.at(0, 0, 3), 1.0);
    EXPECT_DOUBLE_EQ(quantisation_bound(grey, 0, 1), 0.5 / 255);

    write_exr(dir_ / "a.exr", 1, 1, {"R", "G", "B", "A"}, {0.25f, 0.125f, 0.0f, 0.5f});
    const ComparedImage exr = read_compared_image(dir_ / "a.exr", glm::dvec4(1.0, 0.5, 0.25, 0.5));
    EXPECT_EQ(exr.bits, 0);
    EXPECT_DOUBLE_EQ(exr.rgba.at(0, 0, 0), 0.25 + 0.5 * 0.5 * 1.0);
    EXPECT_DOUBLE_EQ(exr.rgba.at(0, 0, 1), 0.125 + 0.5 * 0.5 * 0.5);
    EXPECT_DOUBLE_EQ(exr.rgba.at(0, 0, 2), 0.0 + 0.5 * 0.5 * 0.25);
    EXPECT_DOUBLE_EQ(exr.rgba.at(0, 0, 3), 0.5 + 0.5 * 0.5);
}

// 8-bit quantisation: q = 0.5/255; an opaque stored colour u_s = 128/255 has the bound
// q (1 + 128/255) + q^2 = 0.7510/255 + q^2 in colour and q in alpha. An EXR 0.70/255 above is within,
// 0.80/255 above is not; the same in alpha: 0.45/255 within, 0.55/255 not.
TEST_F(CompareCli, EightBitQuantisationBound) {
    write_png(dir_ / "b.png", 1, 1, {128, 128, 128, 255});
    const double q = 0.5 / 255, u = 128.0 / 255;
    const ComparedImage png = read_compared_image(dir_ / "b.png");
    EXPECT_NEAR(quantisation_bound(png, 0, 0), q * (1 + u) + q * q, 1e-17);
    EXPECT_NEAR(quantisation_bound(png, 0, 3), q, 1e-17);

    auto over = [&](double dc, double da) {
        const float c = float(u + dc), a = float(1.0 - da);
        write_exr(dir_ / "a.exr", 1, 1, {"R", "G", "B", "A"}, {c, c, c, a});
        const ComparedImage exr = read_compared_image(dir_ / "a.exr");
        return measure_difference(exr.rgba, png.rgba, tolerance_map(exr, png, {})).overall.over;
    };
    EXPECT_EQ(over(0.70 / 255, 0.0), 0);
    EXPECT_EQ(over(0.80 / 255, 0.0), 1);
    EXPECT_EQ(over(0.0, 0.45 / 255), 0);
    EXPECT_EQ(over(0.0, 0.55 / 255), 1);
    // Two 8-bit inputs each add their bound: bytes 128 and 129 differ by 1/255 < 2 (0.751/255 + q^2).
    auto over_png = [&](std::uint8_t r) {
        write_png(dir_ / "c.png", 1, 1, {r, 128, 128, 255});
        const ComparedImage c = read_compared_image(dir_ / "c.png");
        return measure_difference(png.rgba, c.rgba, tolerance_map(png, c, {})).overall.over;
    };
    EXPECT_EQ(over_png(129), 0);
    EXPECT_EQ(over_png(130), 1);  // 2/255 > 0.751/255 + 0.755/255 + 2 q^2
    // Semi-transparent: stored (200, 50, 0, 100): colour bound q (100/255 + u_s) + q^2 per channel.
    write_png(dir_ / "e.png", 1, 1, {200, 50, 0, 100});
    const ComparedImage e = read_compared_image(dir_ / "e.png");
    EXPECT_NEAR(quantisation_bound(e, 0, 0), q * (100.0 / 255 + 200.0 / 255) + q * q, 1e-17);
    EXPECT_NEAR(quantisation_bound(e, 0, 2), q * (100.0 / 255) + q * q, 1e-17);
    // Through the command: the statuses follow (0 within, 1 over).
    over(0.70 / 255, 0.0);
    EXPECT_EQ(run(p("a.exr") + " " + p("b.png")).status, 0);
    over(0.80 / 255, 0.0);
    EXPECT_EQ(run(p("a.exr") + " " + p("b.png")).status, 1);
}

// The `error` channel: B = A + 0.01 everywhere; A's error is 0.02 on the left half, 0.005 on the right:
// half the pixels are over. With --tolerance 0.006 added, 0.011 >= 0.01 everywhere: within.
TEST_F(CompareCli, ToleranceFromErrorChannel) {
    const int w = 8, h = 4;
    std::vector<float> a, b;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float e = x < w / 2 ? 0.02f : 0.005f;
            for (float v : {0.25f, 0.5f, 0.125f, 0.75f}) {
                a.push_back(v);
                b.push_back(v + 0.0078125f);  // exact in float
            }
            a.push_back(e);
        }
    write_exr(dir_ / "a.exr", w, h, {"R", "G", "B", "A", "error"}, a);
    write_exr(dir_ / "b.exr", w, h, {"R", "G", "B", "A"}, b);
    CmdResult r = run(p("a.exr") + " " + p("b.exr") + " --tolerance-from-error --json");
    EXPECT_EQ(r.status, 1) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["pixels_over"].get<long>(), 16);
    EXPECT_DOUBLE_EQ(j["fraction_over"].get<double>(), 0.5);
    EXPECT_EQ(run(p("a.exr") + " " + p("b.exr") + " --tolerance-from-error --tolerance 0.006").status, 0);
    const ComparedImage ia = read_compared_image(dir_ / "a.exr"), ib = read_compared_image(dir_ / "b.exr");
    EXPECT_EQ(measure_difference(ia.rgba, ib.rgba, tolerance_map(ia, ib, {0.006, false})).overall.over, 32);
    // Neither input has an error channel: an input error (2), one line naming both files.
    r = run(p("b.exr") + " " + p("b.exr") + " --tolerance-from-error");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("b.exr"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
}

// ---- the command's statuses and report --------------------------------------------------------------------

// Offset 1/128 on R, G, B, A (exact in float): max abs = RMSE = 0.0078125, PSNR = 20 log10(128) dB.
TEST_F(CompareCli, ExitStatusesAndJsonReport) {
    const Image a = make_image(12, 12, [](int x, int y, int c) { return 0.25 + 0.015625 * ((x + y + c) % 8); });
    Image b = a;
    for (double& v : b.pixels) v += 0.0078125;
    write_exr(dir_ / "a.exr", 12, 12, {"R", "G", "B", "A"}, to_floats(a));
    write_exr(dir_ / "b.exr", 12, 12, {"R", "G", "B", "A"}, to_floats(b));

    CmdResult r = run(p("a.exr") + " " + p("a.exr"));
    EXPECT_EQ(r.status, 0) << r.err;
    r = run(p("a.exr") + " " + p("b.exr") + " --json");
    EXPECT_EQ(r.status, 1) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_DOUBLE_EQ(j["overall"]["max_abs"].get<double>(), 0.0078125);
    EXPECT_DOUBLE_EQ(j["overall"]["mean_abs"].get<double>(), 0.0078125);
    EXPECT_DOUBLE_EQ(j["overall"]["rmse"].get<double>(), 0.0078125);
    EXPECT_NEAR(j["overall"]["psnr_db"].get<double>(), 20 * std::log10(128.0), 1e-12);
    EXPECT_EQ(j["pixels_over"].get<long>(), 144);
    EXPECT_FALSE(j["within_tolerance"].get<bool>());
    EXPECT_EQ(run(p("a.exr") + " " + p("b.exr") + " --tolerance 0.0078").status, 1);
    // Text report: the table's overall row and the verdict; |d| = tolerance is within.
    r = run(p("a.exr") + " " + p("b.exr") + " --tolerance 0.0078125");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("all       7.8125e-03   7.8125e-03   7.8125e-03     42.14"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("within tolerance"), std::string::npos) << r.out;
}

TEST_F(CompareCli, InputAndUsageErrorsExitTwo) {
    write_exr(dir_ / "a.exr", 4, 4, {"R", "G", "B", "A"}, std::vector<float>(64, 0.5f));
    write_exr(dir_ / "c.exr", 4, 3, {"R", "G", "B", "A"}, std::vector<float>(48, 0.5f));
    auto expect_one_line = [&](const std::string& args, const std::string& needle) {
        const CmdResult r = run(args);
        EXPECT_EQ(r.status, 2) << args;
        EXPECT_EQ(r.err.rfind("volref: error: ", 0), 0u) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
    };
    expect_one_line(p("a.exr") + " " + p("c.exr"), "same size");
    expect_one_line(p("a.exr") + " " + p("nope.exr"), "nope.exr");
    std::ofstream(dir_ / "junk.png") << "not an image";
    expect_one_line(p("junk.png") + " " + p("a.exr"), "junk.png");
    // A mismatch must not leave a heat map.
    EXPECT_EQ(run(p("a.exr") + " " + p("c.exr") + " --heatmap " + p("h.png")).status, 2);
    EXPECT_FALSE(fs::exists(dir_ / "h.png"));
}

TEST_F(CompareCli, BadOptionsExitTwo) {
    write_exr(dir_ / "a.exr", 4, 4, {"R", "G", "B", "A"}, std::vector<float>(64, 0.5f));
    CmdResult r = run(p("a.exr") + " " + p("a.exr") + " --background 1,2");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--background"), std::string::npos) << r.err;
    r = run(p("a.exr") + " " + p("a.exr") + " --heatmap " + p("h.jpg"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("h.jpg"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "h.jpg"));
    // CLI11 usage errors.
    EXPECT_EQ(run(p("a.exr")).status, 2);
    EXPECT_EQ(run(p("a.exr") + " " + p("a.exr") + " --tolerance -1").status, 2);
}

// Heat map: d = max abs per pixel, scale = the max (0.3): d = 0.3 white, 0 black, 0.15 -> t = 1/2 ->
// (min(1, 1.5), clamp(0.5), clamp(-0.5)) = (1, 0.5, 0) -> bytes (255, 128, 0); 0.05 -> t = 1/6 -> (0.5, 0, 0)
// -> (128, 0, 0).
TEST_F(CompareCli, HeatMapColours) {
    std::vector<float> a(4 * 4, 0.5f), b = a;
    b[0 * 4 + 2] += 0.3f;   // pixel 0, channel B
    b[1 * 4 + 3] -= 0.15f;  // pixel 1, alpha
    b[2 * 4 + 0] += 0.05f;  // pixel 2, R
    write_exr(dir_ / "a.exr", 4, 1, {"R", "G", "B", "A"}, a);
    write_exr(dir_ / "b.exr", 4, 1, {"R", "G", "B", "A"}, b);
    const CmdResult r = run(p("a.exr") + " " + p("b.exr") + " --heatmap " + p("h.png") + " --tolerance 1");
    ASSERT_EQ(r.status, 0) << r.err;
    auto in = OIIO::ImageInput::open(p("h.png"));
    ASSERT_TRUE(in);
    ASSERT_EQ(in->spec().nchannels, 4);  // opaque RGBA: read R, G, B
    std::vector<std::uint8_t> px(12);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
    EXPECT_EQ(std::vector<std::uint8_t>(px.begin(), px.begin() + 3), (std::vector<std::uint8_t>{255, 255, 255}));
    EXPECT_EQ(std::vector<std::uint8_t>(px.begin() + 3, px.begin() + 6), (std::vector<std::uint8_t>{255, 128, 0}));
    EXPECT_EQ(std::vector<std::uint8_t>(px.begin() + 6, px.begin() + 9), (std::vector<std::uint8_t>{128, 0, 0}));
    EXPECT_EQ(std::vector<std::uint8_t>(px.begin() + 9, px.begin() + 12), (std::vector<std::uint8_t>{0, 0, 0}));
}

// ---- --fit ------------------------------------------------------------------------------------------

// B's colour is 1.1 times A's (alpha unchanged): the gain fit recovers 1.1 and leaves no residual.
TEST(CompareFit, RecoversAGain) {
    const Image a = make_image(24, 20, [](int x, int y, int c) { return c == 3 ? 0.8 : smooth(x, y, c) * 0.8; });
    Image b = a;
    for (std::size_t i = 0; i < b.pixels.size(); ++i)
        if (i % 4 != 3) b.pixels[i] *= 1.1;
    const DifferenceExplanation e = explain_difference(a, b);
    EXPECT_EQ(e.fits[0].model, "gain");
    EXPECT_NEAR(e.fits[0].values[0], 1.1, 1e-6);
    EXPECT_LT(e.fits[0].residual_after, 1e-9);
    EXPECT_GT(e.fits[0].residual_before, 0.01);
    EXPECT_NE(e.verdict.find("colour gain"), std::string::npos) << e.verdict;
}

// B's alpha is 1 - (1 - alpha_A)^1.7 and its colour follows (constant colour c per pixel: C = c alpha):
// the opacity fit recovers k = 1.7.
TEST(CompareFit, RecoversAnOpacityExponent) {
    const double k = 1.7;
    auto alpha = [](int x, int y) { return 0.05 + 0.9 * (0.5 + 0.5 * std::sin(0.37 * x + 0.21 * y)); };
    const Image a = make_image(20, 20, [&](int x, int y, int c) {
        return c == 3 ? alpha(x, y) : smooth(x, y, c) * alpha(x, y);
    });
    const Image b = make_image(20, 20, [&](int x, int y, int c) {
        const double ab = 1.0 - std::pow(1.0 - alpha(x, y), k);
        return c == 3 ? ab : smooth(x, y, c) * ab;
    });
    const DifferenceExplanation e = explain_difference(a, b);
    EXPECT_EQ(e.fits[1].model, "opacity");
    EXPECT_NEAR(e.fits[1].values[0], k, 1e-6);
    EXPECT_LT(e.fits[1].residual_after, 1e-9);
    EXPECT_NE(e.verdict.find("opacity"), std::string::npos) << e.verdict;
    // The gain model cannot explain it as well: its residual stays well above.
    EXPECT_GT(e.fits[0].residual_after, 100 * e.fits[1].residual_after);
}

// The opacity model is judged on alpha, which follows T_B = T_A^k for any ray: B's colour here does not
// follow A's alpha ratio (colour varying along the ray), yet k = 2.5 is recovered from alpha and named.
TEST(CompareFit, OpacityExponentFromAlphaWhateverTheColour) {
    auto alpha = [](int x, int y) { return 0.1 + 0.8 * (0.5 + 0.5 * std::cos(0.29 * x - 0.17 * y)); };
    const Image a = make_image(16, 16, [&](int x, int y, int c) { return c == 3 ? alpha(x, y) : 0.3 * alpha(x, y); });
    const Image b = make_image(16, 16, [&](int x, int y, int c) {
        const double ab = 1.0 - std::pow(1.0 - alpha(x, y), 2.5);
        return c == 3 ? ab : smooth(x, y, c) * ab;
    });
    const ModelFit f = fit_opacity_exponent(a, b);
    EXPECT_EQ(f.judged_on, "alpha");
    EXPECT_NEAR(f.values[0], 2.5, 1e-6);
    EXPECT_LT(f.residual_after, 1e-9);
    EXPECT_GT(f.rgba_after, 1e-3);  // the colour is not explained
    EXPECT_NE(explain_difference(a, b).verdict.find("2.5 times A's optical depth"), std::string::npos);
}

// B(x, y) = f(x - 0.3, y + 0.2) for a smooth f sampled at the pixels: the shift fit finds (0.3, -0.2)
// to the accuracy of bicubic interpolation of f (a wavelength of ~20 pixels: ~1e-3 pixel).
TEST(CompareFit, RecoversASubPixelShift) {
    const Image a = make_image(32, 32, [](int x, int y, int c) { return smooth(x, y, c); });
    const Image b = make_image(32, 32, [](int x, int y, int c) { return smooth(x - 0.3, y + 0.2, c); });
    const ModelFit f = fit_shift(a, b);
    ASSERT_TRUE(f.fitted);
    EXPECT_NEAR(f.values[0], 0.3, 0.01);
    EXPECT_NEAR(f.values[1], -0.2, 0.01);
    EXPECT_LT(f.residual_after, 0.05 * f.residual_before);
    const DifferenceExplanation e = explain_difference(a, b);
    EXPECT_NE(e.verdict.find("shift"), std::string::npos) << e.verdict;
}

// Unrelated images: no model explains them; identical images need no explanation.
TEST(CompareFit, NamesNoCauseWhenNothingFits) {
    const Image a = make_image(16, 16, [](int x, int y, int c) { return smooth(x, y, c); });
    const Image b = make_image(16, 16, [](int x, int y, int c) { return ((x * 7 + y * 13 + c * 5) % 11) / 11.0; });
    EXPECT_NE(explain_difference(a, b).verdict.find("none of"), std::string::npos);
    EXPECT_NE(explain_difference(a, a).verdict.find("identical"), std::string::npos);
}

// Through the command: --fit --json on EXR files (float storage: 1e-6 relative).
TEST_F(CompareCli, FitThroughTheCommand) {
    const Image a = make_image(16, 16, [](int x, int y, int c) { return c == 3 ? 1.0 : smooth(x, y, c) * 0.5; });
    Image b = a;
    for (std::size_t i = 0; i < b.pixels.size(); ++i)
        if (i % 4 != 3) b.pixels[i] *= 1.25;  // 1.25 x is exact in float
    write_exr(dir_ / "a.exr", 16, 16, {"R", "G", "B", "A"}, to_floats(a));
    write_exr(dir_ / "b.exr", 16, 16, {"R", "G", "B", "A"}, to_floats(b));
    CmdResult r = run(p("a.exr") + " " + p("b.exr") + " --fit --json");
    ASSERT_EQ(r.status, 1) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_NEAR(j["fit"]["gain"]["values"][0].get<double>(), 1.25, 1e-9);
    EXPECT_NE(j["fit"]["verdict"].get<std::string>().find("colour gain"), std::string::npos);
    r = run(p("a.exr") + " " + p("b.exr") + " --fit");
    EXPECT_NE(r.out.find("likely cause: a colour gain, B = 1.25 A"), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;  // Ceres stays silent
}

// Two real renders, the second with opacity_unit_distance halved: every segment's optical depth doubles,
// so alpha_B = 1 - (1 - alpha_A)^2 exactly and --fit must find k = 2 (to float storage).
TEST_F(CompareCli, FitFindsTheOpacityUnitDistanceOfRealRenders) {
    std::ofstream(dir_ / "s.json") << R"({
  "volume": { "source": { "field": "gaussian", "dims": [9, 9, 9], "center": [4, 4, 4], "sigma": 2.5 },
              "transfer": { "opacity": [[0, 0], [1, 0.6]], "color": [[0, 0.2, 0.4, 1.0], [1, 1.0, 0.6, 0.2]] } },
  "image": { "width": 12, "height": 12 }
})";
    const std::string render = std::string(VOLREF_CLI) + " render " + p("s.json") + " > /dev/null 2>&1 -o ";
    ASSERT_EQ(std::system((render + p("a.exr")).c_str()), 0);
    ASSERT_EQ(std::system((render + p("b.exr") + " --set volume.transfer.opacity_unit_distance=0.5").c_str()), 0);
    const CmdResult r = run(p("a.exr") + " " + p("b.exr") + " --fit --json");
    ASSERT_EQ(r.status, 1) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_NEAR(j["fit"]["opacity"]["values"][0].get<double>(), 2.0, 1e-5);
    EXPECT_NE(j["fit"]["verdict"].get<std::string>().find("opacity correction, B has 2 times"), std::string::npos)
        << j["fit"]["verdict"];
}
