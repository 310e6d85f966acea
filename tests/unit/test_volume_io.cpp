// Tests of read_volume (core/io): NRRD and raw + JSON sidecar files written here byte by byte, read
// back and compared with the numbers written; and every error, by its message.
#include <unistd.h>
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/io/VolumeReader.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;
using volref::ScalarType;
using volref::Volume;

// ---- writing test files ----

// The bytes of `value` in byte order `order`, built from shifts of its bit pattern (independent of
// how the reader swaps bytes).
template <typename T>
std::string to_bytes(T value, std::endian order) {
    using U = std::conditional_t<
        sizeof(T) == 1, std::uint8_t,
        std::conditional_t<sizeof(T) == 2, std::uint16_t,
                           std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
    const auto bits = static_cast<std::uint64_t>(std::bit_cast<U>(value));
    std::string out(sizeof(T), '\0');
    for (std::size_t i = 0; i < sizeof(T); ++i) {
        const char byte = char((bits >> (8 * i)) & 0xff);  // i-th least significant byte
        out[order == std::endian::little ? i : sizeof(T) - 1 - i] = byte;
    }
    return out;
}

template <typename T>
std::string to_bytes(const std::vector<T>& values, std::endian order) {
    std::string out;
    for (T v : values) out += to_bytes(v, order);
    return out;
}

// `data` compressed as one gzip member (or a zlib stream when `gzip_wrapper` is false).
std::string compress(const std::string& data, bool gzip_wrapper = true) {
    z_stream zs{};
    EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, gzip_wrapper ? 15 + 16 : 15, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&zs, uLong(data.size())) + 64, '\0');
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    zs.avail_in = uInt(data.size());
    zs.next_out = reinterpret_cast<Bytef*>(out.data());
    zs.avail_out = uInt(out.size());
    EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
    out.resize(zs.total_out);
    deflateEnd(&zs);
    return out;
}

// A NRRD header: the magic, the lines, and (for attached data) the blank line that ends it.
std::string nrrd(const std::vector<std::string>& lines, bool blank_line = true,
                 const std::string& magic = "NRRD0004") {
    std::string text = magic + "\n";
    for (const auto& line : lines) text += line + "\n";
    return blank_line ? text + "\n" : text;
}

const char* endian_name(std::endian e) { return e == std::endian::little ? "little" : "big"; }

// ---- checking ----

// True when a and b are the same double, bit for bit (so -0.0 != 0.0), or both nan.
bool same_double(double a, double b) {
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
    return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

void expect_values(const Volume& v, const std::vector<double>& expected) {
    ASSERT_EQ(v.values.size(), expected.size());
    // Kept in the file's type: as many bytes in memory as the file's samples.
    EXPECT_EQ(v.values.type(), v.type);
    EXPECT_EQ(v.values.bytes(), expected.size() * scalar_type_size(v.type));
    for (std::size_t i = 0; i < expected.size(); ++i)
        EXPECT_TRUE(same_double(v.values[i], expected[i]))
            << "value " << i << ": got " << v.values[i] << ", wrote " << expected[i];
}

void expect_vec(const glm::dvec3& got, double x, double y, double z) {
    EXPECT_EQ(got.x, x);
    EXPECT_EQ(got.y, y);
    EXPECT_EQ(got.z, z);
}

// The message of the volref::Error that `read` throws; a test failure if it throws nothing or
// something else, or if the message is not one line.
std::string error_message(const std::function<void()>& read) {
    try {
        read();
    } catch (const volref::Error& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        return message;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected volref::Error, got another exception: " << e.what();
        return "";
    } catch (...) {
        ADD_FAILURE() << "expected volref::Error, got a non-std exception";
        return "";
    }
    ADD_FAILURE() << "expected volref::Error, nothing was thrown";
    return "";
}

std::string read_error(const fs::path& path, const std::string& format = "") {
    return error_message([&] { volref::read_volume(path, format); });
}

// ---- the 8 types, with values for which byte order matters ----

struct TypeCase {
    std::string nrrd_type;     // as in a NRRD header
    std::string sidecar_type;  // as in a sidecar
    ScalarType type;
    std::function<std::string(std::endian)> bytes;
    std::vector<double> values;  // what the bytes hold
};

template <typename T>
TypeCase type_case(std::string nrrd_type, std::string sidecar_type, ScalarType type, std::vector<T> values) {
    std::vector<double> as_double(values.begin(), values.end());
    return {std::move(nrrd_type), std::move(sidecar_type), type,
            [values](std::endian order) { return to_bytes(values, order); }, as_double};
}

std::vector<TypeCase> type_cases() {
    return {
        type_case<std::uint8_t>("uchar", "u8", ScalarType::U8, {0, 1, 2, 127, 128, 255}),
        type_case<std::int8_t>("signed char", "i8", ScalarType::I8, {-128, -1, 0, 1, 2, 127}),
        type_case<std::uint16_t>("ushort", "u16", ScalarType::U16, {0x0102, 0xfffe, 0, 1, 0x8000, 65535}),
        type_case<std::int16_t>("short", "i16", ScalarType::I16, {0x0102, -2, -32768, 32767, 0, -0x0102}),
        type_case<std::uint32_t>("uint", "u32", ScalarType::U32,
                                 {0x01020304u, 4294967295u, 0u, 1u, 0x80000000u, 65536u}),
        type_case<std::int32_t>("int", "i32", ScalarType::I32,
                                {0x01020304, -2, std::numeric_limits<std::int32_t>::min(),
                                 std::numeric_limits<std::int32_t>::max(), 0, -0x01020304}),
        type_case<float>("float", "f32", ScalarType::F32, {1.5f, -2.25f, 0.1f, 1e-40f, 3.4e38f, -0.0f}),
        type_case<double>("double", "f64", ScalarType::F64, {-2.25, 0.1, 1e300, 5e-324, 258.0, -0.0}),
    };
}

const std::endian kEndians[] = {std::endian::little, std::endian::big};

// ---- the fixture: a fresh temporary folder per test ----

class VolumeIo : public ::testing::Test {
protected:
    void SetUp() override {
        static int counter = 0;
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("volref_io_" + std::to_string(::getpid()) + "_" +
                                            std::to_string(counter++) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }

    fs::path write(const std::string& name, const std::string& bytes) {
        const fs::path path = dir_ / name;
        fs::create_directories(path.parent_path());
        std::ofstream out(path, std::ios::binary);
        out.write(bytes.data(), std::streamsize(bytes.size()));
        EXPECT_TRUE(out.good()) << path;
        return path;
    }

    // A u8 NRRD with attached raw data 1 2 3 4 5 6 (sizes 3 2) and the extra header lines.
    fs::path small_nrrd(const std::string& name, const std::vector<std::string>& extra) {
        std::vector<std::string> lines = {"type: uchar", "dimension: 2", "sizes: 3 2", "encoding: raw"};
        lines.insert(lines.end(), extra.begin(), extra.end());
        return write(name, nrrd(lines) + std::string("\x01\x02\x03\x04\x05\x06", 6));
    }

    // A raw file of 2 x 3 x 1 u16 values (little endian) and its sidecar.
    fs::path small_raw(const std::string& sidecar) {
        write("head.raw.json", sidecar);
        return write("head.raw", to_bytes(std::vector<std::uint16_t>{1, 2, 3, 4, 5, 6}, std::endian::little));
    }

    fs::path dir_;
};

// ======================= NRRD: values =======================

TEST_F(VolumeIo, NrrdLiteralBytesOfBothByteOrders) {
    // 0x01 0x02 is 258 big-endian and 513 little-endian.
    for (std::endian e : kEndians) {
        const fs::path p = write("v.nrrd", nrrd({"type: uint16", "dimension: 1", "sizes: 2", "encoding: raw",
                                                 std::string("endian: ") + endian_name(e)}) +
                                               std::string("\x01\x02\xff\xfe", 4));
        const Volume v = volref::read_volume(p);
        if (e == std::endian::big)
            expect_values(v, {258.0, 65534.0});
        else
            expect_values(v, {513.0, 65279.0});
    }
}

TEST_F(VolumeIo, NrrdEveryTypeEveryEndianRawAndGzip) {
    for (const TypeCase& tc : type_cases()) {
        for (std::endian e : kEndians) {
            for (bool gzip : {false, true}) {
                SCOPED_TRACE(tc.nrrd_type + " " + endian_name(e) + (gzip ? " gzip" : " raw"));
                const std::string data = gzip ? compress(tc.bytes(e)) : tc.bytes(e);
                const fs::path p =
                    write("v.nrrd", nrrd({"type: " + tc.nrrd_type, "dimension: 3", "sizes: 3 2 1",
                                          std::string("endian: ") + endian_name(e),
                                          gzip ? "encoding: gzip" : "encoding: raw"}) +
                                        data);
                const Volume v = volref::read_volume(p);
                EXPECT_EQ(v.type, tc.type);
                EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 2, 1}));
                expect_values(v, tc.values);
                expect_vec(v.spacing, 1, 1, 1);
                expect_vec(v.origin, 0, 0, 0);
                EXPECT_EQ(v.at(2, 1, 0), tc.values[5]);
            }
        }
    }
}

