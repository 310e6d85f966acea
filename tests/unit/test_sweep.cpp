// volref sweep: the parameter grid, the robust power-law fit, and the command end to end (the midpoint
// rule's order of accuracy, the CSV against renders measured here, the plot files, errors for bad --param).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <OpenImageIO/imageio.h>

#include "core/Error.h"
#include "core/compare/ChildProcess.h"
#include "core/compare/Fits.h"
#include "core/compare/SweepGrid.h"

namespace fs = std::filesystem;
using namespace volref;
using namespace volref::compare;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, sep)) out.push_back(item);
    return out;
}

struct CmdResult {
    int status;
    std::string out, err;
};

class SweepCli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("volref-sweep-test-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        // A smooth scene: a Gaussian field reconstructed by the C2 cubic B-spline, a linear opacity ramp over
        // the window, so the integrand along every ray is smooth and the midpoint rule is of order 2.
        std::ofstream(dir_ / "scene.json") << R"({
  "volume": { "source": { "field": "gaussian", "dims": [17, 17, 17], "center": [8, 8, 8], "sigma": 4 },
              "interpolation": "tricubic-bspline",
              "transfer": { "opacity": [[0, 0], [1, 0.5]], "color": [[0, 0.2, 0.4, 1.0], [1, 1.0, 0.6, 0.2]] } },
  "image": { "width": 12, "height": 12 }
})";
    }
    void TearDown() override { fs::remove_all(dir_); }
    CmdResult run(const std::string& args) const {
        const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
        const std::string cmd = std::string(VOLREF_CLI) + " " + args + " > " + out.string() + " 2> " + err.string();
        const int raw = std::system(cmd.c_str());
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
    }
    std::string scene() const { return (dir_ / "scene.json").string(); }
    fs::path dir_;
};

// RGBA of an EXR as double (OIIO's float values).
std::vector<double> read_rgba(const fs::path& p) {
    auto in = OIIO::ImageInput::open(p.string());
    EXPECT_TRUE(in) << p;
    if (!in) return {};
    const auto& spec = in->spec();
    std::vector<float> v(std::size_t(spec.width) * std::size_t(spec.height) * 4);
    EXPECT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, v.data()));
    return std::vector<double>(v.begin(), v.end());
}

}  // namespace

// ---- the grid ----------------------------------------------------------------------------------------------

TEST(SweepGrid, ParsesValuesAndCombinations) {
    const SweepParam a = parse_sweep_param("render.step=0.5,0.25");
    EXPECT_EQ(a.path, "render.step");
    EXPECT_EQ(a.values, (std::vector<std::string>{"0.5", "0.25"}));
    const SweepParam b = parse_sweep_param("volume.transfer.opacity[1]=[0.5,0.2],[0.5,0.4]");
    EXPECT_EQ(b.values, (std::vector<std::string>{"[0.5,0.2]", "[0.5,0.4]"}));
    const SweepParam c = parse_sweep_param(R"(render.projection="mip","a,b",composite)");
    EXPECT_EQ(c.values, (std::vector<std::string>{"\"mip\"", "\"a,b\"", "composite"}));
    const SweepParam d = parse_sweep_param("image.width=8,16,32");
    // 2 x 3 combinations, the first parameter slowest.
    const auto combos = sweep_combinations({a, d});
    ASSERT_EQ(combos.size(), 6u);
    EXPECT_EQ(combos[0], (std::vector<std::string>{"render.step=0.5", "image.width=8"}));
    EXPECT_EQ(combos[2], (std::vector<std::string>{"render.step=0.5", "image.width=32"}));
    EXPECT_EQ(combos[3], (std::vector<std::string>{"render.step=0.25", "image.width=8"}));
    EXPECT_EQ(combos[5], (std::vector<std::string>{"render.step=0.25", "image.width=32"}));
}

TEST(SweepGrid, BadParamsAreNamed) {
    auto expect_error = [](const std::string& text, const std::string& needle) {
        try {
            parse_sweep_param(text);
            ADD_FAILURE() << text << " was accepted";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("--param '" + text + "'"), std::string::npos) << m;
            EXPECT_NE(m.find(needle), std::string::npos) << m;
        }
    };
    expect_error("render.step", "expected PATH=V1,V2");
    expect_error("=1,2", "empty scene path");
    expect_error("render.step=1,,2", "empty value");
    expect_error("render.step=", "empty value");
    expect_error("render.step=[1,2", "unclosed");
    expect_error("render.step=1]", "unbalanced");
    const SweepParam s = parse_sweep_param("render.step=1,2");
    EXPECT_THROW(sweep_combinations({s, s}), Error);
}

// ---- the fit -------------------------------------------------------------------------------------------

