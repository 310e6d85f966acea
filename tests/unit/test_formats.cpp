// Tests of the volume readers for NIfTI-1/2, MetaImage, VTK legacy, VTK XML ImageData and VolPack .den:
// small files laid out byte by byte here (headers at the offsets the formats' specifications give,
// big-endian numbers built from shifts, base64 encoded by the test's own encoder, zlib blocks made
// with zlib's compress), read back with read_volume and compared with the numbers written; and every
// malformed file rejected with one line naming the file and what is wrong.
#include <zlib.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/io/VolumeInfo.h"
#include "core/io/VolumeReader.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;
using volref::ScalarType;
using volref::Volume;

// ---- building files ----

// The bytes of `value` in byte order `order`, from shifts of its bit pattern.
template <typename T>
std::string to_bytes(T value, std::endian order) {
    using U = std::conditional_t<
        sizeof(T) == 1, std::uint8_t,
        std::conditional_t<sizeof(T) == 2, std::uint16_t, std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
    const auto bits = static_cast<std::uint64_t>(std::bit_cast<U>(value));
    std::string out(sizeof(T), '\0');
    for (std::size_t i = 0; i < sizeof(T); ++i)
        out[order == std::endian::little ? i : sizeof(T) - 1 - i] = char((bits >> (8 * i)) & 0xff);
    return out;
}

template <typename T>
std::string to_bytes(const std::vector<T>& values, std::endian order) {
    std::string out;
    for (T v : values) out += to_bytes(v, order);
    return out;
}

// `value` written at `offset` of `buf` (which grows as needed).
template <typename T>
void put(std::string& buf, std::size_t offset, T value, std::endian order) {
    const std::string b = to_bytes(value, order);
    if (buf.size() < offset + b.size()) buf.resize(offset + b.size(), '\0');
    buf.replace(offset, b.size(), b);
}

// zlib's compress (a zlib stream), as vtkZLibDataCompressor and MetaIO write.
std::string zlib_compress(const std::string& data) {
    uLongf size = compressBound(uLong(data.size()));
    std::string out(size, '\0');
    EXPECT_EQ(compress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(data.data()),
                       uLong(data.size())),
              Z_OK);
    out.resize(size);
    return out;
}

// One gzip member.
std::string gzip(const std::string& data) {
    z_stream zs{};
    EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
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

// RFC 4648 base64 with '=' padding.
std::string base64(const std::string& data) {
    static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < data.size(); i += 3) {
        const std::size_t n = std::min<std::size_t>(3, data.size() - i);
        std::uint32_t bits = 0;
        for (std::size_t k = 0; k < 3; ++k)
            bits = bits << 8 | (k < n ? static_cast<unsigned char>(data[i + k]) : 0u);
        for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(bits >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

class Formats : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("volref-formats-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path write(const std::string& name, const std::string& bytes) const {
        std::ofstream(dir_ / name, std::ios::binary) << bytes;
        return dir_ / name;
    }
    // The message of the Error reading `path` throws; it must be one line starting with the path.
    static std::string read_error(const fs::path& path, const std::string& format = "") {
        try {
            volref::read_volume(path, format);
        } catch (const volref::Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
            EXPECT_THAT(m, StartsWith(path.string())) << m;
            return m;
        }
        ADD_FAILURE() << path << ": read without an error";
        return "";
    }
    fs::path dir_;
};

// ======================= NIfTI =======================

// A NIfTI-1 header (348 bytes, offsets of the NIfTI-1 specification) for a 3-D image; sform/qform
// fields left 0 unless set by the caller.
std::string nifti1_header(std::array<std::int16_t, 3> dims, std::int16_t datatype, std::int16_t bitpix,
                          std::endian order, std::array<float, 3> pixdim = {1, 1, 1}) {
    std::string h(348, '\0');
    put<std::int32_t>(h, 0, 348, order);
    const std::int16_t dim[8] = {3, dims[0], dims[1], dims[2], 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) put<std::int16_t>(h, 40 + 2 * std::size_t(i), dim[i], order);
    put<std::int16_t>(h, 70, datatype, order);
    put<std::int16_t>(h, 72, bitpix, order);
    const float pd[8] = {1, pixdim[0], pixdim[1], pixdim[2], 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) put<float>(h, 76 + 4 * std::size_t(i), pd[i], order);
    put<float>(h, 108, 352.0f, order);  // vox_offset
    h.replace(344, 4, std::string("n+1\0", 4));
    return h;
}

void set_sform(std::string& h, const std::array<std::array<float, 4>, 3>& rows, std::endian order) {
    put<std::int16_t>(h, 254, 1, order);  // sform_code: scanner
    for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 4; ++c) put<float>(h, 280 + 16 * r + 4 * c, rows[r][c], order);
}

TEST_F(Formats, Nifti1U16LittleEndianWithSform) {
    std::string h = nifti1_header({3, 2, 2}, 512 /* UINT16 */, 16, std::endian::little, {0.5f, 2, 3});
    set_sform(h, {{{0.5f, 0, 0, 10}, {0, 2, 0, 20}, {0, 0, 3, 30}}}, std::endian::little);
    std::vector<std::uint16_t> values(12);
    for (std::size_t n = 0; n < 12; ++n) values[n] = std::uint16_t(1000 * n + 7);
    const fs::path p = write("a.nii", h + std::string(4, '\0') + to_bytes(values, std::endian::little));
    const Volume v = volref::read_volume(p);
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 2, 2}));
    EXPECT_EQ(v.type, ScalarType::U16);
    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 2, 3));
    EXPECT_EQ(v.origin, glm::dvec3(10, 20, 30));
    EXPECT_EQ(v.at(0, 0, 0), 7.0);
    EXPECT_EQ(v.at(2, 1, 0), 5007.0);   // n = 2 + 3*1
    EXPECT_EQ(v.at(1, 1, 1), 10007.0);  // n = 1 + 3*(1 + 2*1) = 10
}