TEST_F(VolumeIo, NrrdEveryTypeAlias) {
    // clang-format off
    const std::pair<const char*, ScalarType> aliases[] = {
        {"uchar", ScalarType::U8},          {"unsigned char", ScalarType::U8},  {"uint8", ScalarType::U8},
        {"uint8_t", ScalarType::U8},        {"signed char", ScalarType::I8},    {"int8", ScalarType::I8},
        {"int8_t", ScalarType::I8},         {"short", ScalarType::I16},         {"short int", ScalarType::I16},
        {"signed short", ScalarType::I16},  {"signed short int", ScalarType::I16}, {"int16", ScalarType::I16},
        {"int16_t", ScalarType::I16},       {"ushort", ScalarType::U16},        {"unsigned short", ScalarType::U16},
        {"unsigned short int", ScalarType::U16}, {"uint16", ScalarType::U16},   {"uint16_t", ScalarType::U16},
        {"int", ScalarType::I32},           {"signed int", ScalarType::I32},    {"int32", ScalarType::I32},
        {"int32_t", ScalarType::I32},       {"uint", ScalarType::U32},          {"unsigned int", ScalarType::U32},
        {"uint32", ScalarType::U32},        {"uint32_t", ScalarType::U32},      {"float", ScalarType::F32},
        {"double", ScalarType::F64},
    };
    // clang-format on
    for (const auto& [alias, type] : aliases) {
        SCOPED_TRACE(alias);
        const fs::path p = write(
            "a.nrrd",
            nrrd({std::string("type: ") + alias, "dimension: 1", "sizes: 2", "encoding: ascii"}) + "7 -0\n");
        const Volume v = volref::read_volume(p);
        EXPECT_EQ(v.type, type);
        EXPECT_EQ(v.values, (std::vector<double>{7.0, 0.0}));
    }
}

TEST_F(VolumeIo, NrrdNonFiniteFloatsAreKept) {
    const float f_inf = std::numeric_limits<float>::infinity();
    const double d_inf = std::numeric_limits<double>::infinity();
    const fs::path pf =
        write("f.nrrd", nrrd({"type: float", "dimension: 1", "sizes: 3", "encoding: raw", "endian: big"}) +
                            to_bytes(std::vector<float>{std::nanf(""), f_inf, -f_inf}, std::endian::big));
    const Volume vf = volref::read_volume(pf);
    ASSERT_EQ(vf.values.size(), 3u);
    EXPECT_TRUE(std::isnan(vf.values[0]));
    EXPECT_EQ(vf.values[1], d_inf);
    EXPECT_EQ(vf.values[2], -d_inf);

    const fs::path pd = write(
        "d.nrrd", nrrd({"type: double", "dimension: 1", "sizes: 3", "encoding: raw", "endian: little"}) +
                      to_bytes(std::vector<double>{-d_inf, std::nan(""), 1.0}, std::endian::little));
    const Volume vd = volref::read_volume(pd);
    ASSERT_EQ(vd.values.size(), 3u);
    EXPECT_EQ(vd.values[0], -d_inf);
    EXPECT_TRUE(std::isnan(vd.values[1]));
    EXPECT_EQ(vd.values[2], 1.0);
}

TEST_F(VolumeIo, NrrdEveryMagicVersionAndCrlfLines) {
    for (const char* magic : {"NRRD0001", "NRRD0002", "NRRD0003", "NRRD0004", "NRRD0005"}) {
        const fs::path p = write("m.nrrd", std::string(magic) +
                                               "\r\ntype: uchar\r\ndimension: 1\r\nsizes: 2\r\n"
                                               "encoding: raw\r\n\r\n\x09\x08");
        expect_values(volref::read_volume(p), {9.0, 8.0});
    }
}

