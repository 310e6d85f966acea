// volref trace: every sample of one pixel's ray, recorded by the integrator's own loop
// (Integrator::integrate_traced, core/integrate/march/SampleRecorder.h; core/explain/PixelTrace.h).
// The last row is the rendered pixel; the rows follow the closed forms of sample placement
// (conventions section 4) and of the optical model (section 3).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "TestScenes.h"
#include "core/explain/PixelTrace.h"
#include "core/render/PreparedScene.h"
#include "core/scene/SceneLoader.h"

namespace fs = std::filesystem;
using namespace volref;

namespace {

// A Gaussian blob in a 33^3 grid: the corners are below the opacity ramp's start (0.3), so most
// macrocells are empty and empty-space skipping has something to skip.
Scene blob_scene(Projection projection, CompositeOrder order, bool shaded) {
    FieldSpec f;
    f.kind = FieldSpec::Kind::Gaussian;
    f.dims = {33, 33, 33};
    f.center = {16.0, 16.0, 16.0};
    f.sigma = 5.0;
    Scene s = test::field_scene(f);
    s.volume().transfer.opacity = {{0.0, 0.0}, {0.3, 0.0}, {1.0, 0.6}};
    s.volume().transfer.color = {{0.0, 0.1, 0.2, 0.9}, {1.0, 1.0, 0.8, 0.2}};
    s.volume().transfer.opacity_unit_distance = 2.0;
    if (shaded) {
        s.volume().shading = ShadingSpec{};
        LightSpec d;
        d.type = LightSpec::Type::Directional;
        d.direction = glm::normalize(glm::dvec3(1.0, 1.0, 1.0));
        d.color = {0.5, 0.4, 0.3};
        s.lights.push_back(d);
    }
    s.image.width = 16;
    s.image.height = 16;
    s.render.projection = projection;
    s.render.order = order;
    s.render.step = 0.7;
    return s;
}

glm::dvec4 pixel(const Image& im, int x, int y) { return test::rgba(im, x, y); }

// Trace pixel (x, y) and check its last row against the image rendered by the scalar path (bitwise)
// and by the default (SIMD where available) path (1e-12).
void expect_last_row_is_pixel(const Scene& scene, bool skipping, int x, int y) {
    RenderOptions options;
    options.empty_space_skipping = skipping;
    const PreparedScene prepared(scene, options);
    const explain::PixelTrace t = explain::trace_pixel(prepared, x, y);
    ASSERT_FALSE(t.samples.empty());
    const glm::dvec4 last = t.samples.back().record.accumulated;
    for (int c = 0; c < 4; ++c) EXPECT_EQ(last[c], t.pixel.rgba[c]) << c;

    RenderOptions scalar = options;
    scalar.simd = false;
    scalar.threads = 1;
    const glm::dvec4 rendered = pixel(render_scene(scene, scalar), x, y);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(last[c], rendered[c]) << "channel " << c;
    RenderOptions simd = options;
    simd.threads = 1;
    const glm::dvec4 packet = pixel(render_scene(scene, simd), x, y);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(last[c], packet[c], 1e-12) << "channel " << c;
    EXPECT_GT(last.a, 0.0);  // the pixel sees the blob, so the comparison means something
}

}  // namespace

TEST(Trace, LastRowIsTheRenderedPixelComposite) {
    for (const CompositeOrder order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront})
        for (const bool shaded : {false, true})
            for (const bool skipping : {false, true}) {
                SCOPED_TRACE(::testing::Message() << "order " << int(order) << " shaded " << shaded << " skipping " << skipping);
                const Scene s = blob_scene(Projection::Composite, order, shaded);
                expect_last_row_is_pixel(s, skipping, 8, 8);
                expect_last_row_is_pixel(s, skipping, 6, 9);
            }
}

