// volref info and volref convert through the command line: the summary of a small VolPack file laid
// out here (numbers worked by hand), exact round trips convert -> read_volume, and bad input (one line
// on stderr, exit status 1, no output file).
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/io/VolumeReader.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct CliRun {
    int status;
    std::string out, err;
};

class FormatsCli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("volref-formats-cli-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    static std::string slurp(const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    }
    CliRun run(const std::string& args) const {
        const std::string cmd = std::string(VOLREF_CLI) + " " + args + " > " + (dir_ / "out.txt").string() + " 2> " +
                                (dir_ / "err.txt").string();
        const int raw = std::system(cmd.c_str());
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir_ / "out.txt"), slurp(dir_ / "err.txt")};
    }
    fs::path write(const std::string& name, const std::string& bytes) const {
        std::ofstream(dir_ / name, std::ios::binary) << bytes;
        return dir_ / name;
    }
    // Failure with one line "volref: error: ..." containing `needle`, and none of `outputs` written.
    void expect_error(const std::string& args, const std::string& needle, const std::vector<fs::path>& outputs) const {
        const CliRun r = run(args);
        EXPECT_EQ(r.status, 1) << args;
        EXPECT_THAT(r.err, HasSubstr(needle));
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_EQ(r.err.rfind("volref: error: ", 0), 0u) << r.err;
        for (const fs::path& p : outputs) EXPECT_FALSE(fs::exists(p)) << p;
        for (const auto& e : fs::directory_iterator(dir_))
            EXPECT_EQ(e.path().filename().string().find(".volref-tmp"), std::string::npos) << e.path();
    }
    fs::path dir_;
};

// A 3 x 2 x 2 VolPack file, little endian, samples 0, 20, ..., 220 (i fastest).
std::string den_file() {
    std::string h(62, '\0');
    h[0] = 1;                                   // map_version 1
    h[50] = 3, h[52] = 2, h[54] = 2;            // map_len
    h[58] = 12;                                 // map_length
    for (int n = 0; n < 12; ++n) h += char(20 * n);
    return h;
}

// A NIfTI-1 file: 2 x 3 x 2 i16 values -7, 100, ..., big endian, sform with x flipped (spacing 0.5)
// and an offset, so that the volume is reordered and placed.
std::string nifti_file() {
    std::string h(352, '\0');
    const auto put16 = [&](std::size_t at, std::int16_t v) { h[at] = char((v >> 8) & 0xff), h[at + 1] = char(v & 0xff); };
    const auto put32 = [&](std::size_t at, std::uint32_t v) {
        for (int b = 0; b < 4; ++b) h[at + std::size_t(b)] = char((v >> (24 - 8 * b)) & 0xff);
    };
    const auto putf = [&](std::size_t at, float v) { put32(at, std::bit_cast<std::uint32_t>(v)); };
    put32(0, 348);
    const std::int16_t dim[8] = {3, 2, 3, 2, 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) put16(40 + 2 * std::size_t(i), dim[i]);
    put16(70, 4), put16(72, 16);  // INT16
    for (int i = 0; i < 8; ++i) putf(76 + 4 * std::size_t(i), 1.0f);
    putf(108, 352.0f);
    put16(254, 1);  // sform_code
    const float rows[3][4] = {{-0.5f, 0, 0, 3}, {0, 1, 0, -2}, {0, 0, 2, 0.25f}};
    for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 4; ++c) putf(280 + 16 * r + 4 * c, rows[r][c]);
    h.replace(344, 4, std::string("n+1\0", 4));
    for (int n = 0; n < 12; ++n) {
        const std::int16_t v = std::int16_t(n * 107 - 7);
        h += char((v >> 8) & 0xff);
        h += char(v & 0xff);
    }
    return h;
}

}  // namespace

TEST_F(FormatsCli, InfoTextAndJson) {
    const fs::path p = write("v.den", den_file());
    CliRun r = run("info " + p.string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("format:   den"));
    EXPECT_THAT(r.out, HasSubstr("dims:     3 x 2 x 2 (12 voxels)"));
    EXPECT_THAT(r.out, HasSubstr("type:     u8"));
    EXPECT_THAT(r.out, HasSubstr("spacing:  1 1 1"));
    EXPECT_THAT(r.out, HasSubstr("origin:   0 0 0"));
    EXPECT_THAT(r.out, HasSubstr("range:    0 .. 220"));
    EXPECT_THAT(r.out, HasSubstr("16 bins of width 13.75"));  // 220 / 16

    r = run("info " + p.string() + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["dims"], nlohmann::json::parse("[3, 2, 2]"));
    EXPECT_EQ(j["type"], "u8");
    EXPECT_EQ(j["range"], nlohmann::json::parse("[0.0, 220.0]"));
    // Value 20 n goes to bin floor(20 n / 13.75) = floor(1.4545 n): n = 0..11 -> 0 1 2 4 5 7 8 10 11 13 14 15.
    EXPECT_EQ(j["histogram"]["counts"], nlohmann::json::parse("[1,1,1,0,1,1,0,1,1,0,1,1,0,1,1,1]"));

    r = run("info " + p.string() + " --json --bins 2");
    EXPECT_EQ(nlohmann::json::parse(r.out)["histogram"]["counts"], nlohmann::json::parse("[6, 6]"));  // < 110, >= 110
}

