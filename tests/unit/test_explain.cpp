// volref explain: each topic against numbers worked by hand here (the comments show the work), the
// --json output against the same numbers, and bad arguments as one-line errors naming the argument.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/explain/Explain.h"
#include "core/explain/ExplainArguments.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneLoader.h"

namespace fs = std::filesystem;
using namespace volref;
using explain::Explanation;

namespace {

// Levoy's lecture corners f1..f8 in his order (f1 (0,0,0), f2 (1,0,0), f3 (1,1,0), f4 (0,1,0), f5..f8 at z = 1).
const std::array<double, 8> kLevoy{5.0, 5.1, 5.2, 4.6, 4.9, 5.1, 5.3, 4.7};
const std::string kLevoyScene = std::string(VOLREF_SOURCE_DIR) + "/reference_scenes/levoy-lecture.json";

std::vector<double> vec(const Explanation& e, const std::string& section, const std::string& step) {
    return e.step(section, step).value;
}

struct CliRun {
    int status;
    std::string out, err;
};

CliRun run_cli(const std::string& args) {
    const fs::path dir = fs::temp_directory_path() / ("volref-explain-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string cmd = std::string(VOLREF_CLI) + " " + args + " > " + (dir / "out").string() + " 2> " + (dir / "err").string();
    const int raw = std::system(cmd.c_str());
    auto slurp = [](const fs::path& p) {
        std::ifstream in(p);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    };
    CliRun r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir / "out"), slurp(dir / "err")};
    fs::remove_all(dir);
    return r;
}

// The JSON step `name` of the section titled `title`.
const nlohmann::json& json_step(const nlohmann::json& j, const std::string& title, const std::string& name) {
    for (const auto& s : j.at("sections"))
        if (s.at("title") == title) return s.at("steps").at(name);
    throw std::out_of_range("no section " + title);
}

}  // namespace

// ---- trilinear ---------------------------------------------------------------------------------

// At the cell's centre every weight is 1/8: f = (5.0 + 5.1 + 5.2 + 4.6 + 4.9 + 5.1 + 5.3 + 4.7) / 8
// = 39.9 / 8 = 4.9875. Lecture steps: f12 = (5.0 + 5.1)/2 = 5.05, f43 = (4.6 + 5.2)/2 = 4.9,
// f56 = (4.9 + 5.1)/2 = 5.0, f87 = (4.7 + 5.3)/2 = 5.0; f1243 = (5.05 + 4.9)/2 = 4.975, f5687 = 5.0;
// f = (4.975 + 5.0)/2 = 4.9875.
TEST(Explain, TrilinearAtTheCentreIsTheMeanOfTheCorners) {
    const Explanation e = explain::trilinear(kLevoy, {0.5, 0.5, 0.5});
    EXPECT_NEAR(e.value("x-lerps (Levoy's lecture)", "f12"), 5.05, 1e-15);
    EXPECT_NEAR(e.value("x-lerps (Levoy's lecture)", "f43"), 4.9, 1e-15);
    EXPECT_NEAR(e.value("x-lerps (Levoy's lecture)", "f56"), 5.0, 1e-15);
    EXPECT_NEAR(e.value("x-lerps (Levoy's lecture)", "f87"), 5.0, 1e-15);
    EXPECT_NEAR(e.value("y-lerps", "f1243"), 4.975, 1e-15);
    EXPECT_NEAR(e.value("y-lerps", "f5687"), 5.0, 1e-15);
    EXPECT_NEAR(e.value("z-lerp", "f"), 4.9875, 1e-15);
    for (int n = 1; n <= 8; ++n)
        EXPECT_EQ(e.value("volref's sum (core/sample/Trilinear.h), term by term", "w" + std::to_string(n)), 0.125);
    EXPECT_NEAR(e.value("result", "f"), 4.9875, 1e-15);
}

