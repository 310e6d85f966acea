// Seed 001 (issue 17, part 3), worked by hand on one ray: its own ray span, and its data read as v / 65535.
// The span: rayIntersectTriangles takes
// inAbs = the smallest entry and outAbs = the largest exit over all triangles along the whole line
// (behind the eye too), then the kernel clamps inAbs = fmaxf(s, inAbs) to its image plane; the fallback
// 2 geomSize.x / length(rayVect) for a line with only an entry or only an exit is assigned without its
// flag, so such a ray is not rendered (conventions section 9, "cuda-curvilinear and seed 001"). On a
// closed boundary every line that meets it has both, and cuda-curvilinear's span [first t0, last t1]
// (t >= 0 from the ray's origin) is the seed's [fmaxf(0, inAbs), outAbs]: here with the eye inside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "TestScenes.h"
#include "core/scene/SceneLoader.h"

using namespace volref;
using namespace volref::test;

namespace {

// A full cylinder (R = 1, height 1, dims (4, 8, 2)), data = the radial index; one orthographic ray from
// (0, 0.5, 0.5), inside the cylinder (r = 0.5), along -z. bounds_extra: e.g. a tessellation.
std::string inside_scene(const std::string& bounds_extra, const std::string& projection) {
    std::string values;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 4; ++i) values += (values.empty() ? "" : ", ") + std::to_string(i);
    return R"({"volume": {"source": {"field": "cells", "dims": [4, 8, 2], "values": [)" + values + R"(]},
               "bounds": {"type": "cylindrical", "center": [0, 0, 0], "radius": [0, 1], "angle": [0, 360], "height": [0, 1])" +
           bounds_extra + R"(},
               "transfer": {"color": [[0, 1, 0, 0], [3, 0, 0, 1]], "opacity": [[0, 0.5], [3, 1]]}},
              "camera": {"type": "orthographic", "eye": [0, 0.5, 0.5], "target": [0, 0.5, -1], "up": [0, 1, 0], "height": 0.01},
              "image": {"width": 1, "height": 1},
              "render": {"projection": ")" + projection + R"(", "step": 0.25, "step_units": "world", "profile": "cuda-curvilinear",
                         "profile_options": {"kernel": "double"}}})";
}

glm::dvec4 render_json(const std::string& json) { return rgba(render_scene(parse_scene(json, ".", "test"), {1, false}), 0, 0); }

}  // namespace

// The line crosses the cylinder at z = 1 (t = -0.5, behind the eye) and z = -1 (t = 1.5): the seed's
// inAbs = fmaxf(0, -0.5) = 0, outAbs = 1.5; samples from the exit t = 1.5 - 0.25 k >= 0, k = 0 .. 6, at
// z = -1 + 0.25 k (not the 9 of the whole chord). interpolateCyl: x_r = 4 r, outVal past 3, else
// v = max(4 r - 0.5, 0); s = v / 3; the 9-entry table over [0, 3]: colour (1 - p/8, 0, p/8), opacity
// 0.5 + 0.5 p/8 at p = clamp(9 s - 0.5, 0, 8); sum = lerp(sum, col, col.a) in that order.
TEST(CudaSeedIntersection, EyeInsideTheCylinderByHand) {
    auto expected = [] {
        glm::dvec4 sum(0.0);
        for (int k = 0; k <= 6; ++k) {
            const double r = std::fabs(-1.0 + 0.25 * k);
            const double v = 4.0 * r > 3.0 ? 0.0 : std::max(4.0 * r - 0.5, 0.0);
            const double p = std::clamp(9.0 * v / 3.0 - 0.5, 0.0, 8.0);
            const glm::dvec4 col(1.0 - p / 8.0, 0.0, p / 8.0, 0.5 + 0.5 * p / 8.0);
            sum += (col - sum) * col.a;
        }
        return sum;
    }();
    for (const std::string& extra : {std::string(), std::string(R"(, "tessellate": 64)")}) {
        SCOPED_TRACE(extra);
        const glm::dvec4 p = render_json(inside_scene(extra, "composite"));
        EXPECT_NEAR(p.r, expected.r, 1e-9);
        EXPECT_NEAR(p.b, expected.b, 1e-9);
        EXPECT_NEAR(p.a, expected.a, 1e-9);
    }
}

// render.profile_options.texture_format "unorm16": seed 001's data texture holds the values normalised over
// the data range as unsigned shorts (readVtk: [0, 65535]; rounded to nearest here) and reads them as
// v / 65535. Cylinder R = 1, height 1, dims (4, 8, 2), radial data v_i = (0, 1, 2, 7) (s_i = v_i / 7), the
// ray across the height (x = 0, y = 0.5, along -z), step 0.25: samples at r = |z| in 0.25 steps; the
// largest s is at r = 0.75 (x_r = 3 = n - 1, texel position 2.5): (s_2 + s_3) / 2. With unorm16,
// s_2 = round(65535 * 2 / 7) / 65535 = 18724 / 65535 (2/7 = 18724.29 / 65535), s_3 = 1. X-ray: 0.8 times it.
TEST(CudaSeedIntersection, DataReadAsUnorm16ByHand) {
    std::string values;
    const int v[4] = {0, 1, 2, 7};
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 4; ++i) values += (values.empty() ? "" : ", ") + std::to_string(v[i]);
    auto scene = [&](const std::string& format) {
        return R"({"volume": {"source": {"field": "cells", "dims": [4, 8, 2], "values": [)" + values + R"(]},
                   "bounds": {"type": "cylindrical", "center": [0, 0, 0], "radius": [0, 1], "angle": [0, 360], "height": [0, 1]}},
                  "camera": {"type": "orthographic", "eye": [0, 0.5, 5], "target": [0, 0.5, 0], "up": [0, 1, 0], "height": 0.01},
                  "image": {"width": 1, "height": 1},
                  "render": {"projection": "xray", "step": 0.25, "step_units": "world", "profile": "cuda-curvilinear",
                             "profile_options": {"brightness": 0.8, "kernel": "double", "texture_format": ")" + format + R"("}}})";
    };
    EXPECT_NEAR(render_json(scene("float")).r, 0.8 * (2.0 / 7.0 + 1.0) / 2.0, 1e-12);
    const double q = 0.8 * (18724.0 / 65535.0 + 1.0) / 2.0;
    EXPECT_NEAR(render_json(scene("unorm16")).r, q, 1e-12);
    EXPECT_GT(std::fabs(q - 0.8 * (2.0 / 7.0 + 1.0) / 2.0), 1e-6);
    // On a box (no shell) the option is refused with the key's name.
    try {
        render_scene(parse_scene(R"({"volume": {"source": {"field": "constant", "value": 1, "dims": [3, 3, 3]}},
                                     "render": {"profile": "cuda-curvilinear", "profile_options": {"texture_format": "unorm16"}}})", ".", "t"),
                     {1, false});
        ADD_FAILURE() << "no error";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("render.profile_options.texture_format"), std::string::npos) << e.what();
    }
}