// Big-endian header and doubles, gzip-compressed (.nii.gz), an sform flipping x: voxel i of the
// file is at x = 5 - 2 i, so the volume's x axis runs the other way from x = 5 - 2*2 = 1.
TEST_F(Formats, Nifti1BigEndianDoublesGzipFlippedX) {
    std::string h = nifti1_header({3, 2, 1}, 64 /* FLOAT64 */, 64, std::endian::big, {2, 1, 1});
    set_sform(h, {{{-2, 0, 0, 5}, {0, 1, 0, -1}, {0, 0, 1, 0}}}, std::endian::big);
    const std::vector<double> values{1.5, -2.25, 3e100, 0.125, -0.0, 6.0};
    const fs::path p = write("b.nii.gz", gzip(h + std::string(4, '\0') + to_bytes(values, std::endian::big)));
    const Volume v = volref::read_volume(p);
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 2, 1}));
    EXPECT_EQ(v.type, ScalarType::F64);
    EXPECT_EQ(v.spacing, glm::dvec3(2, 1, 1));
    EXPECT_EQ(v.origin, glm::dvec3(1, -1, 0));
    // Volume voxel i holds the file's voxel 2 - i.
    EXPECT_EQ(v.at(0, 0, 0), 3e100);
    EXPECT_EQ(v.at(1, 0, 0), -2.25);
    EXPECT_EQ(v.at(2, 0, 0), 1.5);
    EXPECT_EQ(v.at(0, 1, 0), 6.0);
    EXPECT_EQ(v.at(2, 1, 0), 0.125);
}

// An sform that swaps the axes: file axis i runs along world y (spacing 2.5), j along world x (1.5).
TEST_F(Formats, Nifti1SformPermutesAxes) {
    std::string h = nifti1_header({2, 3, 1}, 2 /* UINT8 */, 8, std::endian::little);
    set_sform(h, {{{0, 1.5f, 0, 0}, {2.5f, 0, 0, 7}, {0, 0, 1, 0}}}, std::endian::little);
    const std::string data{char(10), char(11), char(20), char(21), char(30), char(31)};  // (i, j): i fastest
    const Volume v = volref::read_volume(write("c.nii", h + std::string(4, '\0') + data));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 2, 1}));
    EXPECT_EQ(v.spacing, glm::dvec3(1.5, 2.5, 1));
    EXPECT_EQ(v.origin, glm::dvec3(0, 7, 0));
    // Volume (x, y) = file (i = y, j = x): file (i, j) holds 10 (j + 1) + i.
    EXPECT_EQ(v.at(0, 0, 0), 10.0);
    EXPECT_EQ(v.at(2, 0, 0), 30.0);
    EXPECT_EQ(v.at(0, 1, 0), 11.0);
    EXPECT_EQ(v.at(2, 1, 0), 31.0);
}

// qform only: quaternion (b, c, d) = (0, 0, 1) is a half turn about z, R = diag(-1, -1, 1); with pixdim
// (1, 2, 3) and offset (4, 5, 6), voxel (i, j, k) is at (4 - i, 5 - 2 j, 6 + 3 k).
TEST_F(Formats, Nifti1QformHalfTurn) {
    std::string h = nifti1_header({2, 2, 2}, 4 /* INT16 */, 16, std::endian::little, {1, 2, 3});
    put<std::int16_t>(h, 252, 1, std::endian::little);  // qform_code
    put<float>(h, 256 + 8, 1.0f, std::endian::little);  // quatern_d
    put<float>(h, 268, 4.0f, std::endian::little);
    put<float>(h, 272, 5.0f, std::endian::little);
    put<float>(h, 276, 6.0f, std::endian::little);
    const std::vector<std::int16_t> values{-1, -2, -3, -4, -5, -6, -7, -8};
    const Volume v = volref::read_volume(write("q.nii", h + std::string(4, '\0') + to_bytes(values, std::endian::little)));
    EXPECT_EQ(v.spacing, glm::dvec3(1, 2, 3));
    EXPECT_EQ(v.origin, glm::dvec3(3, 3, 6));
    EXPECT_EQ(v.at(0, 0, 0), -4.0);  // file (1, 1, 0)
    EXPECT_EQ(v.at(1, 1, 0), -1.0);  // file (0, 0, 0)
    EXPECT_EQ(v.at(0, 1, 1), -6.0);  // file (1, 0, 1)
}

TEST_F(Formats, Nifti1ScalingAppliedAsF64) {
    std::string h = nifti1_header({2, 1, 1}, 2, 8, std::endian::little);
    put<float>(h, 112, 2.0f, std::endian::little);   // scl_slope
    put<float>(h, 116, -1.0f, std::endian::little);  // scl_inter
    const Volume v = volref::read_volume(write("s.nii", h + std::string(4, '\0') + std::string{char(3), char(200)}));
    EXPECT_EQ(v.type, ScalarType::F64);
    EXPECT_EQ(v.at(0, 0, 0), 5.0);
    EXPECT_EQ(v.at(1, 0, 0), 399.0);
}

// NIfTI-2: 540-byte header, 64-bit dims, double pixdim and sform (offsets of the NIfTI-2 specification).
TEST_F(Formats, Nifti2Float32) {
    std::string h(540, '\0');
    const auto le = std::endian::little;
    put<std::int32_t>(h, 0, 540, le);
    h.replace(4, 8, std::string("n+2\0\r\n\x1a\n", 8));
    put<std::int16_t>(h, 12, 16, le);  // FLOAT32
    put<std::int16_t>(h, 14, 32, le);
    const std::int64_t dim[8] = {3, 2, 2, 1, 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) put<std::int64_t>(h, 16 + 8 * std::size_t(i), dim[i], le);
    const double pd[8] = {1, 0.25, 0.75, 1, 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) put<double>(h, 104 + 8 * std::size_t(i), pd[i], le);
    put<std::int64_t>(h, 168, 544, le);  // vox_offset
    put<std::int32_t>(h, 348, 2, le);    // sform_code
    const double rows[3][4] = {{0.25, 0, 0, -1.5}, {0, 0.75, 0, 2.5}, {0, 0, 1, 0.1}};
    for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 4; ++c) put<double>(h, 400 + 32 * r + 8 * c, rows[r][c], le);
    const std::vector<float> values{0.1f, -7.5f, 1e30f, 2.0f};
    const Volume v = volref::read_volume(write("n2.nii", h + std::string(4, '\0') + to_bytes(values, le)));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{2, 2, 1}));
    EXPECT_EQ(v.type, ScalarType::F32);
    EXPECT_EQ(v.spacing, glm::dvec3(0.25, 0.75, 1));
    EXPECT_EQ(v.origin, glm::dvec3(-1.5, 2.5, 0.1));
    EXPECT_EQ(v.at(0, 0, 0), double(0.1f));
    EXPECT_EQ(v.at(1, 0, 0), -7.5);
    EXPECT_EQ(v.at(0, 1, 0), double(1e30f));
}