// At (p, q, r) = (0.2, 0.3, 0.8): (1-p, 1-q, 1-r) = (0.8, 0.7, 0.2).
//   x-lerps: f12 = 0.8*5.0 + 0.2*5.1 = 5.02; f43 = 0.8*4.6 + 0.2*5.2 = 4.72;
//            f56 = 0.8*4.9 + 0.2*5.1 = 4.94; f87 = 0.8*4.7 + 0.2*5.3 = 4.82;
//   y-lerps: f1243 = 0.7*5.02 + 0.3*4.72 = 4.93; f5687 = 0.7*4.94 + 0.3*4.82 = 4.904;
//   z-lerp:  f = 0.2*4.93 + 0.8*4.904 = 0.986 + 3.9232 = 4.9092.
//   weights: w1 = 0.8*0.7*0.2 = 0.112, w2 = 0.028, w3 = 0.012, w4 = 0.048, w5 = 0.448, w6 = 0.112,
//            w7 = 0.048, w8 = 0.192 (sum 1).
// At (0.8, 0.7, 0.2): f = 5.0*0.048 + 5.1*0.192 + 5.2*0.448 + 4.6*0.112 + 4.9*0.012 + 5.1*0.048
//   + 5.3*0.112 + 4.7*0.028 = 0.24 + 0.9792 + 2.3296 + 0.5152 + 0.0588 + 0.2448 + 0.5936 + 0.1316 = 5.0928.
TEST(Explain, TrilinearAtLevoysSamplePoints) {
    const Explanation e = explain::trilinear(kLevoy, {0.2, 0.3, 0.8});
    const std::string x = "x-lerps (Levoy's lecture)", sum = "volref's sum (core/sample/Trilinear.h), term by term";
    EXPECT_NEAR(e.value(x, "f12"), 5.02, 1e-14);
    EXPECT_NEAR(e.value(x, "f43"), 4.72, 1e-14);
    EXPECT_NEAR(e.value(x, "f56"), 4.94, 1e-14);
    EXPECT_NEAR(e.value(x, "f87"), 4.82, 1e-14);
    EXPECT_NEAR(e.value("y-lerps", "f1243"), 4.93, 1e-14);
    EXPECT_NEAR(e.value("y-lerps", "f5687"), 4.904, 1e-14);
    EXPECT_NEAR(e.value("z-lerp", "f"), 4.9092, 1e-14);
    const double w[8] = {0.112, 0.028, 0.012, 0.048, 0.448, 0.112, 0.048, 0.192};
    for (int n = 0; n < 8; ++n) EXPECT_NEAR(e.value(sum, "w" + std::to_string(n + 1)), w[n], 1e-15);
    EXPECT_NEAR(e.value(sum, "f5 w5"), 4.9 * 0.448, 1e-14);
    EXPECT_NEAR(e.value("result", "f"), 4.9092, 1e-14);
    EXPECT_NEAR(e.value("result", "lerps - f"), 0.0, 1e-14);
    EXPECT_NEAR(explain::trilinear(kLevoy, {0.8, 0.7, 0.2}).value("result", "f"), 5.0928, 1e-14);
}

// The lecture scene stores the corners i fastest as [f1, f2, f4, f3, f5, f6, f8, f7]; at the world point
// (0.2, 0.3, 0.8) of the unit cell the cell is (0, 0, 0), the local coordinates the point itself, and
// the corners come back in Levoy's order.
TEST(Explain, TrilinearAtAWorldPointOfTheLectureScene) {
    const Scene scene = load_scene(kLevoyScene);
    VolumeModel model;
    build_volume_model(scene.volume(), model);
    const Explanation e = explain::trilinear_at(*model.cartesian, {0.2, 0.3, 0.8});
    EXPECT_EQ(vec(e, "grid", "cell"), (std::vector<double>{0, 0, 0}));
    const std::vector<double> local = vec(e, "grid", "(p, q, r)");
    EXPECT_NEAR(local[0], 0.2, 1e-15);
    EXPECT_NEAR(local[1], 0.3, 1e-15);
    EXPECT_NEAR(local[2], 0.8, 1e-15);
    for (int n = 0; n < 8; ++n)
        EXPECT_EQ(e.value("corners (Levoy's order) and local coordinates", "f" + std::to_string(n + 1)), kLevoy[std::size_t(n)]);
    EXPECT_NEAR(e.value("result", "f"), 4.9092, 1e-14);
    EXPECT_EQ(e.value("result", "VolumeSampler::value"), e.value("result", "f"));
}

// ---- composite ---------------------------------------------------------------------------------