// Pre-classification, tricubic reconstruction and early termination go through the same loop.
TEST(Trace, LastRowIsTheRenderedPixelForOtherPipelines) {
    Scene pre = blob_scene(Projection::Composite, CompositeOrder::FrontToBack, true);
    pre.volume().classify = VolumeSpec::Classify::Pre;
    expect_last_row_is_pixel(pre, true, 8, 8);
    Scene cubic = blob_scene(Projection::Composite, CompositeOrder::BackToFront, true);
    cubic.volume().interpolation = Interpolation::TricubicCatmullRom;
    expect_last_row_is_pixel(cubic, true, 7, 8);
    Scene early = blob_scene(Projection::Composite, CompositeOrder::FrontToBack, false);
    early.render.early_termination = 0.3;
    early.volume().transfer.opacity = {{0.0, 0.0}, {0.3, 0.0}, {1.0, 1.0}};
    expect_last_row_is_pixel(early, true, 8, 8);
    const PreparedScene p(early, {});
    const explain::PixelTrace t = explain::trace_pixel(p, 8, 8);
    // the loop stopped after the first sample where A exceeds 0.3: the rows end there
    EXPECT_GT(t.samples.back().record.accumulated.a, 0.3);
    EXPECT_LE(t.samples[t.samples.size() - 2].record.accumulated.a, 0.3);
    EXPECT_LT(t.samples.back().record.t1, t.intervals.back().t1);
}

TEST(Trace, SkippingLeavesOutOnlyTransparentSamples) {
    const Scene s = blob_scene(Projection::Composite, CompositeOrder::FrontToBack, false);
    RenderOptions on, off;
    off.empty_space_skipping = false;
    const PreparedScene a(s, on), b(s, off);
    ASSERT_NE(a.volume().macrocells, nullptr);  // the scene has empty macrocells
    const explain::PixelTrace ta = explain::trace_pixel(a, 8, 8), tb = explain::trace_pixel(b, 8, 8);
    EXPECT_LT(ta.samples.size(), tb.samples.size());
    std::size_t j = 0;  // every row with skipping is a row without, at the same t, with the same numbers
    for (const explain::TracedSample& r : ta.samples) {
        while (j < tb.samples.size() && tb.samples[j].record.t != r.record.t) {
            EXPECT_EQ(tb.samples[j].record.sample.opacity, 0.0);  // skipped: transparent
            ++j;
        }
        ASSERT_LT(j, tb.samples.size());
        EXPECT_EQ(tb.samples[j].record.alpha, r.record.alpha);
        EXPECT_EQ(tb.samples[j].record.accumulated, r.record.accumulated);
        ++j;
    }
}

TEST(Trace, LastRowIsTheRenderedPixelOtherProjections) {
    for (const Projection p : {Projection::Mip, Projection::Minip, Projection::Average, Projection::Xray}) {
        SCOPED_TRACE(explain::projection_name(p));
        Scene s = blob_scene(p, CompositeOrder::FrontToBack, false);
        s.render.gain = 0.25;
        s.volume().transfer.opacity = {{0.0, 0.1}, {1.0, 0.6}};  // minip's minimum has opacity > 0 too
        expect_last_row_is_pixel(s, true, 8, 8);
        expect_last_row_is_pixel(s, true, 3, 12);
    }
}

TEST(Trace, RunningValuesOfMipAndXray) {
    Scene s = blob_scene(Projection::Mip, CompositeOrder::FrontToBack, false);
    const PreparedScene mip(s, {});
    const explain::PixelTrace t = explain::trace_pixel(mip, 8, 8);
    double best = -INFINITY;
    for (const explain::TracedSample& r : t.samples) {
        best = std::max(best, r.record.sample.value);
        EXPECT_EQ(r.record.running, best);  // the maximum so far
    }
    s.render.projection = Projection::Xray;
    s.render.gain = 2.0;
    const PreparedScene xray(s, {});
    const explain::PixelTrace x = explain::trace_pixel(xray, 8, 8);
    double sum = 0.0;
    for (const explain::TracedSample& r : x.samples) {
        sum += r.record.sample.value * r.record.length;  // data domain: s(v) = v
        EXPECT_NEAR(r.record.running, 2.0 * sum, 1e-12 * (1.0 + sum));
    }
}