// A header + image pair (.hdr + .img, magic "ni1", vox_offset 0).
TEST_F(Formats, Nifti1HeaderImagePair) {
    std::string h = nifti1_header({2, 2, 1}, 256 /* INT8 */, 8, std::endian::little);
    h.replace(344, 4, std::string("ni1\0", 4));
    put<float>(h, 108, 0.0f, std::endian::little);
    write("pair.img", std::string{char(-128), char(-1), char(0), char(127)});
    const Volume v = volref::read_volume(write("pair.hdr", h));
    EXPECT_EQ(v.type, ScalarType::I8);
    EXPECT_EQ(v.values, (std::vector<double>{-128, -1, 0, 127}));
    fs::remove(dir_ / "pair.img");
    try {
        volref::read_volume(dir_ / "pair.hdr");
        ADD_FAILURE();
    } catch (const volref::Error& e) {
        EXPECT_THAT(e.what(), StartsWith((dir_ / "pair.img").string() + ": cannot read file"));
        EXPECT_THAT(e.what(), HasSubstr("(image file of " + (dir_ / "pair.hdr").string() + ")"));
    }
}

TEST_F(Formats, NiftiErrors) {
    const auto le = std::endian::little;
    const std::string data(12, 'x');
    std::string h = nifti1_header({3, 2, 2}, 2, 8, le);

    std::string bad = h;
    bad.replace(344, 4, std::string("x+1\0", 4));
    EXPECT_THAT(read_error(write("m.nii", bad + std::string(4, '\0') + data)), HasSubstr("bad magic at byte 344"));

    bad = h;
    put<std::int32_t>(bad, 0, 347, le);
    EXPECT_THAT(read_error(write("s.nii", bad + std::string(4, '\0') + data)),
                HasSubstr("not a NIfTI file: sizeof_hdr at byte 0 is 347"));

    EXPECT_THAT(read_error(write("h.nii", h.substr(0, 200))), HasSubstr("truncated header: expected 348 bytes"));

    EXPECT_THAT(read_error(write("t.nii", h + std::string(4, '\0') + data.substr(0, 10))),
                HasSubstr("truncated: expected 12 bytes of data, found 10"));
    EXPECT_THAT(read_error(write("t.nii.gz", gzip(h + std::string(4, '\0') + data.substr(0, 10)))),
                HasSubstr("truncated: expected 12 bytes of data, found 10 after inflating"));

    bad = h;
    put<std::int16_t>(bad, 40 + 2 * 2, 0, le);  // dim[2] = 0
    EXPECT_THAT(read_error(write("d.nii", bad + std::string(4, '\0') + data)), HasSubstr("dim[2] must be >= 1, got 0"));

    bad = h;
    put<std::int16_t>(bad, 40, 4, le);          // dim[0] = 4
    put<std::int16_t>(bad, 40 + 2 * 4, 2, le);  // two volumes
    EXPECT_THAT(read_error(write("4d.nii", bad + std::string(4, '\0') + data + data)), HasSubstr("dim[4] is 2"));

    bad = nifti1_header({3, 2, 2}, 1024 /* INT64 */, 64, le);
    EXPECT_THAT(read_error(write("i64.nii", bad + std::string(4, '\0') + std::string(96, '\0'))),
                HasSubstr("datatype (byte 70) 1024"));
    bad = nifti1_header({3, 2, 2}, 3, 8, le);
    EXPECT_THAT(read_error(write("dt3.nii", bad + std::string(4, '\0') + data)),
                HasSubstr("datatype (byte 70) 3 is not a NIfTI datatype"));

    bad = h;
    set_sform(bad, {{{0.7f, 0.7f, 0, 0}, {-0.7f, 0.7f, 0, 0}, {0, 0, 1, 0}}}, le);
    EXPECT_THAT(read_error(write("o.nii", bad + std::string(4, '\0') + data)), HasSubstr("sform is oblique"));
}

// ======================= MetaImage =======================

TEST_F(Formats, MetaImageDetachedShortBigEndian) {
    const std::vector<std::int16_t> values{-300, 2, 32767, -32768, 5, 6};
    write("v.raw", to_bytes(values, std::endian::big));
    const fs::path p = write("v.mhd",
                             "ObjectType = Image\nNDims = 3\nDimSize = 3 1 2\nElementType = MET_SHORT\n"
                             "ElementSpacing = 0.5 1 2.5\nOffset = -1 2 3.25\nBinaryData = True\n"
                             "BinaryDataByteOrderMSB = True\nElementDataFile = v.raw\n");
    const Volume v = volref::read_volume(p);
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 1, 2}));
    EXPECT_EQ(v.type, ScalarType::I16);
    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 1, 2.5));
    EXPECT_EQ(v.origin, glm::dvec3(-1, 2, 3.25));
    EXPECT_EQ(v.at(0, 0, 0), -300.0);
    EXPECT_EQ(v.at(2, 0, 0), 32767.0);
    EXPECT_EQ(v.at(0, 0, 1), -32768.0);
    EXPECT_EQ(v.at(2, 0, 1), 6.0);
}

TEST_F(Formats, MetaImageInlineDoubleAndHeaderSize) {
    const std::vector<double> values{1.0 / 3.0, -2.5, 1e-300, 4.0};
    const Volume v = volref::read_volume(write(
        "v.mha", "NDims = 2\nDimSize = 2 2\nElementType = MET_DOUBLE\nElementByteOrderMSB = False\n"
                 "ElementDataFile = LOCAL\n" + to_bytes(values, std::endian::little)));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{2, 2, 1}));
    EXPECT_EQ(v.at(0, 0, 0), 1.0 / 3.0);
    EXPECT_EQ(v.at(0, 1, 0), 1e-300);

    write("u.raw", std::string("HEAD") + char(9) + char(250));
    const Volume u = volref::read_volume(
        write("u.mhd", "NDims = 1\nDimSize = 2\nElementType = MET_UCHAR\nHeaderSize = 4\nElementDataFile = u.raw\n"));
    EXPECT_EQ(u.values, (std::vector<double>{9, 250}));
}