// Samples front first: red a = 0.5, green a = 0.5, blue a = 1; l = 1, d = 0.5.
// alpha = 1 - (1 - 0.5)^0.5 = 1 - sqrt(0.5) = 0.29289321881345; front to back:
//   after red:   C = (alpha, 0, 0), T = sqrt(0.5);
//   after green: C.g = sqrt(0.5) alpha = sqrt(0.5) - 0.5 = 0.20710678118655, T = 0.5;
//   after blue (opaque): C.b = 0.5, A = 1.
TEST(Explain, CompositeBothOrdersAgreeWithTheHandResult) {
    const std::vector<explain::CompositeSample> s{{{1, 0, 0}, 0.5}, {{0, 1, 0}, 0.5}, {{0, 0, 1}, 1.0}};
    const double r2 = std::sqrt(0.5);
    for (const CompositeOrder order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
        const Explanation e = explain::composite(s, order, 1.0, 0.5);
        const auto ftb = vec(e, "both orders", "front to back"), btf = vec(e, "both orders", "back to front");
        const double hand[4] = {1.0 - r2, r2 - 0.5, 0.5, 1.0};
        for (int c = 0; c < 4; ++c) {
            EXPECT_NEAR(ftb[std::size_t(c)], hand[c], 1e-15);
            EXPECT_NEAR(btf[std::size_t(c)], hand[c], 1e-15);
        }
        EXPECT_LE(e.value("both orders", "max |difference|"), 1e-15);
        const explain::Section& t = e.sections[1];
        ASSERT_EQ(t.rows.size(), 3u);
        const auto col = [&](const std::string& name) {
            return std::size_t(std::find(t.columns.begin(), t.columns.end(), name) - t.columns.begin());
        };
        const auto& first = t.rows.front();
        if (order == CompositeOrder::FrontToBack) {
            EXPECT_EQ(first[col("sample")], 1.0);
            EXPECT_NEAR(first[col("alpha")], 1.0 - r2, 1e-15);
            EXPECT_NEAR(first[col("T_after")], r2, 1e-15);
            EXPECT_NEAR(t.rows[1][col("C_g")], r2 - 0.5, 1e-15);
            EXPECT_NEAR(t.rows[1][col("T_after")], 0.5, 1e-15);
        } else {  // the far (opaque, blue) sample first: C = blue, A = 1
            EXPECT_EQ(first[col("sample")], 3.0);
            EXPECT_EQ(first[col("alpha")], 1.0);
            EXPECT_EQ(first[col("C_b")], 1.0);
            // then green over it: C = alpha green + (1 - alpha) blue
            EXPECT_NEAR(t.rows[1][col("C_g")], 1.0 - r2, 1e-15);
            EXPECT_NEAR(t.rows[1][col("C_b")], r2, 1e-15);
        }
    }
}

// Two white samples of a = 0.2 with d = l = 1: alpha = 0.2 each, A = 1 - 0.8^2 = 0.36 = C.
TEST(Explain, CompositeOfTwoTranslucentSamples) {
    const Explanation e = explain::composite({{{1, 1, 1}, 0.2}, {{1, 1, 1}, 0.2}}, CompositeOrder::FrontToBack, 1.0, 1.0);
    const auto p = vec(e, "both orders", "front to back");
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(p[std::size_t(c)], 0.36, 1e-15);
}

// ---- opacity correction ------------------------------------------------------------------------