// A constant field (value 1, opacity a = 0.2 per unit distance 1) in the box [0, 4]^3, seen along the
// diagonal (1, 1, 1) / sqrt(3) from (-1, -1, -1): the chord is t in [sqrt(3), 5 sqrt(3)], length
// 4 sqrt(3) = 6.928; with step h = 0.5 there are n = ceil(6.928 / 0.5) = 14 segments, 13 of length 0.5
// and the last 6.928 - 6.5 = 0.428. After the segments up to t, T = 0.8^(t - sqrt(3)).
TEST(Trace, RowsFollowTheClosedFormsOfABox) {
    Scene s = test::field_scene(test::constant_field(1.0, {5, 5, 5}));
    s.volume().transfer.opacity = {{0.0, 0.2}};
    s.volume().transfer.color = {{0.0, 0.5, 0.25, 1.0}};
    s.camera.type = CameraSpec::Type::Orthographic;
    s.camera.eye = {-1.0, -1.0, -1.0};
    s.camera.target = {2.0, 2.0, 2.0};
    s.camera.up = {0.0, 0.0, 1.0};
    s.image.width = s.image.height = 1;
    s.render.step = 0.5;
    s.render.step_units = StepUnits::World;
    const double r3 = std::sqrt(3.0);
    for (const CompositeOrder order : {CompositeOrder::FrontToBack, CompositeOrder::BackToFront}) {
        s.render.order = order;
        const PreparedScene p(s, {});
        const explain::PixelTrace t = explain::trace_pixel(p, 0, 0);
        ASSERT_EQ(t.samples.size(), 14u);
        const bool ftb = order == CompositeOrder::FrontToBack;
        const explain::TracedSample& front = ftb ? t.samples.front() : t.samples.back();
        const explain::TracedSample& back = ftb ? t.samples.back() : t.samples.front();
        EXPECT_NEAR(front.record.t0, r3, 1e-12);
        EXPECT_NEAR(back.record.t1, 5.0 * r3, 1e-12);
        EXPECT_NEAR(back.record.length, 4.0 * r3 - 6.5, 1e-12);
        for (const explain::TracedSample& row : t.samples) {
            const SampleRecord& r = row.record;
            // alpha = 1 - (1 - a)^(d / l): the textbook form, against volref's expm1/log1p form.
            EXPECT_NEAR(r.alpha, 1.0 - std::pow(0.8, r.length), 1e-15);
            EXPECT_NEAR(r.transmittance_after, r.transmittance_before * (1.0 - r.alpha), 1e-15);
            // Front to back: T is the transmittance from the chord's entry; back to front: from the exit.
            const double behind = ftb ? r.t1 - r3 : 5.0 * r3 - r.t0;
            EXPECT_NEAR(r.transmittance_after, std::pow(0.8, behind), 1e-14);
            EXPECT_NEAR(r.accumulated.a, 1.0 - std::pow(0.8, behind), 1e-14);
            // emission in proportion to absorption: C = A c for a constant colour
            EXPECT_NEAR(r.accumulated.r, 0.5 * (1.0 - std::pow(0.8, behind)), 1e-14);
            EXPECT_NEAR(r.accumulated.b, 1.0 * (1.0 - std::pow(0.8, behind)), 1e-14);
            // the grid location: u = x for unit spacing and zero origin
            for (int a = 0; a < 3; ++a) {
                EXPECT_NEAR(row.grid.index[a], r.sample.position[a], 1e-12);
                EXPECT_EQ(row.grid.cell[std::size_t(a)], std::min<std::int64_t>(3, std::int64_t(std::floor(r.sample.position[a]))));
            }
        }
        // consecutive rows hand the transmittance on
        for (std::size_t k = 1; k < t.samples.size(); ++k)
            EXPECT_EQ(t.samples[k].record.transmittance_before, t.samples[k - 1].record.transmittance_after);
        EXPECT_NEAR(t.pixel.rgba.a, 1.0 - std::pow(0.8, 4.0 * r3), 1e-14);
    }
}

