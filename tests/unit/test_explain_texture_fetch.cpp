// `volref explain texture-fetch` (issue 27; core/explain/ExplainTextureFetch.cpp): one fetch's steps
// worked by hand, and the --points form against every fetch the H100 returned on the random volume
// (tests/data/h100-fetches), through the command line.
#include <gtest/gtest.h>

#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/Error.h"
#include "core/explain/ExplainArguments.h"

using namespace volref;

namespace {

const std::string kData = std::string(VOLREF_SOURCE_DIR) + "/tests/data/h100-fetches/";

explain::Explanation fetch(const std::vector<std::string>& args) { return explain::from_arguments("texture-fetch", args); }

std::string error_of(const std::vector<std::string>& args) {
    try {
        fetch(args);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// The first point of fetch3d_random_volume.csv, (9.48425293, 6.60173273, 4.08762169), on the u16 volume.
// By hand: t = x - 0.5 = (8.98425293, 6.10173273, 3.58762169), i0 = (8, 6, 3), a = floor(256 frac + 0.5):
// 251.969 -> 252, 26.044 -> 26, 150.431 -> 150. Z0 = 106, Z1 = 150. Slice 0: X1 = (252 * 106 + 128) >> 8 =
// 26840 >> 8 = 104, X0 = 2, w(1,1,0) = (26 * 104 + 128) >> 8 = 11, w(1,0,0) = 93, w(0,0,0) = (230 * 2 + 128)
// >> 8 = 2, w(0,1,0) = 0. Slice 1: X1 = (252 * 150 + 128) >> 8 = 148, X0 = 2, w(1,1,1) = (26 * 148 + 128) >> 8
// = 15, w(1,0,1) = 133, w(0,0,1) = 2, w(0,1,1) = 0. Texels (x, y, z) -> q: (8,6,3) 49021, (9,6,3) 47525,
// (9,7,3) 58639, (8,6,4) 14232, (9,6,4) 37526, (9,7,4) 63505 (the weighted ones). S = 2 * 49021 + 93 * 47525
// + 11 * 58639 + 2 * 14232 + 133 * 37526 + 15 * 63505 = 11134893, N = (S + 128) >> 8 = 43496,
// fetch = float32(43496 / 65535) = 0.663706422: what the H100 returned.
TEST(ExplainTextureFetch, OneUnorm16FetchByHand) {
    const auto e = fetch({"--unit", "h100", "--volume", kData + "random-volume-u16.nrrd", "--at", "9.48425293,6.60173273,4.08762169"});
    EXPECT_EQ(e.value("axis x", "i0"), 8.0);
    EXPECT_EQ(e.value("axis x", "a"), 252.0);
    EXPECT_EQ(e.value("axis y", "a"), 26.0);
    EXPECT_EQ(e.value("axis z", "a"), 150.0);
    const std::string cw = e.sections[4].title;
    EXPECT_EQ(e.value(cw, "Z0"), 106.0);
    EXPECT_EQ(e.value(cw, "X1,0"), 104.0);
    EXPECT_EQ(e.value(cw, "X1,1"), 148.0);
    const double w[8] = {2, 93, 0, 11, 2, 133, 0, 15};
    const char* names[8] = {"(0,0,0)", "(1,0,0)", "(0,1,0)", "(1,1,0)", "(0,0,1)", "(1,0,1)", "(0,1,1)", "(1,1,1)"};
    for (int c = 0; c < 8; ++c) EXPECT_EQ(e.value(cw, std::string("w") + names[c]), w[c]) << names[c];
    EXPECT_EQ(e.value("texels", "v(1,1,1)"), 63505.0);
    EXPECT_EQ(e.value("sum and rounding", "S"), 11134893.0);
    EXPECT_EQ(e.value("sum and rounding", "N"), 43496.0);
    EXPECT_EQ(e.value("result", "fetch"), double(0.663706422f));
    EXPECT_EQ(e.value("result", "fetch"), double(static_cast<float>(43496.0 / 65535.0)));
    // exact trilinear beside it, and the exact unit gives it (rounded to float32)
    const double exact = e.value("result", "exact");
    EXPECT_LT(std::fabs(exact - 0.663706422), 6e-3);
    const auto x = fetch({"--unit", "exact", "--volume", kData + "random-volume-u16.nrrd", "--at", "9.48425293,6.60173273,4.08762169"});
    EXPECT_EQ(x.value("result", "fetch"), double(static_cast<float>(exact)));
}

// The same point on the f32 volume: the H100 returned 0.489043504. The weights are the same; the slices'
// largest texels 0.86574596 and 0.23551361 (E = 0 and -2) keep 28 bits: truncated to multiples of 2^-28
// and 2^-30, their sum rounded once.
TEST(ExplainTextureFetch, OneFloatFetchAsTheH100) {
    const auto e = fetch({"--volume", kData + "random-volume-f32.nrrd", "--at", "9.48425293,6.60173273,4.08762169"});
    EXPECT_EQ(e.value("result", "fetch"), double(0.489043504f));
    EXPECT_EQ(e.value("texels", "E0"), 0.0);
    EXPECT_EQ(e.value("texels", "E1"), -2.0);
    for (const char* c : {"(0,0,0)", "(1,0,0)", "(1,1,0)"}) {
        const double v = e.value("texels", std::string("v'") + c);
        EXPECT_EQ(v, std::ldexp(std::trunc(std::ldexp(e.value("texels", std::string("v") + c), 28)), -28)) << c;
    }
    // normalised coordinates: u = x / n, cut to 20 bits: the same fetch here (x n 2^-20 moves t by < 2^-16)
    char at[128];
    std::snprintf(at, sizeof at, "%.17g,%.17g,%.17g", 9.48425293 / 16, 6.60173273 / 12, 4.08762169 / 10);
    const auto n = fetch({"--volume", kData + "random-volume-f32.nrrd", "--normalized", "--at", at});
    EXPECT_EQ(n.value("axis x", "a"), 252.0);
    EXPECT_EQ(n.value("axis z", "a"), 150.0);
    EXPECT_EQ(n.value("axis x", "u20"), std::floor(std::ldexp(double(float(9.48425293 / 16)), 20)) / 1048576.0);
    EXPECT_EQ(n.value("axis x", "x"), n.value("axis x", "u20") * 16.0);
}

TEST(ExplainTextureFetch, ErrorsNameTheOption) {
    EXPECT_NE(error_of({"--volume", kData + "random-volume-u16.nrrd"}).find("--at"), std::string::npos);
    EXPECT_NE(error_of({"--unit", "fast", "--volume", kData + "random-volume-u16.nrrd", "--at", "1,1,1"}).find("--unit"), std::string::npos);
    EXPECT_NE(error_of({"--volume", kData + "nope.nrrd", "--at", "1,1,1"}).find("nope.nrrd"), std::string::npos);
    EXPECT_NE(error_of({"--volume", kData + "random-volume-u16.nrrd", "--points", kData + "missing.csv"}).find("--points"), std::string::npos);
    // a volume of another type
    const std::string dir = testing::TempDir();
    const std::string path = dir + "/i16.nrrd";
    {
        std::ofstream o(path, std::ios::binary);
        o << "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nendian: little\n\n";
        const short v[8] = {0, 1, 2, 3, 4, 5, 6, 7};
        o.write(reinterpret_cast<const char*>(v), sizeof v);
    }
    EXPECT_NE(error_of({"--volume", path, "--at", "1,1,1"}).find("--volume"), std::string::npos);
    const std::string bad = dir + "/bad-points.csv";
    {
        std::ofstream o(bad);
        o << "x,y,z\n1,2,3\n1,2\n";
    }
    const std::string m = error_of({"--volume", kData + "random-volume-u16.nrrd", "--points", bad});
    EXPECT_NE(m.find("line 3"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

// --points through the command line: every fetch of the random volume, both formats, against the H100's
// values (printed with 9 significant digits, as the dump printed them).
TEST(ExplainTextureFetch, PointsThroughTheCommandLineAsTheH100) {
    gzFile f = gzopen((kData + "fetch3d_random_volume.csv.gz").c_str(), "rb");
    ASSERT_TRUE(f);
    std::vector<std::string> points;
    std::vector<float> gpu[2];
    char line[512];
    int n = 0;
    const std::string csv = testing::TempDir() + "/points.csv";
    std::ofstream out(csv);
    out << "x,y,z\n";
    while (gzgets(f, line, sizeof line)) {
        if (n++ < 2) continue;
        std::stringstream ss(line);
        std::string x, y, z, a, b;
        std::getline(ss, x, ',');
        std::getline(ss, y, ',');
        std::getline(ss, z, ',');
        std::getline(ss, a, ',');
        std::getline(ss, b, ',');
        out << x << ',' << y << ',' << z << '\n';
        gpu[0].push_back(std::stof(a));
        gpu[1].push_back(std::stof(b));
    }
    gzclose(f);
    out.close();
    ASSERT_EQ(gpu[0].size(), 50000u);
    for (int u = 0; u < 2; ++u) {
        const std::string cmd = std::string(VOLREF_CLI) + " explain texture-fetch --unit h100 --volume " + kData +
                                (u ? "random-volume-u16.nrrd" : "random-volume-f32.nrrd") + " --points " + csv;
        FILE* p = popen(cmd.c_str(), "r");
        ASSERT_TRUE(p);
        std::string text;
        char buf[4096];
        std::size_t got;
        while ((got = fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, got);
        ASSERT_EQ(pclose(p), 0);
        std::stringstream ss(text);
        std::string row;
        std::getline(ss, row);
        EXPECT_EQ(row, "x,y,z,fetch");
        std::size_t k = 0, same = 0;
        while (std::getline(ss, row)) {
            const float v = std::stof(row.substr(row.rfind(',') + 1));
            if (k < gpu[u].size()) same += v == gpu[u][k];
            ++k;
        }
        EXPECT_EQ(k, 50000u);
        EXPECT_EQ(same, 50000u) << (u ? "unorm16" : "float32");
    }
}