// a = 0.5 over l = 1, d = 0.5: tau = -(0.5) ln(0.5) = 0.5 ln 2 = 0.34657359027997264,
// alpha = 1 - 0.5^0.5 = 0.2928932188134524; sigma = ln 2.
TEST(Explain, OpacityCorrection) {
    const Explanation e = explain::opacity_correction(0.5, 1.0, 0.5);
    const std::string v = "volref (transfer/OpacityCorrection.h)";
    EXPECT_NEAR(e.value(v, "sigma"), std::log(2.0), 1e-15);
    EXPECT_NEAR(e.value(v, "tau"), 0.5 * std::log(2.0), 1e-15);
    EXPECT_NEAR(e.value(v, "alpha"), 1.0 - std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(e.value("textbook form", "alpha"), 1.0 - std::sqrt(0.5), 1e-15);
    EXPECT_LE(std::fabs(e.value("difference", "textbook - volref")), 1e-15);
    // d = l: the corrected opacity is a itself (a = 0.2, l = d = 2).
    EXPECT_NEAR(explain::opacity_correction(0.2, 2.0, 2.0).value(v, "alpha"), 0.2, 1e-15);
    // a = 1 is opaque for any d > 0, d = 0 transparent for any a.
    EXPECT_EQ(explain::opacity_correction(1.0, 1.0, 0.1).value(v, "alpha"), 1.0);
    EXPECT_EQ(explain::opacity_correction(0.7, 1.0, 0.0).value(v, "alpha"), 0.0);
}

// ---- classification ----------------------------------------------------------------------------

// f = 0.9, g = 2. Contour 1 (fv 1, av 0.8, r 0.1, red): |f - fv| = 0.1 <= r g = 0.2, a_1 = 0.8 (1 - 0.5)
// = 0.4. Contour 2 (fv 0.8, av 0.5, r 0.5, white): 0.1 <= 1, a_2 = 0.5 (1 - 0.1) = 0.45.
// a = 1 - 0.6 * 0.55 = 0.67; colour = (0.4 red + 0.45 white) / 0.85 = (1, 9/17, 9/17).
TEST(Explain, ClassifyIsovalue) {
    IsovalueContour c1, c2;
    c1.value = 1.0, c1.opacity = 0.8, c1.thickness = 0.1, c1.color = {1, 0, 0};
    c2.value = 0.8, c2.opacity = 0.5, c2.thickness = 0.5;
    const Explanation e = explain::classify_isovalue(0.9, 2.0, {c1, c2});
    EXPECT_NEAR(e.value("contour 1", "a_n"), 0.4, 1e-15);
    EXPECT_NEAR(e.value("contour 2", "a_n"), 0.45, 1e-15);
    EXPECT_NEAR(e.value("contour 1", "|f - fv| / (r g)"), 0.5, 1e-15);
    const std::string r = "result (IsovalueClassifier::classify)";
    EXPECT_NEAR(e.value(r, "a"), 0.67, 1e-15);
    const auto colour = vec(e, r, "colour");
    EXPECT_NEAR(colour[0], 1.0, 1e-15);
    EXPECT_NEAR(colour[1], 9.0 / 17.0, 1e-15);
    // outside the tent (|2 - 1| = 1 > r g = 0.5): 0; g = 0 exactly on the isovalue: av.
    IsovalueContour c3;
    c3.value = 1.0, c3.opacity = 0.8, c3.thickness = 0.5;
    EXPECT_EQ(explain::classify_isovalue(2.0, 1.0, {c3}).value(r, "a"), 0.0);
    EXPECT_EQ(explain::classify_isovalue(1.0, 0.0, {c3}).value(r, "a"), 0.8);
}

// Regions fv 1 (av 0.2, red), 2 (av 0.8, blue); f = 1.5, g = 0.5: w = 0.5, av_1 (1 - w) = 0.1,
// av_2 w = 0.4, a = 0.5 * 0.5 = 0.25, colour (0.1 red + 0.4 blue) / 0.5 = (0.2, 0, 0.8).
// g = 10: 10 * 0.5 = 5, clamped to 1. f = 3: outside, 0. Three regions 1, 2, 3 (av 0.2, 0.8, 0.4),
// f = 2.5, g = 1: the second interval, w = 0.5, a = 0.8 * 0.5 + 0.4 * 0.5 = 0.6.
TEST(Explain, ClassifyBoundary) {
    BoundaryRegion a, b, c;
    a.value = 1, a.opacity = 0.2, a.color = {1, 0, 0};
    b.value = 2, b.opacity = 0.8, b.color = {0, 0, 1};
    c.value = 3, c.opacity = 0.4;
    const std::string t = "terms (BoundaryClassifier)", r = "result (BoundaryClassifier::classify)";
    const Explanation e = explain::classify_boundary(1.5, 0.5, {a, b});
    EXPECT_EQ(e.value(t, "w"), 0.5);
    EXPECT_NEAR(e.value(t, "av_1 (1 - w)"), 0.1, 1e-16);
    EXPECT_NEAR(e.value(t, "av_2 w"), 0.4, 1e-16);
    EXPECT_NEAR(e.value(r, "a"), 0.25, 1e-16);
    const auto colour = vec(e, r, "colour");
    EXPECT_NEAR(colour[0], 0.2, 1e-15);
    EXPECT_NEAR(colour[2], 0.8, 1e-15);
    const Explanation steep = explain::classify_boundary(1.5, 10.0, {a, b});
    EXPECT_NEAR(steep.value(t, "g (sum)"), 5.0, 1e-15);
    EXPECT_EQ(steep.value(r, "a"), 1.0);
    EXPECT_EQ(explain::classify_boundary(3.0, 1.0, {a, b}).value(r, "a"), 0.0);
    const Explanation three = explain::classify_boundary(2.5, 1.0, {a, b, c});
    EXPECT_EQ(three.value(t, "n"), 2.0);
    EXPECT_NEAR(three.value(r, "a"), 0.6, 1e-15);
}

// ---- shading -----------------------------------------------------------------------------------

// N = V = L = +z (headlight), H = +z: N.L = N.H = 1, m = (1, 0.5, 0.25), defaults ka 0.1, kd 0.7,
// ks 0.2: c = 0.1 m + 0.7 m + 0.2 = (1.0, 0.6, 0.4).
// A directional light at 60 degrees from N, L = (sqrt(3)/2, 0, 1/2), white m: N.L = 1/2,
// H = normalize(L + V) = (1/2, 0, sqrt(3)/2), N.H = sqrt(3)/2, (N.H)^10 = (3/4)^5 = 0.2373046875:
// c = 0.1 + 0.35 + 0.2 * 0.2373046875 = 0.4974609375. Phong: R = 2 (N.L) N - L = (-sqrt(3)/2, 0, 1/2),
// R.V = 1/2, 0.5^10 = 1/1024: c = 0.45 + 0.2 / 1024 = 0.4501953125. Depth cue kl = 0.5 at d = 2:
// cue = 1 / (1 + 1) = 0.5 halves the diffuse and specular terms.
TEST(Explain, Shade) {
    explain::ShadeInput in;
    in.gradient = {0, 0, -1};
    in.material = {1, 0.5, 0.25};
    const std::string res = "result (Shader::shade)";
    auto c = vec(explain::shade(in), res, "c");
    EXPECT_NEAR(c[0], 1.0, 1e-15);
    EXPECT_NEAR(c[1], 0.6, 1e-15);
    EXPECT_NEAR(c[2], 0.4, 1e-15);

    LightSpec l;
    l.type = LightSpec::Type::Directional;
    l.direction = {std::sqrt(3.0) / 2.0, 0.0, 0.5};
    in.lights = {l};
    in.material = glm::dvec3(1.0);
    Explanation e = explain::shade(in);
    EXPECT_NEAR(e.value("light 1 (directional)", "N.L"), 0.5, 1e-15);
    EXPECT_NEAR(e.value("light 1 (directional)", "N.H"), std::sqrt(3.0) / 2.0, 1e-15);
    EXPECT_NEAR(vec(e, res, "c")[0], 0.4974609375, 1e-15);
    in.spec.model = ShadingSpec::Model::Phong;
    e = explain::shade(in);
    EXPECT_NEAR(e.value("light 1 (directional)", "R.V"), 0.5, 1e-15);
    EXPECT_NEAR(vec(e, res, "c")[0], 0.4501953125, 1e-15);
    in.spec.model = ShadingSpec::Model::BlinnPhong;
    in.spec.kl = 0.5;
    in.depth = 2.0;
    e = explain::shade(in);
    EXPECT_EQ(e.value("light 1 (directional)", "cue"), 0.5);
    EXPECT_NEAR(vec(e, res, "c")[0], 0.1 + 0.5 * (0.35 + 0.2 * 0.2373046875), 1e-15);
    // zero gradient: unshaded
    in.gradient = glm::dvec3(0.0);
    in.material = {0.3, 0.2, 0.1};
    EXPECT_EQ(vec(explain::shade(in), res, "c"), (std::vector<double>{0.3, 0.2, 0.1}));
}

// ---- coordinates -------------------------------------------------------------------------------

// Cylindrical (r 2, theta 90, h 1) about (1, 0, 0): p = c + (2 cos 90, 1, -2 sin 90) = (1, 1, -2).
// Spherical of p - c = (0, 1, -2): R = sqrt(5), lon = atan2(2, 0) = 90, lat = atan2(1, 2) = 26.56505...
// Spherical (R 2, lon 180, lat 30) about 0: (2 cos 30 cos 180, 2 sin 30, -2 cos 30 sin 180) = (-sqrt(3), 1, 0);
// cylindrical r = sqrt(3), theta = 180, h = 1.
TEST(Explain, Coords) {
    Explanation e = explain::coords(explain::CoordinateSystem::Cylindrical, {2, 90, 1}, {1, 0, 0});
    const auto p = vec(e, "Cartesian", "(x, y, z)");
    EXPECT_NEAR(p[0], 1.0, 1e-15);
    EXPECT_NEAR(p[1], 1.0, 1e-15);
    EXPECT_NEAR(p[2], -2.0, 1e-15);
    const std::string sph = "spherical: p - center = (R cos lat cos lon, R sin lat, -R cos lat sin lon)";
    EXPECT_NEAR(e.value(sph, "R"), std::sqrt(5.0), 1e-15);
    EXPECT_NEAR(e.value(sph, "lon"), 90.0, 1e-13);
    EXPECT_NEAR(e.value(sph, "lat"), std::atan2(1.0, 2.0) * 180.0 / M_PI, 1e-13);
    e = explain::coords(explain::CoordinateSystem::Spherical, {2, 180, 30}, {0, 0, 0});
    const auto q = vec(e, "Cartesian", "(x, y, z)");
    EXPECT_NEAR(q[0], -std::sqrt(3.0), 1e-15);
    EXPECT_NEAR(q[1], 1.0, 1e-15);
    EXPECT_NEAR(q[2], 0.0, 1e-15);
    const std::string cyl = "cylindrical (axis y): p - center = (r cos theta, h, -r sin theta)";
    EXPECT_NEAR(e.value(cyl, "r"), std::sqrt(3.0), 1e-15);
    EXPECT_NEAR(e.value(cyl, "theta"), 180.0, 1e-13);
    EXPECT_NEAR(e.value(cyl, "h"), 1.0, 1e-15);
}

// ---- intersections -----------------------------------------------------------------------------

// Box [0,1] x [0,2] x [0,4]. Ray from (-1, -1, 0.5) along (1, 1, 0) / sqrt(2): x slab
// t in [sqrt(2), 2 sqrt(2)], y slab [sqrt(2), 3 sqrt(2)], z: direction 0, inside: every t.
// Interval [sqrt(2), 2 sqrt(2)]. From (-1, 5, 0.5) along +x: y = 5 outside, direction 0: no interval.
TEST(Explain, IntersectBox) {
    Ray ray;
    ray.origin = {-1, -1, 0.5};
    ray.direction = glm::normalize(glm::dvec3(1, 1, 0));
    const Explanation e = explain::intersect_box(ray, {0, 0, 0}, {1, 2, 4});
    const explain::Section& slabs = e.sections[2];
    ASSERT_EQ(slabs.rows.size(), 3u);
    EXPECT_NEAR(slabs.rows[0][1], std::sqrt(2.0), 1e-14);
    EXPECT_NEAR(slabs.rows[0][2], 2.0 * std::sqrt(2.0), 1e-14);
    EXPECT_NEAR(slabs.rows[1][2], 3.0 * std::sqrt(2.0), 1e-14);
    EXPECT_TRUE(std::isinf(slabs.rows[2][1]));
    const explain::Section& iv = e.find("intervals (t >= 0)");
    ASSERT_EQ(iv.rows.size(), 1u);
    EXPECT_NEAR(iv.rows[0][0], std::sqrt(2.0), 1e-14);
    EXPECT_NEAR(iv.rows[0][1], 2.0 * std::sqrt(2.0), 1e-14);
    ray.origin = {-1, 5, 0.5};
    ray.direction = {1, 0, 0};
    EXPECT_TRUE(explain::intersect_box(ray, {0, 0, 0}, {1, 2, 4}).find("intervals (t >= 0)").rows.empty());
}

// Cylinder r in [0.5, 1], full turn, h in [-1, 1]; ray from (-3, 0, 0) along +x: r = 1 at t = 2, 4,
// r = 0.5 at t = 2.5, 3.5, closest approach t = 3: intervals [2, 2.5] and [3.5, 4].
// Sphere r in [0.5, 1], latitude [0, 90] (the upper half); ray from (0, -3, 0) along +y: radii at
// t = 2, 2.5, 3.5, 4, the plane y = 0 at t = 3; only [3.5, 4] is in the upper half.
TEST(Explain, IntersectShells) {
    Ray ray;
    ray.origin = {-3, 0, 0};
    ray.direction = {1, 0, 0};
    CylindricalShell c;
    c.r0 = 0.5, c.r1 = 1.0, c.h0 = -1.0, c.h1 = 1.0;
    Explanation e = explain::intersect_cylinder(ray, c);
    const explain::Section& iv = e.find("intervals (t >= 0)");
    ASSERT_EQ(iv.rows.size(), 2u);
    EXPECT_NEAR(iv.rows[0][0], 2.0, 1e-14);
    EXPECT_NEAR(iv.rows[0][1], 2.5, 1e-14);
    EXPECT_NEAR(iv.rows[1][0], 3.5, 1e-14);
    EXPECT_NEAR(iv.rows[1][1], 4.0, 1e-14);
    const auto r1 = e.find("roots and extrema, in the order found (only finite t > 0 split the ray)").steps;
    ASSERT_GE(r1.size(), 6u);  // r1: extremum, 2 roots; r0: extremum, 2 roots
    EXPECT_NEAR(r1[0].value[0], 3.0, 1e-14);

    ray.origin = {0, -3, 0};
    ray.direction = {0, 1, 0};
    SphericalShell s;
    s.r0 = 0.5, s.r1 = 1.0, s.lat0 = 0.0, s.lat1 = 90.0;
    e = explain::intersect_sphere(ray, s);
    const explain::Section& iv2 = e.find("intervals (t >= 0)");
    ASSERT_EQ(iv2.rows.size(), 1u);
    EXPECT_NEAR(iv2.rows[0][0], 3.5, 1e-14);
    EXPECT_NEAR(iv2.rows[0][1], 4.0, 1e-14);
}

// ---- ray: the lecture scene ----------------------------------------------------------------------

// The lecture scene's pixel (32, 32): three samples at (0.8, 0.7, 0.2), (0.5, 0.5, 0.5), (0.2, 0.3, 0.8)
// (back to front: far first) with f = 5.0928, 4.9875, 4.9092 (worked above); the transfer function
// gives a = f - 4.5 and c = (f - 4.5, 0, 5.5 - f); each segment has length h = sqrt(0.22), so
// alpha_k = 1 - (1 - a_k)^h. The pixel, by the textbook front-to-back form with the front sample first:
// A = 1 - prod (1 - alpha_k), C = sum alpha_k c_k prod_{j < k} (1 - alpha_j).
TEST(Explain, RayThroughTheLectureScene) {
    const Scene scene = load_scene(kLevoyScene);
    const PreparedScene prepared(scene, {});
    const Explanation e = explain::ray(prepared, 32, 32);
    const explain::Section& s = e.sections[3];
    ASSERT_EQ(s.rows.size(), 3u);
    const double f[3] = {5.0928, 4.9875, 4.9092};
    const glm::dvec3 at[3] = {{0.8, 0.7, 0.2}, {0.5, 0.5, 0.5}, {0.2, 0.3, 0.8}};
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(s.rows[std::size_t(k)][5], f[k], 1e-12);
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(s.rows[std::size_t(k)][std::size_t(2 + a)], at[k][a], 1e-12);
    }
    const double h = std::sqrt(0.22);
    double T = 1.0;
    glm::dvec3 C(0.0);
    for (int k = 2; k >= 0; --k) {  // front (k = 2) to back
        const double a = f[k] - 4.5, alpha = 1.0 - std::pow(1.0 - a, h);
        C += T * alpha * glm::dvec3(a, 0.0, 5.5 - f[k]);
        T *= 1.0 - alpha;
    }
    const auto px = vec(e, "pixel", "RGBA");
    EXPECT_NEAR(px[0], C.r, 1e-12);
    EXPECT_EQ(px[1], 0.0);
    EXPECT_NEAR(px[2], C.b, 1e-12);
    EXPECT_NEAR(px[3], 1.0 - T, 1e-12);
}