// Shaded rows: ambient = I ka m for each light; the shaded colour is the sum of the lights' terms.
TEST(Trace, ShadingTermsAddUpToTheShadedColour) {
    const Scene s = blob_scene(Projection::Composite, CompositeOrder::FrontToBack, true);
    const PreparedScene p(s, {});
    const explain::PixelTrace t = explain::trace_pixel(p, 8, 8);
    ASSERT_EQ(t.lights, 2u);
    int shaded = 0;
    for (const explain::TracedSample& row : t.samples) {
        const SampleDetail& d = row.record.sample;
        if (!d.shaded) {
            EXPECT_EQ(d.opacity, 0.0);  // only transparent samples are left unshaded
            continue;
        }
        ++shaded;
        ASSERT_TRUE(d.has_gradient);
        ASSERT_EQ(d.shading.lights.size(), 2u);
        EXPECT_NEAR(d.shading.lights[0].ambient.r, 0.1 * d.classified_color.r, 1e-15);  // headlight, I = 1
        EXPECT_NEAR(d.shading.lights[1].ambient.g, 0.4 * 0.1 * d.classified_color.g, 1e-15);
        EXPECT_NEAR(d.shading.lights[0].n_dot_l, std::max(0.0, -glm::dot(d.gradient, -t.ray.direction) / glm::length(d.gradient)),
                    1e-14);
        glm::dvec3 sum(0.0);
        for (const LightTerms& l : d.shading.lights) sum += l.ambient + l.diffuse + l.specular;
        EXPECT_EQ(sum, d.color);
    }
    EXPECT_GT(shaded, 0);
}

TEST(Trace, FirstHitAndBadPixelsAreErrors) {
    Scene s = blob_scene(Projection::FirstHit, CompositeOrder::FrontToBack, false);
    s.render.isovalue = 0.5;
    const PreparedScene p(s, {});
    try {
        explain::trace_pixel(p, 8, 8);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "trace: first-hit is not supported yet");
    }
    Scene adaptive = blob_scene(Projection::Composite, CompositeOrder::FrontToBack, false);
    adaptive.render.integrator = IntegrationMethod::Adaptive;
    const PreparedScene pa(adaptive, {});
    try {
        explain::trace_pixel(pa, 8, 8);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("trace: render.integrator \"adaptive\" is not supported yet", 0), 0u) << e.what();
    }
    EXPECT_THROW(explain::parse_pixel("16,3", 16, 16), Error);
    EXPECT_THROW(explain::parse_pixel("3", 16, 16), Error);
    EXPECT_THROW(explain::parse_pixel("3,x", 16, 16), Error);
    EXPECT_EQ(explain::parse_pixel("15,0", 16, 16), (std::array<int, 2>{15, 0}));
}

// ---- the command line ------------------------------------------------------------------------

namespace {

struct CliRun {
    int status;
    std::string out, err;
};

CliRun run_cli(const std::string& args) {
    const fs::path dir = fs::temp_directory_path() / ("volref-trace-" + std::to_string(::getpid()));
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

const std::string kShadedScene = std::string(VOLREF_SOURCE_DIR) + "/reference_scenes/levoy-isosurfaces.json";

}  // namespace

TEST(Trace, CsvHeaderAndRows) {
    const std::string scene = std::string(VOLREF_SOURCE_DIR) + "/reference_scenes/levoy-lecture.json";
    const CliRun r = run_cli("trace " + scene + " --pixel 32,32");
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream in(r.out);
    std::string header, line;
    std::getline(in, header);
    EXPECT_EQ(header,
              "sample,interval,segment,t0,t1,t,length,x,y,z,u0,u1,u2,cell_i,cell_j,cell_k,local_p,local_q,local_r,value,class_r,class_g,"
              "class_b,opacity,tau,alpha,transmittance_before,transmittance_after,acc_r,acc_g,acc_b,acc_a");
    std::vector<std::vector<std::string>> rows;
    while (std::getline(in, line)) {
        rows.emplace_back();
        std::stringstream ls(line);
        std::string cell;
        while (std::getline(ls, cell, ',')) rows.back().push_back(cell);
    }
    ASSERT_EQ(rows.size(), 3u);  // the lecture's three samples, back to front
    // sample 0 is the far one, at (0.8, 0.7, 0.2): f = 5.0928 (docs/explain.md works it by hand)
    EXPECT_NEAR(std::stod(rows[0][19]), 5.0928, 1e-12);
    EXPECT_NEAR(std::stod(rows[1][19]), 4.9875, 1e-12);
    EXPECT_NEAR(std::stod(rows[2][19]), 4.9092, 1e-12);
    for (const auto& row : rows) EXPECT_EQ(row.size(), 32u);
    // issue 29: one interval of three segments, listed back to front: segments 2, 1, 0 of interval 0
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(rows[std::size_t(k)][1], "0");
        EXPECT_EQ(rows[std::size_t(k)][2], std::to_string(2 - k));
    }
}