TEST_F(Formats, MetaImageCompressedFloat) {
    const std::vector<float> values{0.5f, -1.25f, 3.0f, 1e20f, -0.0f, 7.0f};
    const std::string packed = zlib_compress(to_bytes(values, std::endian::little));
    const Volume v = volref::read_volume(
        write("c.mha", "NDims = 3\nDimSize = 1 2 3\nElementType = MET_FLOAT\nCompressedData = True\n"
                       "CompressedDataSize = " + std::to_string(packed.size()) + "\nElementDataFile = LOCAL\n" + packed));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{1, 2, 3}));
    EXPECT_EQ(v.at(0, 1, 0), -1.25);
    EXPECT_EQ(v.at(0, 1, 1), double(1e20f));
    EXPECT_EQ(v.at(0, 1, 2), 7.0);
}

// HeaderSize = -1: the samples end the data file, whatever precedes them.
TEST_F(Formats, MetaImageHeaderSizeMinusOne) {
    write("t.raw", std::string("anything at all") + char(1) + char(2) + char(3));
    const Volume v = volref::read_volume(
        write("t.mhd", "NDims = 1\nDimSize = 3\nElementType = MET_CHAR\nHeaderSize = -1\nElementDataFile = t.raw\n"));
    EXPECT_EQ(v.values, (std::vector<double>{1, 2, 3}));
}

TEST_F(Formats, MetaImageErrors) {
    const std::string head = "NDims = 3\nDimSize = 2 2 1\n";
    EXPECT_THAT(read_error(write("a.mha", head + "ElementType = MET_LONG_LONG\nElementDataFile = LOCAL\n" + std::string(32, 'x'))),
                HasSubstr("line 3: ElementType: type 'MET_LONG_LONG' is not supported"));
    EXPECT_THAT(read_error(write("b.mha", head + "ElementType = UCHAR\nElementDataFile = LOCAL\n")),
                HasSubstr("unknown type 'UCHAR'"));
    EXPECT_THAT(read_error(write("c.mha", "NDims = 3\nElementType = MET_UCHAR\nElementDataFile = LOCAL\nxxxx")),
                HasSubstr("missing required key 'DimSize'"));
    EXPECT_THAT(read_error(write("d.mha", head + "ElementType = MET_USHORT\nElementDataFile = LOCAL\n" + std::string(7, 'x'))),
                HasSubstr("truncated: expected 8 bytes of data, found 7"));
    EXPECT_THAT(read_error(write("e.mha", "NDims = 3\nDimSize = 2 0 1\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n")),
                HasSubstr("DimSize: expected numbers > 0"));
    EXPECT_THAT(read_error(write("f.mha", "NDims = 4\nDimSize = 2 2 1 1\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n")),
                HasSubstr("NDims: 4 dimensions are not supported"));
    EXPECT_THAT(read_error(write("g.mha", head + "ElementType = MET_UCHAR\nTransformMatrix = 0 1 0 1 0 0 0 0 1\n"
                                                 "ElementDataFile = LOCAL\nxxxx")),
                HasSubstr("TransformMatrix: only the identity is supported"));
    const std::string packed = zlib_compress(std::string(4, 'x'));
    EXPECT_THAT(read_error(write("h.mha", head + "ElementType = MET_UCHAR\nCompressedData = True\nCompressedDataSize = " +
                                              std::to_string(packed.size() + 5) + "\nElementDataFile = LOCAL\n" + packed)),
                HasSubstr("truncated: CompressedDataSize is " + std::to_string(packed.size() + 5)));
    EXPECT_THAT(read_error(write("i.mha", head + "ElementType = MET_UCHAR\nCompressedData = True\nElementDataFile = LOCAL\n" +
                                              packed.substr(0, packed.size() - 3))),
                HasSubstr("corrupt gzip stream"));
    const fs::path missing = write("j.mhd", head + "ElementType = MET_UCHAR\nElementDataFile = nothere.raw\n");
    try {
        volref::read_volume(missing);
        ADD_FAILURE();
    } catch (const volref::Error& e) {
        EXPECT_THAT(e.what(), HasSubstr("nothere.raw: cannot read file"));
    }
}

// ======================= VTK legacy =======================

TEST_F(Formats, VtkLegacyAsciiUnsignedShort) {
    const Volume v = volref::read_volume(write(
        "a.vtk", "# vtk DataFile Version 3.0\nsome title\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 3 1\n"
                 "ORIGIN 1.5 -2 0\nSPACING 0.5 0.25 1\n\nPOINT_DATA 6\nSCALARS density unsigned_short 1\n"
                 "LOOKUP_TABLE default\n0 1 65535\n300 4 5\n"));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{2, 3, 1}));
    EXPECT_EQ(v.type, ScalarType::U16);
    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.25, 1));
    EXPECT_EQ(v.origin, glm::dvec3(1.5, -2, 0));
    EXPECT_EQ(v.at(0, 1, 0), 65535.0);
    EXPECT_EQ(v.at(1, 1, 0), 300.0);
    EXPECT_EQ(v.at(1, 2, 0), 5.0);
}

TEST_F(Formats, VtkLegacyBinaryBigEndianDouble) {
    const std::vector<double> values{1.0 / 7.0, -1e-310, 2.5, -4.0};
    const std::string head = "# vtk DataFile Version 2.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 1 2 2\n"
                             "ASPECT_RATIO 1 2 3\nPOINT_DATA 4\nSCALARS s double\nLOOKUP_TABLE default\n";
    const Volume v = volref::read_volume(write("b.vtk", head + to_bytes(values, std::endian::big) + "\n"));
    EXPECT_EQ(v.type, ScalarType::F64);
    EXPECT_EQ(v.spacing, glm::dvec3(1, 2, 3));
    EXPECT_EQ(v.at(0, 0, 0), 1.0 / 7.0);
    EXPECT_EQ(v.at(0, 1, 0), -1e-310);
    EXPECT_EQ(v.at(0, 1, 1), -4.0);
}