TEST_F(FormatsCli, ConvertRoundTripsExactly) {
    const fs::path in = write("head.nii", nifti_file());
    const volref::Volume original = volref::read_volume(in);
    ASSERT_EQ(original.origin, glm::dvec3(2.5, -2, 0.25));  // x flipped: 3 - 0.5 * (2 - 1)
    ASSERT_EQ(original.at(0, 0, 0), 100.0);                  // file voxel (1, 0, 0): 1 * 107 - 7

    for (const std::string& extra : {std::string(""), std::string(" --encoding gzip")}) {
        const fs::path nrrd = dir_ / "out.nrrd";
        CliRun r = run("convert " + in.string() + " " + nrrd.string() + extra);
        ASSERT_EQ(r.status, 0) << r.err;
        const volref::Volume a = volref::read_volume(nrrd);
        EXPECT_EQ(a.dims, original.dims);
        EXPECT_EQ(a.origin, original.origin);
        EXPECT_EQ(a.spacing, original.spacing);
        EXPECT_EQ(a.values, original.values);
        EXPECT_EQ(a.type, volref::ScalarType::I16);  // NRRD keeps the input's type too (issue 18)

        const fs::path raw = dir_ / "out.raw";
        r = run("convert " + in.string() + " " + raw.string() + extra);
        ASSERT_EQ(r.status, 0) << r.err;
        const volref::Volume b = volref::read_volume(raw);
        EXPECT_EQ(b.dims, original.dims);
        EXPECT_EQ(b.origin, original.origin);
        EXPECT_EQ(b.spacing, original.spacing);
        EXPECT_EQ(b.values, original.values);
        EXPECT_EQ(b.type, volref::ScalarType::I16);  // raw keeps the input's type by default
    }
    // Every type NRRD and raw can hold, through NRRD: the values read back exactly, in that type, and
    // the data takes its size per voxel (2 bytes for u16, where it used to be written as 8-byte doubles).
    for (const std::string t : {"i16", "i32", "f32", "f64"}) {
        const fs::path nrrd = dir_ / ("typed-" + t + ".nrrd");
        const CliRun r = run("convert " + in.string() + " " + nrrd.string() + " --type " + t);
        ASSERT_EQ(r.status, 0) << r.err;
        const volref::Volume v = volref::read_volume(nrrd);
        EXPECT_EQ(v.values, original.values) << t;
        EXPECT_EQ(volref::scalar_type_name(v.type), t);
    }
    // An explicit wider type holds the values exactly too.
    const fs::path wide = dir_ / "wide.raw";
    ASSERT_EQ(run("convert " + in.string() + " " + wide.string() + " --type i32").status, 0);
    EXPECT_EQ(volref::read_volume(wide).values, original.values);
    EXPECT_EQ(volref::read_volume(wide).type, volref::ScalarType::I32);
}

TEST_F(FormatsCli, BadInputOneLineNoOutput) {
    const fs::path in = write("head.nii", nifti_file());
    expect_error("convert " + in.string() + " " + (dir_ / "out.png").string(), "the output must be .nrrd", {dir_ / "out.png"});
    expect_error("convert " + in.string() + " " + (dir_ / "out.nrrd").string() + " --type u8",
                 "value -7 at voxel (1, 0, 0) is not an integer in the range of u8", {dir_ / "out.nrrd"});
    // -7 does not fit in u8: neither the data nor the sidecar appear.
    expect_error("convert " + in.string() + " " + (dir_ / "out.raw").string() + " --type u8",
                 "value -7 at voxel (1, 0, 0) is not an integer in the range of u8", {dir_ / "out.raw", dir_ / "out.raw.json"});
    expect_error("convert " + in.string() + " " + (dir_ / "out.raw").string() + " --encoding bz2", "--encoding",
                 {dir_ / "out.raw"});
    const fs::path bad = write("bad.den", den_file().substr(0, 70));
    expect_error("convert " + bad.string() + " " + (dir_ / "o.nrrd").string(), bad.string() + ": truncated", {dir_ / "o.nrrd"});
    expect_error("info " + bad.string(), bad.string() + ": truncated: expected 12 bytes of data, found 8", {});
    expect_error("info " + in.string() + " --format png", "unknown volume format 'png'", {});
}