TEST(Trace, JsonStructureOfAShadedScene) {
    const CliRun r = run_cli("trace " + kShadedScene + " --format json --pixel 12,12 --set image.width=24 --set image.height=24");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["projection"], "composite");
    EXPECT_EQ(j["pixel"], nlohmann::json::array({12, 12}));
    ASSERT_TRUE(j["samples"].is_array());
    ASSERT_FALSE(j["samples"].empty());
    int shaded = 0;
    for (const auto& s : j["samples"]) {
        for (const char* key : {"t0", "t1", "t", "length", "position", "grid", "value", "classified", "tau", "alpha",
                                "transmittance_before", "transmittance_after", "accumulated"})
            EXPECT_TRUE(s.contains(key)) << key;
        if (s.contains("shading")) {
            ++shaded;
            EXPECT_TRUE(s.contains("gradient"));
            EXPECT_FALSE(s["shading"]["lights"].empty());
        }
    }
    EXPECT_GT(shaded, 0);
    EXPECT_EQ(j["samples"].back()["accumulated"], j["pixel_value"]);
}

TEST(Trace, CommandLineErrorsAreOneLine) {
    const std::string scene = std::string(VOLREF_SOURCE_DIR) + "/reference_scenes/sphere-first-hit.json";
    CliRun r = run_cli("trace " + scene + " --pixel 1,1");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "volref: error: trace: first-hit is not supported yet\n");
    r = run_cli("trace " + kShadedScene + " --pixel 1000,1");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.rfind("volref: error: --pixel:", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
    r = run_cli("trace " + kShadedScene + " --pixel 1,1 --format xml");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.rfind("volref: error: --format:", 0), 0u) << r.err;
}

// On a beam-space grid the grid columns are the shell's: a full-turn cylinder r in [0, 10] (11 samples,
// u0 = r), theta in [0, 360) (36 samples, periodic, u1 = theta / 10), h in [0, 3] (4 samples, u2 = h);
// the cell is min(floor(u), n - 2) on r and h and floor(u) on the periodic angle (cell 35 runs over the
// seam back to sample 0), the local coordinates u - cell.
TEST(Trace, GridColumnsOnACylindricalShell) {
    Scene s = test::field_scene(test::constant_field(1.0, {11, 36, 4}));
    s.volume().origin.reset();
    s.volume().spacing.reset();
    s.volume().bounds.type = BoundsSpec::Type::Cylindrical;
    s.volume().bounds.cylinder.r1 = 10.0;
    s.volume().bounds.cylinder.h1 = 3.0;
    s.volume().transfer.opacity = {{0.0, 0.05}};
    s.image.width = s.image.height = 16;
    const PreparedScene p(s, {});
    for (const auto& px : {std::array<int, 2>{5, 8}, std::array<int, 2>{11, 7}}) {
        const explain::PixelTrace t = explain::trace_pixel(p, px[0], px[1]);
        ASSERT_FALSE(t.samples.empty());
        for (const explain::TracedSample& row : t.samples) {
            const glm::dvec3 x = row.record.sample.position;
            const double r = std::hypot(x.x, x.z);
            double theta = std::atan2(-x.z, x.x) * 180.0 / M_PI;
            if (theta < 0.0) theta += 360.0;
            EXPECT_NEAR(row.grid.index[0], r, 1e-9);
            EXPECT_NEAR(row.grid.index[1], theta / 10.0, 1e-9);
            EXPECT_NEAR(row.grid.index[2], x.y, 1e-9);
            EXPECT_EQ(row.grid.cell[0], std::min<std::int64_t>(9, std::int64_t(std::floor(row.grid.index[0]))));
            EXPECT_EQ(row.grid.cell[1], std::int64_t(std::floor(row.grid.index[1])));
            EXPECT_EQ(row.grid.cell[2], std::min<std::int64_t>(2, std::int64_t(std::floor(row.grid.index[2]))));
            for (int a = 0; a < 3; ++a)
                EXPECT_NEAR(row.grid.local[a], row.grid.index[a] - double(row.grid.cell[std::size_t(a)]), 1e-12);
        }
    }
}