TEST_F(Formats, VtkLegacyBinaryShortUcharFloat) {
    const std::string head = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 1 1\nPOINT_DATA 3\n";
    const Volume s = volref::read_volume(write("s.vtk", head + "SCALARS s short\nLOOKUP_TABLE t\n" +
                                                            to_bytes(std::vector<std::int16_t>{-2, 258, -32768}, std::endian::big)));
    EXPECT_EQ(s.values, (std::vector<double>{-2, 258, -32768}));
    const Volume u = volref::read_volume(write("u.vtk", head + "SCALARS s unsigned_char\nLOOKUP_TABLE t\n" +
                                                            std::string{char(0), char(128), char(255)}));
    EXPECT_EQ(u.values, (std::vector<double>{0, 128, 255}));
    const Volume f = volref::read_volume(write("f.vtk", head + "SCALARS s float 1\nLOOKUP_TABLE t\n" +
                                                            to_bytes(std::vector<float>{0.1f, -3.5f, 1e38f}, std::endian::big)));
    EXPECT_EQ(f.type, ScalarType::F32);
    EXPECT_EQ(f.values, (std::vector<double>{double(0.1f), -3.5, double(1e38f)}));
}

TEST_F(Formats, VtkLegacyErrors) {
    const std::string head = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\n";
    EXPECT_THAT(read_error(write("a.vtk", "# not vtk\nt\nASCII\n")), HasSubstr("not a VTK legacy file: line 1 is '# not vtk'"));
    EXPECT_THAT(read_error(write("b.vtk", "# vtk DataFile Version 3.0\nt\nTEXT\n")), HasSubstr("line 3: expected ASCII or BINARY"));
    EXPECT_THAT(read_error(write("c.vtk", head + "POINT_DATA 4\nSCALARS s short\nLOOKUP_TABLE d\n" + std::string(7, 'x'))),
                HasSubstr("line 9: truncated: expected 8 bytes of data, found 7"));
    EXPECT_THAT(read_error(write("d.vtk", head + "POINT_DATA 5\nSCALARS s short\nLOOKUP_TABLE d\n" + std::string(10, 'x'))),
                HasSubstr("line 6: POINT_DATA 5 does not match DIMENSIONS 2 x 2 x 1 = 4"));
    EXPECT_THAT(read_error(write("e.vtk", head + "POINT_DATA 4\nSCALARS s long\nLOOKUP_TABLE d\n")),
                HasSubstr("line 7: SCALARS: type 'long' is not supported"));
    EXPECT_THAT(read_error(write("f.vtk", head + "POINT_DATA 4\nSCALARS s complex\nLOOKUP_TABLE d\n")),
                HasSubstr("unknown type 'complex'"));
    EXPECT_THAT(read_error(write("g.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n"
                                          "DIMENSIONS 2 2 1\nPOINT_DATA 4\nSCALARS s float\nLOOKUP_TABLE d\n1 2\n3\n")),
                HasSubstr("truncated: expected 4 values of data, found 3"));
    EXPECT_THAT(read_error(write("h.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n"
                                          "DIMENSIONS 2 0 1\n")),
                HasSubstr("line 5: DIMENSIONS: expected an integer >= 1, got '0'"));
    EXPECT_THAT(read_error(write("i.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n")),
                HasSubstr("DATASET 'POLYDATA' is not supported"));
    EXPECT_THAT(read_error(write("j.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n"
                                          "DIMENSIONS 2 2 1\nPOINT_DATA 4\nSCALARS s unsigned_char\nLOOKUP_TABLE d\n1 2\n3 256\n")),
                HasSubstr("line 10: ascii sample 3: '256' is not an integer in the range of u8"));
}

// ======================= VTK XML ImageData =======================

std::string vti(const std::string& file_attributes, const std::string& array, const std::string& after = "") {
    return "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" " + file_attributes +
           ">\n  <ImageData WholeExtent=\"1 2 0 1 4 4\" Origin=\"10 20 30\" Spacing=\"0.5 2 4\">\n"
           "    <Piece Extent=\"1 2 0 1 4 4\">\n      <PointData Scalars=\"f\">\n" +
           array + "\n      </PointData>\n    </Piece>\n  </ImageData>\n" + after + "</VTKFile>\n";
}

// The expected grid of the files `vti` makes: extent 1..2 x 0..1 x 4..4, so dims 2 x 2 x 1 and
// origin (10 + 1 * 0.5, 20 + 0 * 2, 30 + 4 * 4).
void expect_vti_grid(const Volume& v) {
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{2, 2, 1}));
    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 2, 4));
    EXPECT_EQ(v.origin, glm::dvec3(10.5, 20, 46));
}

TEST_F(Formats, VtiAsciiInt16) {
    const Volume v = volref::read_volume(write(
        "a.vti", vti("byte_order=\"LittleEndian\"",
                     "<DataArray type=\"Int16\" Name=\"other\" format=\"ascii\">9 9 9 9</DataArray>\n"
                     "<DataArray type=\"Int16\" Name=\"f\" format=\"ascii\">\n -5 6\n 7 -32768 </DataArray>")));
    expect_vti_grid(v);
    EXPECT_EQ(v.type, ScalarType::I16);
    EXPECT_EQ(v.values, (std::vector<double>{-5, 6, 7, -32768}));
}

TEST_F(Formats, VtiBase64UncompressedFloat64) {
    const std::vector<double> values{0.1, -2.0, 1e200, 3.5};
    const std::string payload = to_bytes<std::uint32_t>(32, std::endian::little) + to_bytes(values, std::endian::little);
    const Volume v = volref::read_volume(write(
        "b.vti", vti("byte_order=\"LittleEndian\" header_type=\"UInt32\"",
                     "<DataArray type=\"Float64\" Name=\"f\" format=\"binary\">\n  " + base64(payload) + "\n</DataArray>")));
    expect_vti_grid(v);
    EXPECT_EQ(v.values, values);
}