TEST_F(VolumeIo, NrrdDetachedHeaderRelativeSubfolderAndAbsolute) {
    const std::vector<std::int16_t> values = {-2, 0x0102, 3, -4};
    const std::string bytes = to_bytes(values, std::endian::big);
    write("vol.raw", bytes);
    write("sub/data.bin", bytes);
    const std::vector<std::string> common = {"type: int16", "dimension: 3", "sizes: 2 2 1", "encoding: raw",
                                             "endian: big"};
    for (const std::string& data_line :
         {std::string("data file: vol.raw"), std::string("datafile: sub/data.bin"),
          "data file: " + (dir_ / "vol.raw").string()}) {
        SCOPED_TRACE(data_line);
        auto lines = common;
        lines.push_back(data_line);
        const fs::path p = write("vol.nhdr", nrrd(lines, false));  // a detached header ends at end of file
        expect_values(volref::read_volume(p), {-2.0, 258.0, 3.0, -4.0});
    }
}

TEST_F(VolumeIo, NrrdDetachedGzipAndZlibStreams) {
    const std::vector<std::uint32_t> values = {0x01020304u, 7u, 0xfffffffeu};
    const std::string bytes = to_bytes(values, std::endian::little);
    write("vol.raw.gz", compress(bytes, true));
    write("vol.raw.z", compress(bytes, false));  // zlib wrapper: told apart from gzip by its header
    for (const char* file : {"vol.raw.gz", "vol.raw.z"}) {
        SCOPED_TRACE(file);
        const fs::path p = write("v.nhdr", nrrd({"type: uint32", "dimension: 1", "sizes: 3", "encoding: gz",
                                                 "endian: little", std::string("data file: ") + file},
                                                false));
        expect_values(volref::read_volume(p), {double(0x01020304u), 7.0, double(0xfffffffeu)});
    }
}

TEST_F(VolumeIo, NrrdGzipOfSeveralMembers) {
    // gunzip reads concatenated gzip members as one stream.
    const std::string data = to_bytes(std::vector<std::uint16_t>{1, 0x0102, 3, 4}, std::endian::big);
    const fs::path p =
        write("v.nrrd", nrrd({"type: ushort", "dimension: 1", "sizes: 4", "encoding: gzip", "endian: big"}) +
                            compress(data.substr(0, 3)) + compress(data.substr(3)));
    expect_values(volref::read_volume(p), {1.0, 258.0, 3.0, 4.0});
}

TEST_F(VolumeIo, NrrdAsciiEncodings) {
    const fs::path pf =
        write("f.nrrd", nrrd({"type: float", "dimension: 2", "sizes: 2 2", "encoding: ascii"}) +
                            "1.5  -2.25\n0.1\t+3\n");
    const Volume vf = volref::read_volume(pf);
    EXPECT_EQ(vf.dims, (std::array<std::int64_t, 3>{2, 2, 1}));
    expect_values(vf, {1.5, -2.25, double(0.1f), 3.0});  // as a float file holds them

    const fs::path pd = write(
        "d.nrrd", nrrd({"type: double", "dimension: 1", "sizes: 3", "encoding: text"}) + "0.1 -1e300 nan");
    const Volume vd = volref::read_volume(pd);
    ASSERT_EQ(vd.values.size(), 3u);
    EXPECT_EQ(vd.values[0], 0.1);
    EXPECT_EQ(vd.values[1], -1e300);
    EXPECT_TRUE(std::isnan(vd.values[2]));

    const fs::path pi = write("i.nrrd", nrrd({"type: int", "dimension: 1", "sizes: 4", "encoding: txt"}) +
                                            "-2147483648\n2147483647\n-5\n0\n");
    expect_values(volref::read_volume(pi), {-2147483648.0, 2147483647.0, -5.0, 0.0});
}

TEST_F(VolumeIo, NrrdSpacings) {
    const Volume v = volref::read_volume(small_nrrd("s.nrrd", {"spacings: 0.5 2.25"}));
    expect_vec(v.spacing, 0.5, 2.25, 1.0);
    expect_vec(v.origin, 0, 0, 0);
    // nan is NRRD's "unknown spacing": read as 1.
    const Volume w = volref::read_volume(small_nrrd("n.nrrd", {"spacings: nan 3"}));
    expect_vec(w.spacing, 1.0, 3.0, 1.0);
}

TEST_F(VolumeIo, NrrdSpaceDirectionsAndOrigin) {
    const fs::path p = write("d.nrrd", nrrd({"type: uchar", "dimension: 3", "sizes: 2 1 1", "encoding: raw",
                                             "space: left-posterior-superior",
                                             "space directions: (0.5,0,0) ( 0, 2.25, 0 ) (0,0,3)",
                                             "space origin: (1.5,-2,3.25)", "spacings: nan nan nan"}) +
                                           "\x05\x06");
    const Volume v = volref::read_volume(p);
    expect_vec(v.spacing, 0.5, 2.25, 3.0);
    expect_vec(v.origin, 1.5, -2.0, 3.25);
    expect_values(v, {5.0, 6.0});

    // A 2-axis grid in a 2D space, and in a 3D space.
    const Volume a = volref::read_volume(small_nrrd(
        "a.nrrd", {"space dimension: 2", "space directions: (0.5,0) (0,4)", "space origin: (1,2)"}));
    expect_vec(a.spacing, 0.5, 4.0, 1.0);
    expect_vec(a.origin, 1.0, 2.0, 0.0);
    const Volume b = volref::read_volume(small_nrrd(
        "b.nrrd", {"space: RAS", "space directions: (2,0,0) (0,3,0)", "space origin: (-1,-2,-3)"}));
    expect_vec(b.spacing, 2.0, 3.0, 1.0);
    expect_vec(b.origin, -1.0, -2.0, -3.0);
}

TEST_F(VolumeIo, NrrdDimensionsArePadded) {
    const Volume v2 = volref::read_volume(small_nrrd("two.nrrd", {}));
    EXPECT_EQ(v2.dims, (std::array<std::int64_t, 3>{3, 2, 1}));
    expect_values(v2, {1, 2, 3, 4, 5, 6});
    EXPECT_EQ(v2.at(0, 1, 0), 4.0);

    const fs::path p1 = write(
        "one.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 4", "encoding: raw", "spacings: 0.25"}) +
                        "\x01\x02\x03\x04");
    const Volume v1 = volref::read_volume(p1);
    EXPECT_EQ(v1.dims, (std::array<std::int64_t, 3>{4, 1, 1}));
    expect_vec(v1.spacing, 0.25, 1.0, 1.0);
    expect_values(v1, {1, 2, 3, 4});
}