// error = 3 h^2 exactly: p = 2, C = 3, and the step for 1e-3 is sqrt(1e-3 / 3).
TEST(SweepFit, PowerLawExact) {
    const std::vector<double> h{1, 0.5, 0.25, 0.125};
    std::vector<double> e;
    for (double x : h) e.push_back(3 * x * x);
    const PowerLawFit f = fit_power_law(h, e);
    ASSERT_TRUE(f.ok);
    EXPECT_EQ(f.points, 4);
    EXPECT_NEAR(f.p, 2.0, 1e-9);
    EXPECT_NEAR(f.c, 3.0, 1e-8);
    EXPECT_NEAR(step_for_error(f, 1e-3), std::sqrt(1e-3 / 3), 1e-10);
    // Too few usable points (zeros and negative steps are dropped).
    EXPECT_FALSE(fit_power_law({1, 0.5}, {1e-3, 0.0}).ok);
    EXPECT_FALSE(fit_power_law({1, -0.5}, {1e-3, 1e-4}).ok);
}

// Six points on 2 h^2 and one 30 times too high (a step in the pre-asymptotic regime): ordinary least
// squares in log-log (computed here) is pulled off by more than 0.2; the Cauchy-loss fit stays within 0.05.
TEST(SweepFit, PowerLawIsRobustToAnOutlier) {
    std::vector<double> h{4, 1, 0.5, 0.25, 0.125, 0.0625, 0.03125}, e;
    for (double x : h) e.push_back(2 * x * x);
    e[0] *= 30;
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < h.size(); ++i) {
        mx += std::log(h[i]) / double(h.size());
        my += std::log(e[i]) / double(h.size());
    }
    double sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < h.size(); ++i) {
        sxx += (std::log(h[i]) - mx) * (std::log(h[i]) - mx);
        sxy += (std::log(h[i]) - mx) * (std::log(e[i]) - my);
    }
    EXPECT_GT(std::abs(sxy / sxx - 2.0), 0.2);
    const PowerLawFit f = fit_power_law(h, e);
    ASSERT_TRUE(f.ok);
    EXPECT_NEAR(f.p, 2.0, 0.05);
}

TEST(SweepFit, MedianOfRuns) {
    EXPECT_DOUBLE_EQ(median({3.0, 1.0, 2.0}), 2.0);
    EXPECT_DOUBLE_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
    EXPECT_TRUE(std::isnan(median({})));
}

// ---- the command ----------------------------------------------------------------------------------------

// The midpoint rule (fixed step) is of second order on a smooth scene: the fitted p is 2 within 0.2.
// Also: the table, the CSV's rows and their PSNR = 10 log10(1 / RMSE^2), the plot files.
TEST_F(SweepCli, MidpointRuleIsSecondOrderAndWritesTableCsvAndPlots) {
    const fs::path out = dir_ / "out";
    const CmdResult r = run("sweep " + scene() + " --param render.step=0.8,0.4,0.2 --repeat 1 --reference fine -o " +
                            out.string());
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    const auto pos = r.out.find("order p = ");
    ASSERT_NE(pos, std::string::npos) << r.out;
    const double p = std::stod(r.out.substr(pos + 10));
    EXPECT_NEAR(p, 2.0, 0.2) << r.out;
    EXPECT_NE(r.out.find("reference: fine (render.step = 0.0125"), std::string::npos) << r.out;  // 0.2 / 16
    EXPECT_NE(r.out.find("render.step for max abs error <= 0.001: "), std::string::npos) << r.out;

    const std::vector<std::string> lines = split(slurp(out / "sweep.csv"), '\n');
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(lines[0],
              "render.step,time_median_s,time_min_s,time_max_s,max_abs,mean_abs,rmse,psnr_db,pixels_over,fraction_over");
    double previous = INFINITY;
    const char* steps[] = {"0.8", "0.4", "0.2"};
    for (int i = 0; i < 3; ++i) {
        const auto f = split(lines[std::size_t(i) + 1], ',');
        ASSERT_EQ(f.size(), 10u) << lines[std::size_t(i) + 1];
        EXPECT_EQ(f[0], steps[i]);
        EXPECT_GT(std::stod(f[1]), 0.0);
        const double max_abs = std::stod(f[4]), mean_abs = std::stod(f[5]), rmse = std::stod(f[6]);
        EXPECT_GT(max_abs, 0.0);
        EXPECT_LT(max_abs, previous);  // smaller steps, smaller errors
        previous = max_abs;
        EXPECT_LE(mean_abs, rmse * (1 + 1e-8));
        EXPECT_LE(rmse, max_abs * (1 + 1e-8));
        EXPECT_NEAR(std::stod(f[7]), 10 * std::log10(1 / (rmse * rmse)), 1e-3);
        const double fraction = std::stod(f[9]);
        EXPECT_NEAR(fraction, std::stod(f[8]) / 144.0, 1e-6);  // 12 x 12 pixels
        // The table on stdout holds the same row.
        EXPECT_NE(r.out.find("\n" + std::string(steps[i]) + " "), std::string::npos) << r.out;
    }
    const std::string png = slurp(out / "sweep.png"), svg = slurp(out / "sweep.svg");
    EXPECT_GT(png.size(), 1000u);
    EXPECT_EQ(png.substr(0, 4), "\x89PNG");
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("max abs error"), std::string::npos);
    for (const auto& e : fs::directory_iterator(out))  // no temporary files left
        EXPECT_EQ(e.path().filename().string().find(".volref-tmp"), std::string::npos) << e.path();
}