// Two zlib blocks of 8 and 4 bytes (block size 8, last block 4), UInt64 header, big-endian, base64:
// the header and the blocks are two separate base64 streams, as VTK writes them.
TEST_F(Formats, VtiBase64ZlibBigEndianUInt64Header) {
    const std::vector<float> values{1.5f, -2.5f, 1e-30f};
    const std::string raw = to_bytes(values, std::endian::big);
    const std::string b0 = zlib_compress(raw.substr(0, 8)), b1 = zlib_compress(raw.substr(8));
    std::string header;
    for (std::uint64_t w : {std::uint64_t(2), std::uint64_t(8), std::uint64_t(4), std::uint64_t(b0.size()), std::uint64_t(b1.size())})
        header += to_bytes(w, std::endian::big);
    const std::string doc = "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" byte_order=\"BigEndian\" header_type=\"UInt64\" "
                            "compressor=\"vtkZLibDataCompressor\">\n<ImageData WholeExtent=\"0 2 0 0 0 0\">\n<Piece Extent=\"0 2 0 0 0 0\">\n"
                            "<PointData>\n<DataArray type=\"Float32\" Name=\"f\" format=\"binary\">" +
                            base64(header) + base64(b0 + b1) + "</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n";
    const Volume v = volref::read_volume(write("c.vti", doc));
    EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 1, 1}));
    EXPECT_EQ(v.spacing, glm::dvec3(1.0));
    EXPECT_EQ(v.values, (std::vector<double>{1.5, -2.5, double(1e-30f)}));
}

TEST_F(Formats, VtiAppendedRawBigEndianUInt16) {
    const std::vector<std::uint16_t> values{1, 256, 65535, 4660};
    const std::string data = to_bytes<std::uint32_t>(99, std::endian::big) +  // another array at offset 0 (ignored)
                             to_bytes<std::uint32_t>(8, std::endian::big) + to_bytes(values, std::endian::big);
    const Volume v = volref::read_volume(write(
        "d.vti", vti("byte_order=\"BigEndian\"", "<DataArray type=\"UInt16\" Name=\"f\" format=\"appended\" offset=\"4\"/>",
                     "  <AppendedData encoding=\"raw\">\n   _" + data + "\n  </AppendedData>\n")));
    expect_vti_grid(v);
    EXPECT_EQ(v.values, (std::vector<double>{1, 256, 65535, 4660}));
}

TEST_F(Formats, VtiAppendedRawZlibAndAppendedBase64) {
    const std::vector<std::int32_t> values{-1, 2, -300000, 2147483647};
    const std::string raw = to_bytes(values, std::endian::little);
    const std::string block = zlib_compress(raw);
    const std::string data = to_bytes<std::uint32_t>(1, std::endian::little) + to_bytes<std::uint32_t>(16, std::endian::little) +
                             to_bytes<std::uint32_t>(0, std::endian::little) +
                             to_bytes<std::uint32_t>(std::uint32_t(block.size()), std::endian::little) + block;
    const Volume v = volref::read_volume(write(
        "e.vti", vti("compressor=\"vtkZLibDataCompressor\"", "<DataArray type=\"Int32\" Name=\"f\" format=\"appended\" offset=\"0\"/>",
                     "<AppendedData encoding=\"raw\">_" + data + "</AppendedData>\n")));
    expect_vti_grid(v);
    EXPECT_EQ(v.values, (std::vector<double>{-1, 2, -300000, 2147483647}));

    const std::string text = base64(to_bytes<std::uint32_t>(4, std::endian::little) + std::string{char(7), char(8), char(9), char(10)});
    const Volume w = volref::read_volume(write(
        "f.vti", vti("", "<DataArray type=\"UInt8\" Name=\"f\" format=\"appended\" offset=\"4\"/>",
                     "<AppendedData encoding=\"base64\">_AAAA" + text + "</AppendedData>\n")));
    EXPECT_EQ(w.values, (std::vector<double>{7, 8, 9, 10}));
}

TEST_F(Formats, VtiErrors) {
    EXPECT_THAT(read_error(write("a.vti", "<VTKFile type=\"ImageData\"><ImageData></VTKFile>")), HasSubstr("line 1: XML error: mismatched tag"));
    EXPECT_THAT(read_error(write("b.vti", "<VTKFile type=\"PolyData\"></VTKFile>")),
                HasSubstr("VTKFile type: 'PolyData' is not supported"));
    EXPECT_THAT(read_error(write("c.vti", vti("compressor=\"vtkLZ4DataCompressor\"", "<DataArray type=\"UInt8\" Name=\"f\"/>"))),
                HasSubstr("compressor: 'vtkLZ4DataCompressor' is not supported"));
    EXPECT_THAT(read_error(write("d.vti", vti("", "<DataArray type=\"Int64\" Name=\"f\" format=\"ascii\">1 2 3 4</DataArray>"))),
                HasSubstr("DataArray type: 'Int64' is not supported"));
    // The byte-count header says 3 bytes for 4 samples of UInt8.
    EXPECT_THAT(read_error(write("e.vti", vti("", "<DataArray type=\"UInt8\" Name=\"f\" format=\"binary\">" +
                                                       base64(to_bytes<std::uint32_t>(3, std::endian::little) + "abc") + "</DataArray>"))),
                HasSubstr("the header gives 3 bytes of data, expected 4"));
    EXPECT_THAT(read_error(write("f.vti", vti("", "<DataArray type=\"UInt8\" Name=\"f\" format=\"binary\">AAA*AAAA</DataArray>"))),
                HasSubstr("base64 character 3: '*' is not base64"));
    // A compressed size larger than the data that follow: truncated.
    const std::string block = zlib_compress("abcd");
    std::string header;
    for (std::uint32_t w : {1u, 4u, 0u, std::uint32_t(block.size() + 100)}) header += to_bytes(w, std::endian::little);
    EXPECT_THAT(read_error(write("g.vti", vti("compressor=\"vtkZLibDataCompressor\"",
                                             "<DataArray type=\"UInt8\" Name=\"f\" format=\"appended\" offset=\"0\"/>",
                                             "<AppendedData encoding=\"raw\">_" + header + block))),
                HasSubstr("truncated: block 0 (compressed size " + std::to_string(block.size() + 100)));
    // A compressed size smaller than the block: the zlib stream ends early.
    header.clear();
    for (std::uint32_t w : {1u, 4u, 0u, std::uint32_t(block.size() - 4)}) header += to_bytes(w, std::endian::little);
    EXPECT_THAT(read_error(write("h.vti", vti("compressor=\"vtkZLibDataCompressor\"",
                                             "<DataArray type=\"UInt8\" Name=\"f\" format=\"appended\" offset=\"0\"/>",
                                             "<AppendedData encoding=\"raw\">_" + header + block + "</AppendedData>"))),
                HasSubstr("block 0: corrupt gzip stream"));
    // Uncompressed total of the blocks not matching the extent.
    header.clear();
    for (std::uint32_t w : {1u, 5u, 0u, std::uint32_t(block.size())}) header += to_bytes(w, std::endian::little);
    EXPECT_THAT(read_error(write("i.vti", vti("compressor=\"vtkZLibDataCompressor\"",
                                             "<DataArray type=\"UInt8\" Name=\"f\" format=\"appended\" offset=\"0\"/>",
                                             "<AppendedData encoding=\"raw\">_" + header + block + "</AppendedData>"))),
                HasSubstr("the compression header describes 5 bytes"));
    EXPECT_THAT(read_error(write("j.vti", vti("", "<DataArray type=\"UInt8\" Name=\"g\" format=\"ascii\">1 2 3 4</DataArray>"))),
                HasSubstr("PointData Scalars: no DataArray is named 'f'"));
}