TEST_F(VolumeIo, NrrdByteSkipAndLineSkip) {
    // Attached: 4 bytes skipped after the header.
    const Volume a = volref::read_volume(small_nrrd("a.nrrd", {"byte skip: 0"}));
    expect_values(a, {1, 2, 3, 4, 5, 6});
    const fs::path pb =
        write("b.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 2", "encoding: raw", "byte skip: 4"}) +
                            "JUNK\x0a\x0b");
    expect_values(volref::read_volume(pb), {10, 11});

    // Detached, byte skip -1: the data ends the file, whatever header precedes it.
    const std::string data = to_bytes(std::vector<std::int32_t>{-7, 0x01020304}, std::endian::big);
    write("skipped.raw", "a 17-byte header" + std::string("\x00", 1) + data);
    const Volume c =
        volref::read_volume(write("c.nhdr", nrrd({"type: int32", "dimension: 1", "sizes: 2", "encoding: raw",
                                                  "endian: big", "byte skip: -1", "data file: skipped.raw"},
                                                 false)));
    expect_values(c, {-7.0, double(0x01020304)});

    // Line skip, then byte skip.
    write("lines.raw", "line one\nline two\nXYZ" + data);
    const Volume d = volref::read_volume(
        write("d.nhdr", nrrd({"type: int32", "dimension: 1", "sizes: 2", "encoding: raw", "endian: big",
                              "line skip: 2", "byte skip: 3", "data file: lines.raw"},
                             false)));
    expect_values(d, {-7.0, double(0x01020304)});

    // gzip: line skip applies to the file, byte skip to the inflated data.
    write("lines.raw.gz", "text line\n" + compress("HDR" + data));
    const Volume e = volref::read_volume(
        write("e.nhdr", nrrd({"type: int32", "dimension: 1", "sizes: 2", "encoding: gzip", "endian: big",
                              "lineskip: 1", "byteskip: 3", "data file: lines.raw.gz"},
                             false)));
    expect_values(e, {-7.0, double(0x01020304)});

    // ascii: line skip over a text preamble.
    const fs::path pf =
        write("f.nrrd", nrrd({"type: short", "dimension: 1", "sizes: 2", "encoding: ascii", "line skip: 1"}) +
                            "not data\n-3 4\n");
    expect_values(volref::read_volume(pf), {-3, 4});
}

TEST_F(VolumeIo, NrrdOtherFieldsCommentsAndKeyValuesAreAccepted) {
    const Volume v = volref::read_volume(small_nrrd("all.nrrd", {"# a comment",
                                                                 "content: test volume",
                                                                 "number: 6",
                                                                 "kinds: space space",
                                                                 "centers: cell cell",
                                                                 "units: \"mm\" \"mm\"",
                                                                 "space units: \"mm\" \"mm\"",
                                                                 "labels: \"x\" \"y\"",
                                                                 "min: 0",
                                                                 "max: 255",
                                                                 "old min: -1",
                                                                 "oldmax: 2",
                                                                 "thicknesses: 1 1",
                                                                 "axis mins: 0 0",
                                                                 "axismaxs: 2 1",
                                                                 "sample units: HU",
                                                                 "block size: 1",
                                                                 "space: 3D-right-handed",
                                                                 "space dimension: 3",
                                                                 "measurement frame: (1,0,0) (0,1,0) (0,0,1)",
                                                                 "modality:=CT",
                                                                 "DICOM:0008:=x: y",
                                                                 "Content:=key named like a field"}));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 2, 1}));
    expect_values(v, {1, 2, 3, 4, 5, 6});
    expect_vec(v.spacing, 1, 1, 1);
    // `centerings` is an alias of `centers`.
    expect_values(volref::read_volume(small_nrrd("c.nrrd", {"centerings: node node"})), {1, 2, 3, 4, 5, 6});
}

TEST_F(VolumeIo, Uint8NeedsNoEndian) {
    const Volume v = volref::read_volume(small_nrrd("u8.nrrd", {}));
    EXPECT_EQ(v.type, ScalarType::U8);
}

// ======================= raw + sidecar =======================

TEST_F(VolumeIo, RawEveryTypeEveryEndianRawAndGzip) {
    for (const TypeCase& tc : type_cases()) {
        for (std::endian e : kEndians) {
            for (bool gzip : {false, true}) {
                SCOPED_TRACE(tc.sidecar_type + " " + endian_name(e) + (gzip ? " gzip" : " raw"));
                write("head.raw.json", std::string("{\"dims\": [1, 3, 2], \"type\": \"") + tc.sidecar_type +
                                           "\", \"endian\": \"" + endian_name(e) + "\", \"encoding\": \"" +
                                           (gzip ? "gzip" : "raw") + "\"}");
                const fs::path p = write("head.raw", gzip ? compress(tc.bytes(e)) : tc.bytes(e));
                const Volume v = volref::read_volume(p);
                EXPECT_EQ(v.type, tc.type);
                EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{1, 3, 2}));
                expect_values(v, tc.values);
            }
        }
    }
}

TEST_F(VolumeIo, RawSidecarDefaults) {
    const Volume v = volref::read_volume(small_raw(R"({"dims": [2, 3, 1], "type": "u16"})"));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{2, 3, 1}));
    EXPECT_EQ(v.type, ScalarType::U16);
    expect_values(v, {1, 2, 3, 4, 5, 6});  // little endian by default
    expect_vec(v.origin, 0, 0, 0);
    expect_vec(v.spacing, 1, 1, 1);
}

TEST_F(VolumeIo, RawSidecarEveryKey) {
    write("head.raw.json", R"({"dims": [2, 1, 2], "type": "i16", "endian": "big", "origin": [1.5, -2, 0.25],
                               "spacing": [0.5, 2, 3.125], "header_bytes": 5, "encoding": "raw"})");
    const fs::path p = write(
        "head.raw", "HEAD!" + to_bytes(std::vector<std::int16_t>{0x0102, -2, 7, -32768}, std::endian::big));
    const Volume v = volref::read_volume(p);
    expect_values(v, {258, -2, 7, -32768});
    expect_vec(v.origin, 1.5, -2.0, 0.25);
    expect_vec(v.spacing, 0.5, 2.0, 3.125);
    EXPECT_EQ(v.at(1, 0, 1), -32768.0);
}

TEST_F(VolumeIo, RawSidecarGzipHeaderBytesCountInflatedBytes) {
    write("head.raw.json", R"({"dims": [3, 1, 1], "type": "f32", "header_bytes": 2, "encoding": "gzip"})");
    const fs::path p = write(
        "head.raw", compress("hh" + to_bytes(std::vector<float>{1.5f, -2.25f, 0.1f}, std::endian::little)));
    expect_values(volref::read_volume(p), {1.5, -2.25, double(0.1f)});
}