// The CSV's errors equal the ones measured here from `volref render` images of the same settings (the
// fine reference at 1 / 16 of the step); -o creates the folder; --set reaches every render.
TEST_F(SweepCli, CsvErrorsMatchRendersMeasuredHere) {
    const fs::path out = dir_ / "a" / "b";
    const std::string set = " --set image.width=10 --set image.height=6";
    CmdResult r = run("sweep " + scene() + " --param render.step=1 --repeat 1 --reference fine --tolerance 1e-4 -o " +
                      out.string() + set);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("order p: not fitted"), std::string::npos) << r.out;
    ASSERT_EQ(run("render " + scene() + " -o " + (dir_ / "h.exr").string() + set + " --set render.step=1").status, 0);
    ASSERT_EQ(run("render " + scene() + " -o " + (dir_ / "ref.exr").string() + set + " --set render.step=0.0625").status,
              0);
    const std::vector<double> a = read_rgba(dir_ / "h.exr"), b = read_rgba(dir_ / "ref.exr");
    ASSERT_EQ(a.size(), 10u * 6u * 4u);
    ASSERT_EQ(a.size(), b.size());
    double max_abs = 0, sum_sq = 0;
    long over = 0;
    for (std::size_t px = 0; px < a.size() / 4; ++px) {
        bool any = false;
        for (std::size_t c = 0; c < 4; ++c) {
            const double d = std::abs(a[px * 4 + c] - b[px * 4 + c]);
            max_abs = std::max(max_abs, d);
            sum_sq += d * d;
            any = any || d > 1e-4;
        }
        over += any;
    }
    const auto f = split(split(slurp(out / "sweep.csv"), '\n').at(1), ',');
    ASSERT_EQ(f.size(), 10u);
    EXPECT_NEAR(std::stod(f[4]), max_abs, 1e-8 * max_abs);
    EXPECT_NEAR(std::stod(f[6]), std::sqrt(sum_sq / double(a.size())), 1e-8 * max_abs);
    EXPECT_EQ(std::stol(f[8]), over);
    EXPECT_GT(over, 0);  // the tolerance matters in this test
}

// Without --reference, a volref that has the adaptive integrator measures against it: the CSV's max abs is
// the one measured here against `volref render --set render.integrator=adaptive`.
TEST_F(SweepCli, DefaultReferenceIsTheAdaptiveIntegrator) {
    const std::string set = " --set image.width=8 --set image.height=8";
    const CmdResult r = run("sweep " + scene() + " --param render.step=0.5 --repeat 1 -o " + dir_.string() + set);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("reference: adaptive (render.integrator=adaptive, render.tolerance = 1e-06)"),
              std::string::npos)
        << r.out;
    ASSERT_EQ(run("render " + scene() + " -o " + (dir_ / "h.exr").string() + set + " --set render.step=0.5").status, 0);
    ASSERT_EQ(run("render " + scene() + " -o " + (dir_ / "ref.exr").string() + set +
                  " --set render.integrator=adaptive")
                  .status,
              0);
    const std::vector<double> a = read_rgba(dir_ / "h.exr"), b = read_rgba(dir_ / "ref.exr");
    ASSERT_EQ(a.size(), b.size());
    double max_abs = 0;
    for (std::size_t i = 0; i < a.size(); ++i) max_abs = std::max(max_abs, std::abs(a[i] - b[i]));
    const auto f = split(split(slurp(dir_ / "sweep.csv"), '\n').at(1), ',');
    ASSERT_EQ(f.size(), 10u);
    EXPECT_GT(max_abs, 1e-6);
    EXPECT_NEAR(std::stod(f[4]), max_abs, 1e-8 * max_abs);
}

TEST_F(SweepCli, BadParamsAreNamedAndWriteNothing) {
    auto expect_error = [&](const std::string& args, const std::string& needle) {
        const CmdResult r = run("sweep " + scene() + " " + args + " -o " + dir_.string());
        EXPECT_EQ(r.status, 1) << args;
        EXPECT_EQ(r.err.rfind("volref: error: ", 0), 0u) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "sweep.csv"));
        EXPECT_FALSE(fs::exists(dir_ / "sweep.png"));
    };
    expect_error("--param render.step", "--param 'render.step'");
    expect_error("--param render.stepp=1,2", "render.stepp");
    expect_error("--param render.step=1,0", "--param render.step=0");
    expect_error("--param render.step=1 --reference coarse", "--reference");
}