// ======================= VolPack .den =======================

std::string den_header(std::array<std::int16_t, 3> len, std::int32_t length, std::endian order) {
    std::string h;
    put<std::int16_t>(h, 0, 1, order);  // map_version
    for (int a = 0; a < 3; ++a) put<std::int16_t>(h, 50 + 2 * std::size_t(a), len[std::size_t(a)], order);  // map_len
    put<std::int32_t>(h, 58, length, order);  // map_length
    return h;
}

TEST_F(Formats, DenBothByteOrders) {
    std::string data;
    for (int n = 0; n < 12; ++n) data += char(20 * n);
    for (const auto order : {std::endian::little, std::endian::big}) {
        const Volume v = volref::read_volume(write("a.den", den_header({3, 2, 2}, 12, order) + data));
        EXPECT_EQ(v.dims, (std::array<std::int64_t, 3>{3, 2, 2}));
        EXPECT_EQ(v.type, ScalarType::U8);
        EXPECT_EQ(v.spacing, glm::dvec3(1.0));
        EXPECT_EQ(v.at(2, 1, 0), 100.0);
        EXPECT_EQ(v.at(2, 1, 1), 220.0);
    }
}

TEST_F(Formats, DenErrors) {
    const std::string data(12, 'x');
    std::string bad = den_header({3, 2, 2}, 12, std::endian::little);
    bad[0] = 2;
    EXPECT_THAT(read_error(write("a.den", bad + data)), HasSubstr("not a VolPack .den file: map_version at byte 0"));
    EXPECT_THAT(read_error(write("b.den", den_header({3, 2, 2}, 12, std::endian::little) + data.substr(0, 11))),
                HasSubstr("truncated: expected 12 bytes of data, found 11"));
    EXPECT_THAT(read_error(write("c.den", den_header({3, 2, 2}, 13, std::endian::big) + data)),
                HasSubstr("map_length at byte 58 is 13, expected map_len 3 x 2 x 2 = 12"));
    EXPECT_THAT(read_error(write("d.den", den_header({3, 0, 2}, 0, std::endian::little))),
                HasSubstr("map_len[1] at byte 52 must be >= 1, got 0"));
    EXPECT_THAT(read_error(write("e.den", den_header({3, 2, 2}, 12, std::endian::little).substr(0, 40))),
                HasSubstr("truncated header: expected 62 bytes, found 40"));
}

// volref info's summary: range over the finite values, NaN and infinities counted apart; with 4 bins
// over [0, 4] of width 1, value v goes to bin floor(v), and the maximum 4 to the last bin.
TEST(FormatsSummary, HistogramByHand) {
    Volume v;
    v.dims = {7, 1, 1};
    v.values = {0, 1, 2, 3, std::nan(""), -INFINITY, 4};
    const volref::VolumeSummary s = volref::summarize(v, 4);
    EXPECT_EQ(s.voxels, 7u);
    EXPECT_EQ(s.finite, 5u);
    EXPECT_EQ(s.nan, 1u);
    EXPECT_EQ(s.infinite, 1u);
    EXPECT_EQ(s.min, 0.0);
    EXPECT_EQ(s.max, 4.0);
    EXPECT_EQ(s.histogram, (std::vector<std::uint64_t>{1, 1, 1, 2}));
    v.values = {5, 5, 5, 5, 5, 5, 5};  // min == max: all in bin 0
    EXPECT_EQ(volref::summarize(v, 3).histogram, (std::vector<std::uint64_t>{7, 0, 0}));
}

TEST_F(Formats, ExplicitFormatOverridesTheExtension) {
    std::string data;
    for (int n = 0; n < 12; ++n) data += char(n);
    const Volume v = volref::read_volume(write("volume.bin", den_header({3, 2, 2}, 12, std::endian::little) + data), "den");
    EXPECT_EQ(v.at(1, 1, 1), 10.0);
    EXPECT_EQ(volref::volume_format("x.NII.GZ"), "nifti");
    EXPECT_EQ(volref::volume_format("x.mha"), "metaimage");
    EXPECT_EQ(volref::volume_format("x.vti"), "vti");
}

}  // namespace

// ======================= issue 32: what a header says, as stored, and once =======================