// ======================= choosing the format =======================

TEST_F(VolumeIo, FormatFromExtensionOrGiven) {
    const std::string body = nrrd({"type: uchar", "dimension: 1", "sizes: 1", "encoding: raw"}) + "\x2a";
    for (const char* name : {"a.nrrd", "b.NRRD", "c.nhdr", "d.Nhdr"})
        expect_values(volref::read_volume(write(name, body)), {42});
    expect_values(volref::read_volume(write("e.dat", body), "nrrd"), {42});

    write("f.bin.json", R"({"dims": [1, 1, 1], "type": "u8"})");
    expect_values(volref::read_volume(write("f.bin", "\x2b"), "raw"), {43});
    write("g.RAW.json", R"({"dims": [1, 1, 1], "type": "i8"})");
    expect_values(volref::read_volume(write("g.RAW", "\xff")), {-1});
}

TEST_F(VolumeIo, ErrorUnknownExtensionOrFormat) {
    const fs::path p = write("v.xyz", "x");
    std::string m = read_error(p);
    EXPECT_THAT(m, StartsWith(p.string()));
    EXPECT_THAT(m, HasSubstr("'.xyz'"));
    EXPECT_THAT(m, HasSubstr(".nrrd, .nhdr, .raw"));

    const fs::path q = write("noext", "x");
    m = read_error(q);
    EXPECT_THAT(m, StartsWith(q.string()));
    EXPECT_THAT(m, HasSubstr("no extension"));

    m = read_error(p, "xyz");
    EXPECT_THAT(m, StartsWith(p.string()));
    EXPECT_THAT(m, HasSubstr("unknown volume format 'xyz'"));
}

// ======================= NRRD errors =======================

TEST_F(VolumeIo, ErrorMissingOrUnreadableFile) {
    const fs::path p = dir_ / "missing.nrrd";
    std::string m = read_error(p);
    EXPECT_THAT(m, StartsWith(p.string() + ": cannot read file"));
    EXPECT_THAT(m, HasSubstr("No such file"));

    fs::create_directories(dir_ / "folder.nrrd");
    m = read_error(dir_ / "folder.nrrd");
    EXPECT_THAT(m, StartsWith((dir_ / "folder.nrrd").string()));
    EXPECT_THAT(m, HasSubstr("directory"));

    if (::geteuid() != 0) {  // root reads any file
        const fs::path locked = small_nrrd("locked.nrrd", {});
        fs::permissions(locked, fs::perms::none);
        m = read_error(locked);
        EXPECT_THAT(m, StartsWith(locked.string() + ": cannot read file"));
        EXPECT_THAT(m, HasSubstr("Permission denied"));
    }
}

TEST_F(VolumeIo, ErrorBadMagic) {
    for (const std::string& content :
         {std::string(""), std::string("NRRD0006\ntype: uchar\n"), std::string("P6\n3 2\n255\n"),
          std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03", 10), std::string("NRRD00041\n")}) {
        const fs::path p = write("bad.nrrd", content);
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string() + ": not a NRRD file"));
        EXPECT_THAT(m, HasSubstr("NRRD0001 to NRRD0005"));
    }
}

TEST_F(VolumeIo, ErrorMissingRequiredField) {
    const std::vector<std::string> all = {"type: uchar", "dimension: 1", "sizes: 1", "encoding: raw"};
    const char* names[] = {"type", "dimension", "sizes", "encoding"};
    for (std::size_t i = 0; i < all.size(); ++i) {
        auto lines = all;
        lines.erase(lines.begin() + long(i));
        const fs::path p = write("m.nrrd", nrrd(lines) + "\x01");
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string()));
        EXPECT_THAT(m, HasSubstr(std::string("missing required field '") + names[i] + "'"));
    }
}

TEST_F(VolumeIo, ErrorDimsOverflowAndZero) {
    const fs::path p = write("o.nrrd", nrrd({"type: uchar", "dimension: 3",
                                             "sizes: 4294967296 4294967296 4294967296", "encoding: raw"}));
    std::string m = read_error(p);
    EXPECT_THAT(m, StartsWith(p.string()));
    EXPECT_THAT(m, HasSubstr("overflow"));

    const fs::path big = write(
        "big.nrrd", nrrd({"type: uchar", "dimension: 3", "sizes: 100000 100000 100000", "encoding: raw"}));
    m = read_error(big);
    EXPECT_THAT(m, StartsWith(big.string()));
    EXPECT_THAT(m, HasSubstr("256 GiB"));

    const fs::path zero =
        write("z.nrrd", nrrd({"type: uchar", "dimension: 2", "sizes: 3 0", "encoding: raw"}));
    m = read_error(zero);
    EXPECT_THAT(m, StartsWith(zero.string()));
    EXPECT_THAT(m, HasSubstr("dims must be >= 1"));
}

TEST_F(VolumeIo, ErrorTruncatedAndTooLongRaw) {
    const std::vector<std::string> lines = {"type: ushort", "dimension: 2", "sizes: 3 2", "encoding: raw",
                                            "endian: little"};
    const fs::path p = write("t.nrrd", nrrd(lines) + std::string(10, '\x01'));
    std::string m = read_error(p);
    EXPECT_EQ(m, p.string() + ": truncated: expected 12 bytes of data, found 10");

    const fs::path q = write("l.nrrd", nrrd(lines) + std::string(13, '\x01'));
    m = read_error(q);
    EXPECT_THAT(m, StartsWith(q.string()));
    EXPECT_THAT(m, HasSubstr("dims do not match the data size: expected 12 bytes of data, found 13"));

    // Byte skip past the end of the data.
    const fs::path s = small_nrrd("s.nrrd", {"byte skip: 100"});
    EXPECT_EQ(read_error(s), s.string() + ": truncated: expected 6 bytes of data, found 0");
    // Byte skip -1 with too little data.
    const fs::path e =
        write("e.nrrd",
              nrrd({"type: uchar", "dimension: 1", "sizes: 5", "encoding: raw", "byte skip: -1"}) + "abc");
    EXPECT_EQ(read_error(e), e.string() + ": truncated: expected 5 bytes of data, found 3");
}