// ---- the command line --------------------------------------------------------------------------

TEST(Explain, JsonHasTheSameNumbers) {
    const CliRun r = run_cli("explain trilinear --corners 5.0,5.1,5.2,4.6,4.9,5.1,5.3,4.7 --point 0.2,0.3,0.8 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("topic"), "trilinear");
    const Explanation e = explain::trilinear(kLevoy, {0.2, 0.3, 0.8});
    EXPECT_EQ(json_step(j, "result", "f").get<double>(), e.value("result", "f"));  // bitwise
    EXPECT_NEAR(json_step(j, "result", "f").get<double>(), 4.9092, 1e-14);
    EXPECT_NEAR(json_step(j, "x-lerps (Levoy's lecture)", "f43").get<double>(), 4.72, 1e-14);

    const CliRun c = run_cli("explain composite --samples 1,0,0,0.5 0,1,0,0.5 0,0,1,1 --step 0.5 --order back-to-front --json");
    ASSERT_EQ(c.status, 0) << c.err;
    const nlohmann::json k = nlohmann::json::parse(c.out);
    const auto& p = json_step(k, "both orders", "back to front");
    EXPECT_NEAR(p[1].get<double>(), std::sqrt(0.5) - 0.5, 1e-15);
    bool table = false;
    for (const auto& s : k.at("sections"))
        if (s.contains("rows")) {
            table = true;
            EXPECT_EQ(s.at("rows").size(), 3u);
            EXPECT_EQ(s.at("rows")[0].at("tau_k"), "inf");  // the opaque sample, composited first
        }
    EXPECT_TRUE(table);

    // The other topics through the same parsing (in process: one volref process per topic is slow).
    auto split = [](const std::string& line) {
        std::vector<std::string> v;
        std::istringstream in(line);
        for (std::string w; in >> w;) v.push_back(w);
        return v;
    };
    for (const std::string& args : std::vector<std::string>{
             "opacity-correction --opacity 0.5 --length 0.5", "classify-isovalue --value 0.9 --gradient 2 --contour 1,0.8,0.1",
             "classify-boundary --value 1.5 --gradient 0.5 --region 1,0.2 --region 2,0.8", "shade --normal 0,0,1",
             "coords --cylindrical 2,90,1", "intersect --origin -3,0,0 --direction 1,0,0 --cylinder --radius 0.5,1",
             "intersect --origin -1,0.5,0.5 --direction 1,0,0 --box 0,0,0,1,1,1",
             "ray --scene " + kLevoyScene + " --pixel 32,32"}) {
        std::vector<std::string> w = split(args);
        const std::string topic = w.front();
        w.erase(w.begin());
        const Explanation e = explain::from_arguments(topic, w);
        const nlohmann::json x = nlohmann::json::parse(explain::to_json(e));
        EXPECT_EQ(x.at("topic"), topic);
        EXPECT_EQ(x.at("sections").size(), e.sections.size()) << args;
        EXPECT_EQ(explain::to_text(e).rfind("volref explain " + topic + "\n", 0), 0u) << args;
    }
    // The numbers of the JSON are the explanation's (opacity-correction: alpha = 1 - sqrt(0.5)).
    const Explanation oc = explain::from_arguments("opacity-correction", {"--opacity", "0.5", "--length", "0.5"});
    const nlohmann::json oj = nlohmann::json::parse(explain::to_json(oc));
    EXPECT_EQ(json_step(oj, "volref (transfer/OpacityCorrection.h)", "alpha").get<double>(),
              oc.value("volref (transfer/OpacityCorrection.h)", "alpha"));
    EXPECT_NEAR(json_step(oj, "volref (transfer/OpacityCorrection.h)", "alpha").get<double>(), 1.0 - std::sqrt(0.5), 1e-15);
}

TEST(Explain, BadArgumentsAreOneLineErrorsNamingTheArgument) {
    const std::string corners = "--corners 5.0,5.1,5.2,4.6,4.9,5.1,5.3,4.7";
    const std::pair<std::string, std::string> cases[] = {
        {"trilinear --corners 1,2 --point 0.5,0.5,0.5", "--corners"},
        {"trilinear " + corners + " --point 0.5,0.5,2", "--point"},
        {"trilinear " + corners + " --point 0.5,x,0.5", "--point"},
        {"trilinear " + corners, "--point"},
        {"trilinear " + corners + " --point 0.5,0.5,0.5 --bogus 1", "--bogus"},
        {"composite --samples 1,0,0,1.5", "--samples"},
        {"composite --samples 1,0,0,0.5 --step 0", "--step"},
        {"composite --samples 1,0,0,0.5 --order sideways", "--order"},
        {"opacity-correction --opacity 0.5", "--length"},
        {"opacity-correction --opacity 2 --length 1", "--opacity"},
        {"classify-isovalue --value 1 --gradient -1 --contour 1,1,1", "--gradient"},
        {"classify-boundary --value 1 --gradient 1 --region 2,1 --region 1,1", "--region"},
        {"shade --normal 0,0,0", "--normal"},
        {"shade --normal 0,0,1 --model toon", "--model"},
        {"coords --cartesian 1,2", "--cartesian"},
        {"coords --spherical 1,0,100", "--spherical"},
        {"intersect --origin 0,0,0 --direction 1,0,0", "--box"},
        {"intersect --origin 0,0,0 --direction 0,0,0 --box 0,0,0,1,1,1", "--direction"},
        {"ray --scene " + kLevoyScene + " --pixel 65,0", "--pixel"},
        {"sideways --x 1", "unknown topic"},
    };
    for (const auto& [args, needle] : cases) {
        std::vector<std::string> w;
        std::istringstream in(args);
        for (std::string x; in >> x;) w.push_back(x);
        const std::string topic = w.front();
        w.erase(w.begin());
        try {
            (void)explain::from_arguments(topic, w);
            ADD_FAILURE() << args << ": no error";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find(needle), std::string::npos) << args << ": " << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << args << ": " << m;
        }
    }
    // On the command line: exit status 1 and one line on stderr.
    for (const std::string args : {"trilinear --corners 1,2 --point 0.5,0.5,0.5", "shade --normal 0,0,1 --model toon"}) {
        const CliRun r = run_cli("explain " + args);
        EXPECT_EQ(r.status, 1) << args << ": " << r.err;
        EXPECT_EQ(r.err.rfind("volref: error: --", 0), 0u) << args << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    }
}