// NIfTI values as the file holds them (nifti_clib would read pixdim 0 as 1 and a vox_offset inside the
// header as its end): each refused naming its field and byte.
TEST_F(Formats, NiftiHeaderFieldsAsStored) {
    const auto le = std::endian::little;
    const std::string data(12, 'x');
    const std::string h = nifti1_header({3, 2, 2}, 2, 8, le);
    std::string bad = h;
    put<float>(bad, 80, 0.0f, le);  // pixdim[1]
    EXPECT_THAT(read_error(write("p0.nii", bad + std::string(4, '\0') + data)),
                HasSubstr("pixdim[1] (byte 80) must be finite and non-zero, got 0"));
    bad = h;
    put<float>(bad, 80, std::numeric_limits<float>::quiet_NaN(), le);
    EXPECT_THAT(read_error(write("pn.nii", bad + std::string(4, '\0') + data)), HasSubstr("pixdim[1] (byte 80)"));
    for (float off : {10.0f, 1e30f, 352.5f}) {
        bad = h;
        put<float>(bad, 108, off, le);  // vox_offset
        const std::string m = read_error(write("v.nii", bad + std::string(4, '\0') + data));
        EXPECT_THAT(m, HasSubstr("vox_offset (byte 108)")) << off;
    }
    bad = h;
    put<float>(bad, 112, std::numeric_limits<float>::quiet_NaN(), le);  // scl_slope
    EXPECT_THAT(read_error(write("s.nii", bad + std::string(4, '\0') + data)), HasSubstr("scl_slope (byte 112)"));
    bad = h;
    put<float>(bad, 112, 2.0f, le);
    put<float>(bad, 116, std::numeric_limits<float>::infinity(), le);  // scl_inter
    EXPECT_THAT(read_error(write("i.nii", bad + std::string(4, '\0') + data)), HasSubstr("scl_inter (byte 116)"));
    bad = h;
    set_sform(bad, {{{1, 0, 0, 0}, {0, std::numeric_limits<float>::quiet_NaN(), 0, 0}, {0, 0, 1, 0}}}, le);
    const std::string m = read_error(write("f.nii", bad + std::string(4, '\0') + data));
    EXPECT_THAT(m, HasSubstr("non-finite number (srow_y[1])"));
    EXPECT_THAT(m, Not(HasSubstr("oblique")));
    // NIfTI-2: a negative vox_offset (int64 at byte 168)
    std::string h2(540, '\0');
    put<std::int32_t>(h2, 0, 540, le);
    h2.replace(4, 8, std::string("n+2\0\r\n\x1a\n", 8));
    put<std::int16_t>(h2, 12, 2, le);
    put<std::int16_t>(h2, 14, 8, le);
    const std::int64_t dim[8] = {3, 2, 2, 1, 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) put<std::int64_t>(h2, 16 + 8 * std::size_t(i), dim[i], le);
    for (int i = 0; i < 8; ++i) put<double>(h2, 104 + 8 * std::size_t(i), 1.0, le);
    put<std::int64_t>(h2, 168, -5, le);
    EXPECT_THAT(read_error(write("n2.nii", h2 + std::string(4, '\0') + "abcd")), HasSubstr("vox_offset (byte 168) must be a whole number >= 0, got -5"));
    put<std::int64_t>(h2, 168, 544, le);
    EXPECT_NO_THROW(volref::read_volume(write("n2ok.nii", h2 + std::string(4, '\0') + "abcd")));
}

// A header that says one thing twice, or two things, is an error naming both (issue 32).
TEST_F(Formats, HeadersThatContradictThemselves) {
    const std::string mha = "NDims = 1\nDimSize = 2\nElementType = MET_UCHAR\n";
    EXPECT_THAT(read_error(write("o.mha", mha + "Offset = 1\nOrigin = 2\nElementDataFile = LOCAL\nab")),
                HasSubstr("line 5: Origin = '2' contradicts Offset = '1' on line 4"));
    EXPECT_THAT(read_error(write("r.mha", mha + "TransformMatrix = 1\nRotation = -1\nElementDataFile = LOCAL\nab")),
                HasSubstr("contradicts TransformMatrix"));
    EXPECT_THAT(read_error(write("b.mha", mha + "ElementByteOrderMSB = True\nBinaryDataByteOrderMSB = False\nElementDataFile = LOCAL\nab")),
                HasSubstr("contradicts ElementByteOrderMSB"));
    // the same value under both names is one statement
    EXPECT_NO_THROW(volref::read_volume(write("s.mha", mha + "Offset = 1\nPosition = 1\nElementDataFile = LOCAL\nab")));
    const std::string vtk = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 1 1\n";
    EXPECT_THAT(read_error(write("d.vtk", vtk + "DIMENSIONS 2 1 1\nPOINT_DATA 2\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\n1 2\n")),
                HasSubstr("DIMENSIONS given twice (first on line 5)"));
    EXPECT_THAT(read_error(write("s.vtk", vtk + "SPACING 1 1 1\nASPECT_RATIO 2 2 2\nPOINT_DATA 2\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\n1 2\n")),
                HasSubstr("SPACING given twice (as ASPECT_RATIO) (first on line 6)"));
    // a sidecar with "type" twice, or bytes after a NUL
    write("v.raw", "ab");
    write("v.raw.json", R"({"dims": [2, 1, 1], "type": "u8", "type": "u16"})");
    EXPECT_THAT(read_error(dir_ / "v.raw"), HasSubstr("type: duplicate key"));
    write("v.raw.json", std::string(R"({"dims": [2, 1, 1], "type": "u8"})") + '\0' + "garbage");
    const std::string m = read_error(dir_ / "v.raw");
    EXPECT_THAT(m, HasSubstr("v.raw.json"));
    EXPECT_THAT(m, HasSubstr("NUL byte"));
}

// Special files are refused by type before they are opened (reading a FIFO without a writer would block).
TEST_F(Formats, SpecialFilesAreRefusedByType) {
    const fs::path fifo = dir_ / "v.nrrd";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_THAT(read_error(fifo), HasSubstr("it is a FIFO"));
    write("h.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\nencoding: raw\ndata file: v.nrrd\n\n");
    try {
        volref::read_volume(dir_ / "h.nhdr");
        ADD_FAILURE();
    } catch (const volref::Error& e) {
        EXPECT_THAT(e.what(), HasSubstr("it is a FIFO"));
    }
    try {
        volref::read_volume("/dev/zero", "raw");
        ADD_FAILURE();
    } catch (const volref::Error& e) {
        EXPECT_THAT(e.what(), HasSubstr("/dev/zero: cannot read file: it is a character device"));
    }
}