TEST_F(VolumeIo, ErrorTruncatedDetachedDataNamesTheDataFile) {
    const fs::path data = write("d.raw", std::string(7, '\0'));
    const fs::path header = write("d.nhdr", nrrd({"type: float", "dimension: 1", "sizes: 2", "encoding: raw",
                                                  "endian: little", "data file: d.raw"},
                                                 false));
    const std::string m = read_error(header);
    EXPECT_THAT(m, StartsWith(data.string() + ": truncated: expected 8 bytes of data, found 7"));
    EXPECT_THAT(m, HasSubstr("data file of " + header.string()));
}

TEST_F(VolumeIo, ErrorGzipDataOfTheWrongSize) {
    const std::vector<std::string> lines = {"type: uchar", "dimension: 1", "sizes: 4", "encoding: gzip"};
    const fs::path s = write("s.nrrd", nrrd(lines) + compress("abc"));
    EXPECT_THAT(read_error(s), StartsWith(s.string() + ": truncated: expected 4 bytes of data, found 3"));
    const fs::path l = write("l.nrrd", nrrd(lines) + compress("abcde"));
    std::string m = read_error(l);
    EXPECT_THAT(m, StartsWith(l.string()));
    EXPECT_THAT(m, HasSubstr("dims do not match the data size"));
    const fs::path k =
        write("k.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 4", "encoding: gzip", "byte skip: 2"}) +
                            compress("abcd"));
    EXPECT_THAT(read_error(k), StartsWith(k.string() + ": truncated: expected 4 bytes of data, found 2"));
}

TEST_F(VolumeIo, ErrorCorruptGzip) {
    const std::vector<std::string> lines = {"type: uchar", "dimension: 1", "sizes: 64", "encoding: gzip"};
    const std::string good = compress(std::string(64, 'x'));
    std::string bad_crc = good;
    bad_crc[bad_crc.size() - 6] ^= 0x55;  // the CRC32 is in the last 8 bytes, before the length
    std::string bad_data = good;
    bad_data[12] ^= 0x7f;
    const std::string cases[] = {
        "this is not compressed at all",    // bad header
        good.substr(0, good.size() / 2),    // cut off
        bad_crc,                            // wrong check value
        bad_data,                           // damaged deflate data
        good + "garbage after the stream",  // trailing bytes
        "",                                 // nothing
    };
    for (const std::string& data : cases) {
        const fs::path p = write("c.nrrd", nrrd(lines) + data);
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string() + ": corrupt gzip stream"));
    }
}

TEST_F(VolumeIo, ErrorUnknownOrUnsupportedType) {
    for (const char* type : {"int64", "unsigned long long", "block", "long long int", "uint64_t"}) {
        const fs::path p = write("t.nrrd", nrrd({std::string("type: ") + type, "dimension: 1", "sizes: 1",
                                                 "encoding: raw", "endian: little"}) +
                                               std::string(8, '\0'));
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string() + ": line 2: type: "));
        EXPECT_THAT(m, HasSubstr(std::string("'") + type + "' is not supported"));
    }
    const fs::path q =
        write("q.nrrd", nrrd({"type: quaternion", "dimension: 1", "sizes: 1", "encoding: raw"}));
    EXPECT_THAT(read_error(q), StartsWith(q.string() + ": line 2: type: unknown type 'quaternion'"));
}

TEST_F(VolumeIo, ErrorBadSpacings) {
    for (const char* spacing : {"0 1", "1 -1", "inf 1", "1 -inf"}) {
        const fs::path p = small_nrrd("s.nrrd", {std::string("spacings: ") + spacing});
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string() + ": line 6: spacings: axis "));
        EXPECT_THAT(m, HasSubstr("spacing must be finite and > 0"));
    }
    const fs::path w = small_nrrd("w.nrrd", {"spacings: 1 two"});
    EXPECT_THAT(read_error(w), HasSubstr("spacings: axis 1: expected a number, got 'two'"));
    const fs::path c = small_nrrd("c.nrrd", {"spacings: 1"});
    EXPECT_THAT(read_error(c), HasSubstr("spacings: expected 2 numbers (one per axis)"));
    const fs::path both = small_nrrd("b.nrrd", {"spacings: 1 2", "space directions: (1,0) (0,2)"});
    const std::string m = read_error(both);
    EXPECT_THAT(m, StartsWith(both.string()));
    EXPECT_THAT(m, HasSubstr("either spacings or space directions"));
}

TEST_F(VolumeIo, ErrorUnsupportedSpaceDirections) {
    for (const char* dirs : {"(0,1,0) (1,0,0)", "(-1,0,0) (0,1,0)", "(1,0,0) (0,-2,0)", "(0.7,0.7,0) (0,1,0)",
                             "(0,0,0) (0,1,0)", "(1,0) (0,0)"}) {
        SCOPED_TRACE(dirs);
        const fs::path p = small_nrrd("d.nrrd", {std::string("space directions: ") + dirs});
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string() + ": line 6: space directions: axis "));
        EXPECT_THAT(m, HasSubstr("non-axis-aligned or flipped directions are not supported yet"));
    }
    const fs::path none = small_nrrd("n.nrrd", {"space directions: none (1,0,0)"});
    std::string m = read_error(none);
    EXPECT_THAT(m, StartsWith(none.string() + ": line 6: space directions: axis 0: 'none'"));
    EXPECT_THAT(m, HasSubstr("scalar volumes"));
    for (const char* bad :
         {"(1,0,0)", "(1,0,0) (0,1)", "(1,0,0) (0,1,x)", "(1,0,0) (0,1,0", "(nan,0,0) (0,1,0)"}) {
        SCOPED_TRACE(bad);
        const fs::path p = small_nrrd("b.nrrd", {std::string("space directions: ") + bad});
        EXPECT_THAT(read_error(p), StartsWith(p.string() + ": line 6: space directions: "));
    }
    const fs::path o = small_nrrd("o.nrrd", {"space directions: (1,0,0) (0,1,0)", "space origin: (1,2)"});
    EXPECT_THAT(read_error(o), StartsWith(o.string() + ": line 7: space origin: expected 3 components"));
    const fs::path f = small_nrrd("f.nrrd", {"space origin: (1,inf,2)"});
    EXPECT_THAT(read_error(f), StartsWith(f.string() + ": line 6: space origin: non-finite"));
    const fs::path g = small_nrrd("g.nrrd", {"space origin: 1 2 3"});
    EXPECT_THAT(read_error(g), StartsWith(g.string() + ": line 6: space origin: expected a vector"));
}

TEST_F(VolumeIo, ErrorEndian) {
    const fs::path p = write(
        "e.nrrd", nrrd({"type: float", "dimension: 1", "sizes: 1", "encoding: raw"}) + std::string(4, '\0'));
    std::string m = read_error(p);
    EXPECT_THAT(m, StartsWith(p.string() + ": missing field 'endian'"));
    const fs::path g =
        write("g.nrrd", nrrd({"type: short", "dimension: 1", "sizes: 1", "encoding: gzip"}) + compress("ab"));
    EXPECT_THAT(read_error(g), StartsWith(g.string() + ": missing field 'endian'"));
    // Not needed for ascii data.
    const fs::path a =
        write("a.nrrd", nrrd({"type: short", "dimension: 1", "sizes: 1", "encoding: ascii"}) + "-300");
    expect_values(volref::read_volume(a), {-300});
    const fs::path b = small_nrrd("b.nrrd", {"endian: middle"});
    EXPECT_THAT(read_error(b),
                StartsWith(b.string() + ": line 6: endian: expected little or big, got 'middle'"));
}

TEST_F(VolumeIo, ErrorUnknownFieldMalformedLineAndDuplicate) {
    const fs::path p = small_nrrd("u.nrrd", {"# fine", "colour: red"});
    EXPECT_EQ(read_error(p), p.string() + ": line 7: unknown field 'colour'");
    const fs::path q = small_nrrd("m.nrrd", {"just some words"});
    EXPECT_THAT(read_error(q), StartsWith(q.string() + ": line 6: expected 'field: value'"));
    const fs::path d = small_nrrd("d.nrrd", {"sizes: 3 2"});
    EXPECT_EQ(read_error(d), d.string() + ": line 6: field 'sizes' given twice (first on line 4)");
    const fs::path c = small_nrrd("c.nrrd", {"centers: cell cell", "centerings: cell cell"});
    EXPECT_THAT(read_error(c), HasSubstr("line 7: field 'centers' given twice"));
}

TEST_F(VolumeIo, ErrorDimensionAndSizes) {
    for (const char* dim : {"0", "4", "-1"}) {
        const fs::path p = write(
            "d.nrrd", nrrd({"type: uchar", std::string("dimension: ") + dim, "sizes: 1", "encoding: raw"}));
        const std::string m = read_error(p);
        EXPECT_THAT(m, StartsWith(p.string() + ": line 3: dimension: "));
        EXPECT_THAT(m, HasSubstr("not supported (volref reads 1 to 3 axes)"));
    }
    const fs::path x =
        write("x.nrrd", nrrd({"type: uchar", "dimension: three", "sizes: 1", "encoding: raw"}));
    EXPECT_THAT(read_error(x), StartsWith(x.string() + ": line 3: dimension: expected an integer"));
    const fs::path s =
        write("s.nrrd", nrrd({"type: uchar", "dimension: 2", "sizes: 1 2 3", "encoding: raw"}));
    EXPECT_THAT(read_error(s), StartsWith(s.string() + ": line 4: sizes: expected 2 integers"));
    const fs::path t =
        write("t.nrrd", nrrd({"type: uchar", "dimension: 2", "sizes: 1 2.5", "encoding: raw"}));
    EXPECT_THAT(read_error(t), StartsWith(t.string() + ": line 4: sizes: expected 2 integers"));
}

TEST_F(VolumeIo, ErrorEncodingAndSkips) {
    const fs::path h =
        write("h.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 1", "encoding: hex"}) + "2a");
    EXPECT_THAT(read_error(h),
                StartsWith(h.string() + ": line 5: encoding: encoding 'hex' is not supported"));
    const fs::path b = write("b.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 1", "encoding: bzip2"}));
    EXPECT_THAT(read_error(b), HasSubstr("'bzip2' is not supported"));
    const fs::path u = write("u.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 1", "encoding: lzma"}));
    EXPECT_THAT(read_error(u), StartsWith(u.string() + ": line 5: encoding: unknown encoding 'lzma'"));

    const fs::path s = small_nrrd("s.nrrd", {"byte skip: -2"});
    EXPECT_THAT(read_error(s),
                StartsWith(s.string() + ": line 6: byte skip: expected an integer >= -1, got '-2'"));
    const fs::path l = small_nrrd("l.nrrd", {"line skip: -1"});
    EXPECT_THAT(read_error(l), StartsWith(l.string() + ": line 6: line skip: expected an integer >= 0"));
    const fs::path g =
        write("g.nrrd", nrrd({"type: uchar", "dimension: 1", "sizes: 1", "encoding: gzip", "byte skip: -1"}) +
                            compress("a"));
    EXPECT_THAT(read_error(g),
                StartsWith(g.string() + ": line 6: byte skip: -1 (data at the end of the file) is "
                                        "only allowed with raw encoding"));
    const fs::path p = small_nrrd("p.nrrd", {"line skip: 3"});
    EXPECT_THAT(read_error(p), StartsWith(p.string() + ": line skip 3 goes past the end of the data"));
}

TEST_F(VolumeIo, ErrorDataFileProblems) {
    const std::vector<std::string> lines = {"type: uchar", "dimension: 1", "sizes: 1", "encoding: raw"};
    auto with = [&](const std::string& extra) {
        auto l = lines;
        l.push_back(extra);
        return nrrd(l, false);
    };
    const fs::path h = write("h.nhdr", with("data file: absent.raw"));
    std::string m = read_error(h);
    EXPECT_THAT(m, StartsWith((dir_ / "absent.raw").string() + ": cannot read file"));
    EXPECT_THAT(m, HasSubstr("data file of " + h.string()));

    const fs::path list = write("l.nhdr", with("data file: LIST"));
    EXPECT_THAT(read_error(list), StartsWith(list.string() + ": line 6: data file: several data files"));
    const fs::path pattern = write("p.nhdr", with("data file: slice%03d.raw 1 10 1 2"));
    EXPECT_THAT(read_error(pattern),
                StartsWith(pattern.string() + ": line 6: data file: several data files"));

    const fs::path none = write("n.nhdr", nrrd(lines, false));
    m = read_error(none);
    EXPECT_THAT(m, StartsWith(none.string() + ": no data"));
    EXPECT_THAT(m, HasSubstr("no 'data file' field"));
}

TEST_F(VolumeIo, ErrorAsciiData) {
    auto ascii = [&](const std::string& type, const std::string& data) {
        return write("a.nrrd", nrrd({"type: " + type, "dimension: 1", "sizes: 3", "encoding: ascii"}) + data);
    };
    fs::path p = ascii("float", "1 2 x3");
    EXPECT_EQ(read_error(p), p.string() + ": ascii sample 2: 'x3' is not a number");
    p = ascii("uchar", "1 256 3");
    EXPECT_EQ(read_error(p), p.string() + ": ascii sample 1: '256' is not an integer in the range of u8");
    p = ascii("short", "1.5 2 3");
    EXPECT_THAT(read_error(p), HasSubstr("ascii sample 0: '1.5' is not an integer"));
    p = ascii("float", "1 1e39 3");
    EXPECT_THAT(read_error(p), HasSubstr("ascii sample 1: '1e39' is out of the range of f32"));
    p = ascii("int", "1 2");
    EXPECT_EQ(read_error(p), p.string() + ": truncated: expected 3 values of data, found 2");
    p = ascii("int", "1 2 3 4");
    EXPECT_THAT(read_error(p),
                StartsWith(p.string() + ": dims do not match the data size: expected 3 values"));
}

// ======================= raw + sidecar errors =======================

TEST_F(VolumeIo, ErrorMissingSidecarOrDataFile) {
    const fs::path p = write("head.raw", "abc");
    const std::string m = read_error(p);
    EXPECT_THAT(m, StartsWith(p.string() + ".json: cannot read file"));
    EXPECT_THAT(m, HasSubstr("JSON sidecar describing " + p.string()));

    const fs::path missing = dir_ / "missing.raw";
    write("missing.raw.json", R"({"dims": [1, 1, 1], "type": "u8"})");
    EXPECT_THAT(read_error(missing), StartsWith(missing.string() + ": cannot read file"));
}

TEST_F(VolumeIo, ErrorSidecarKeys) {
    const std::string side = (dir_ / "head.raw.json").string();
    const std::pair<std::string, std::string> cases[] = {
        {R"({"dims": [2, 3, 1], "type": "u16", "spacing": [1, -1, 1]})",
         side + ": spacing[1]: expected a number > 0, got -1"},
        {R"({"dims": [2, 3, 1], "type": "u16", "spacing": [1, 0, 1]})",
         side + ": spacing[1]: expected a number > 0, got 0"},
        {R"({"dims": [2, 3, 1], "type": "u16", "spacing": [1, 1]})",
         side + ": spacing: expected an array of 3 numbers > 0, got [1,1]"},
        {R"({"dims": [2, 3, 1], "type": "u16", "origin": [0, "a", 0]})",
         side + ": origin[1]: expected a finite number, got \"a\""},
        {R"({"dims": [2, 3, 1], "type": "u16", "origin": 0})",
         side + ": origin: expected an array of 3 numbers, got 0"},
        {R"({"dims": [2, 3], "type": "u16"})",
         side + ": dims: expected an array of 3 integers >= 1, got [2,3]"},
        {R"({"dims": [2, 0, 1], "type": "u16"})", side + ": dims[1]: expected an integer >= 1, got 0"},
        {R"({"dims": [2, 3, 1.5], "type": "u16"})", side + ": dims[2]: expected an integer >= 1, got 1.5"},
        {R"({"dims": "2 3 1", "type": "u16"})",
         side + ": dims: expected an array of 3 integers >= 1, got \"2 3 1\""},
        {R"({"dims": [2, 3, 1], "type": "u64"})",
         side + ": type: expected one of \"u8\", \"i8\", \"u16\", \"i16\", \"u32\", \"i32\", \"f32\", "
                "\"f64\", got \"u64\""},
        {R"({"dims": [2, 3, 1], "type": 16})",
         side + ": type: expected one of \"u8\", \"i8\", \"u16\", \"i16\", "
                "\"u32\", \"i32\", \"f32\", \"f64\", got 16"},
        {R"({"dims": [2, 3, 1], "type": "u16", "endian": "middle"})",
         side + ": endian: expected one of \"little\", \"big\", got \"middle\""},
        {R"({"dims": [2, 3, 1], "type": "u16", "header_bytes": -1})",
         side + ": header_bytes: expected an integer >= 0, got -1"},
        {R"({"dims": [2, 3, 1], "type": "u16", "header_bytes": 2.5})",
         side + ": header_bytes: expected an integer >= 0, got 2.5"},
        {R"({"dims": [2, 3, 1], "type": "u16", "encoding": "bz2"})",
         side + ": encoding: expected one of \"raw\", \"gzip\", got \"bz2\""},
        {R"({"dims": [2, 3, 1], "type": "u16", "spacnig": [1, 1, 1]})",
         side + ": 'spacnig': unknown key (expected dims, type, endian, origin, spacing, header_bytes, "
                "encoding)"},
        {R"({"type": "u16"})", side + ": missing required key 'dims'"},
        {R"({"dims": [2, 3, 1]})", side + ": missing required key 'type'"},
        {R"([2, 3, 1])", side + ": expected a JSON object, got [2,3,1]"},
    };
    for (const auto& [json, expected] : cases) {
        SCOPED_TRACE(json);
        EXPECT_EQ(read_error(small_raw(json)), expected);
    }
    const std::string m = read_error(small_raw("{\"dims\": [2, 3, 1],\n \"type\": }"));
    EXPECT_THAT(m, StartsWith(side + ": invalid JSON: "));
    EXPECT_THAT(m, HasSubstr("line 2"));
}

TEST_F(VolumeIo, ErrorSidecarDimsOverflow) {
    const std::string m =
        read_error(small_raw(R"({"dims": [4294967296, 4294967296, 4294967296], "type": "u8"})"));
    EXPECT_THAT(m, StartsWith((dir_ / "head.raw.json").string()));
    EXPECT_THAT(m, HasSubstr("overflow"));
}

TEST_F(VolumeIo, ErrorRawDataOfTheWrongSize) {
    write("head.raw.json", R"({"dims": [2, 2, 1], "type": "f64", "header_bytes": 4})");
    const fs::path p = write("head.raw", std::string(4 + 31, '\0'));
    EXPECT_EQ(read_error(p), p.string() + ": truncated: expected 32 bytes of data, found 31");
    write("head.raw", std::string(4 + 33, '\0'));
    EXPECT_EQ(read_error(p),
              p.string() + ": dims do not match the data size: expected 32 bytes of data, found 33");

    write("head.raw.json", R"({"dims": [2, 2, 1], "type": "u8", "encoding": "gzip"})");
    write("head.raw", "not gzip at all");
    EXPECT_THAT(read_error(p), StartsWith(p.string() + ": corrupt gzip stream"));
    write("head.raw", compress("abc"));
    EXPECT_EQ(read_error(p), p.string() + ": truncated: expected 4 bytes of data, found 3 after inflating");
}

}  // namespace
