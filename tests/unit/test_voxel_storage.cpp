// Typed voxel storage (core/grid/VoxelArray.h): a volume keeps its file's type in memory, every read
// converts to double exactly, and the renderer's images do not depend on the storage type (bitwise,
// on the scalar and the SIMD paths).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <functional>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <unistd.h>

#include <hwy/targets.h>

#include "TestScenes.h"
#include "core/grid/Volume.h"
#include "core/io/VolumeReader.h"
#include "core/sample/VolumeSampler.h"

using namespace volref;
using namespace volref::test;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
    static const fs::path dir = [] {
        const fs::path d = fs::temp_directory_path() / ("volref_voxels_" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

const char* nrrd_type(ScalarType t) {
    switch (t) {
        case ScalarType::U8: return "uchar";
        case ScalarType::I8: return "signed char";
        case ScalarType::U16: return "ushort";
        case ScalarType::I16: return "short";
        case ScalarType::U32: return "uint";
        case ScalarType::I32: return "int";
        case ScalarType::F32: return "float";
        case ScalarType::F64: return "double";
    }
    return "?";
}

// A NRRD file holding `values` as `type` (little-endian raw, attached), written byte by byte here
// (not by volref's writer). Returns its path and the number of data bytes.
std::pair<fs::path, std::size_t> write_nrrd_file(const std::string& name, ScalarType type, std::array<std::int64_t, 3> dims,
                                                 const std::vector<double>& values, bool big_endian = false) {
    std::string data;
    for (double x : values) {
        dispatch_scalar_type(type, [&](auto tag) {
            using T = decltype(tag);
            const T v = T(x);
            EXPECT_EQ(double(v), x) << "test value not representable";
            char b[sizeof(T)];
            std::memcpy(b, &v, sizeof(T));
            if (big_endian) std::reverse(b, b + sizeof(T));
            data.append(b, sizeof(T));
        });
    }
    const std::string header = std::string("NRRD0004\ntype: ") + nrrd_type(type) + "\ndimension: 3\nsizes: " +
                               std::to_string(dims[0]) + " " + std::to_string(dims[1]) + " " + std::to_string(dims[2]) +
                               "\nendian: " + (big_endian ? "big" : "little") + "\nencoding: raw\n\n";
    const fs::path p = temp_dir() / name;
    std::ofstream out(p, std::ios::binary);
    out << header << data;
    return {p, data.size()};
}

constexpr ScalarType kTypes[] = {ScalarType::U8,  ScalarType::I8,  ScalarType::U16, ScalarType::I16,
                                 ScalarType::U32, ScalarType::I32, ScalarType::F32, ScalarType::F64};

// Values of each type spread over its range (negative for the signed types, above 2^31 for u32,
// above 127 for u8 and above 32767 for u16, so sign and zero extension both matter): a 0..100
// pattern p, mapped per type.
double typed_value(ScalarType t, int p) {
    switch (t) {
        case ScalarType::U8: return 2.0 * p;
        case ScalarType::I8: return p - 60.0;
        case ScalarType::U16: return 650.0 * p;
        case ScalarType::I16: return 650.0 * p - 32768.0;
        case ScalarType::U32: return 42949672.0 * p + 95.0;
        case ScalarType::I32: return 42949672.0 * p - 2147483648.0;
        case ScalarType::F32: return double(float(p * 0.37f - 10.0f));
        case ScalarType::F64: return p * 1e-3 - 0.01;
    }
    return 0.0;
}

}  // namespace

TEST(VoxelArray, HoldsEachTypeInItsOwnSizeAndReadsItExactly) {
    for (ScalarType t : kTypes) {
        SCOPED_TRACE(scalar_type_name(t));
        VoxelArray a(t, 1000);
        EXPECT_EQ(a.type(), t);
        EXPECT_EQ(a.size(), 1000u);
        EXPECT_EQ(a.bytes(), 1000u * scalar_type_size(t));
        EXPECT_EQ(a[999], 0.0);  // zero-filled
        const auto [lo, hi] = scalar_type_range(t);
        const double extremes[] = {scalar_type_is_integer(t) ? lo : -1.5, scalar_type_is_integer(t) ? hi : 3.25};
        a.set(3, extremes[0]);
        a.set(4, extremes[1]);
        EXPECT_EQ(a[3], extremes[0]);
        EXPECT_EQ(a[4], extremes[1]);
        EXPECT_EQ(*(a.begin() + 4), extremes[1]);
        // Not representable in the type: refused, never rounded.
        if (t != ScalarType::F64) EXPECT_THROW(a.set(5, 0.1), std::invalid_argument);
        if (scalar_type_is_integer(t)) EXPECT_THROW(a.set(5, hi + 1.0), std::invalid_argument);
        // Aligned, and zero padding around the samples (the SIMD word gathers read into it).
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.raw()) % VoxelArray::kAlignment, 0u);
        const auto* bytes = static_cast<const unsigned char*>(a.raw());
        for (std::size_t i = 1; i <= VoxelArray::kPadBytes; ++i) EXPECT_EQ(bytes[-std::ptrdiff_t(i)], 0);
    }
    VoxelArray u32(ScalarType::U32, 2);
    u32.data<std::uint32_t>()[1] = 4294967295u;
    EXPECT_EQ(u32[1], 4294967295.0);
    EXPECT_THROW(u32.data<float>(), std::logic_error);
    VoxelArray i8(ScalarType::I8, 1);
    i8.data<std::int8_t>()[0] = -128;
    EXPECT_EQ(i8[0], -128.0);
    EXPECT_EQ(i8.to_vector(), (std::vector<double>{-128.0}));
}

// A buffer of at least kHugeBufferBytes starts on a 2 MiB boundary (the transparent huge pages' advice,
// VoxelArray.h), a smaller one on 64 bytes; swapping, moving and copying keep each buffer's own alignment
// (the sanitizer build checks that each is freed with the alignment it was allocated with) and values.
TEST(VoxelArray, LargeBuffersStartOnHugePageBoundaries) {
    auto offset = [](const VoxelArray& a, std::size_t alignment) {
        return (reinterpret_cast<std::uintptr_t>(a.raw()) - VoxelArray::kPadBytes) % alignment;
    };
    const std::size_t big_count = VoxelArray::kHugeBufferBytes / sizeof(float) + 5;  // 4 MiB + 20 bytes of f32
    VoxelArray big(ScalarType::F32, big_count), small(ScalarType::F32, 1000);
    EXPECT_EQ(offset(big, VoxelArray::kHugePage), 0u);
    EXPECT_EQ(offset(small, VoxelArray::kAlignment), 0u);
    big.set(0, 1.5);
    big.set(big_count - 1, -2.25);
    small.set(999, 7.0);
    big.swap(small);
    EXPECT_EQ(small[big_count - 1], -2.25);
    EXPECT_EQ(big[999], 7.0);
    EXPECT_EQ(offset(small, VoxelArray::kHugePage), 0u);
    VoxelArray moved(std::move(small));
    VoxelArray copied(moved);
    EXPECT_EQ(offset(copied, VoxelArray::kHugePage), 0u);
    EXPECT_EQ(copied[0], 1.5);
    EXPECT_EQ(copied[big_count - 1], -2.25);
    EXPECT_EQ(copied.size(), big_count);
    copied = big;  // a large buffer replaced by a small one's copy
    EXPECT_EQ(copied.size(), 1000u);
    EXPECT_EQ(copied[999], 7.0);
    EXPECT_EQ(offset(copied, VoxelArray::kAlignment), 0u);
}

TEST(VoxelArray, BehavesAsAVectorOfDoublesForF64) {
    VoxelArray a;
    for (int i = 0; i < 100; ++i) a.push_back(i * 0.5);
    EXPECT_EQ(a.type(), ScalarType::F64);
    EXPECT_EQ(a.size(), 100u);
    EXPECT_EQ(a[99], 49.5);
    a[7] = 0.1;  // any double
    EXPECT_EQ(a[7], 0.1);
    a = {1.0, 2.0, 3.0};
    EXPECT_EQ(a, (std::vector<double>{1.0, 2.0, 3.0}));
    VoxelArray b = a;  // deep copy
    b[0] = 9.0;
    EXPECT_EQ(a[0], 1.0);
    a.resize(5);
    EXPECT_EQ(a, (std::vector<double>{1.0, 2.0, 3.0, 0.0, 0.0}));
    VoxelArray u8(ScalarType::U8, 3);
    EXPECT_THROW(u8.push_back(1.0), std::logic_error);
}

// Every reader path keeps the file's type: a NRRD file's samples take exactly its data bytes.
TEST(VoxelArray, ReadNrrdTakesTheFilesBytesInEachType) {
    for (ScalarType t : kTypes) {
        for (bool big : {false, true}) {
            SCOPED_TRACE(std::string(scalar_type_name(t)) + (big ? " big" : " little"));
            std::vector<double> values;
            for (int n = 0; n < 5 * 4 * 3; ++n) values.push_back(typed_value(t, (n * 37) % 101));
            const auto [path, data_bytes] = write_nrrd_file("bytes.nrrd", t, {5, 4, 3}, values, big);
            const Volume v = read_volume(path);
            EXPECT_EQ(v.type, t);
            EXPECT_EQ(v.values.type(), t);
            EXPECT_EQ(v.values.bytes(), data_bytes);
            EXPECT_EQ(v.values, values);  // each value exactly
        }
    }
}

// A u16 volume sampled by hand: f = 1000 + 2000 i + 400 j + 40000 k (u16 up to 43400), trilinear at
// (0.25, 0.5, 0.75) is 1000 + 500 + 200 + 30000 = 31700 (a linear field, binary fractions: exact).
TEST(VoxelArray, U16VolumeSampledByHand) {
    std::vector<double> values;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) values.push_back(1000.0 + 2000.0 * i + 400.0 * j + 40000.0 * k);
    const Volume v = read_volume(write_nrrd_file("hand.nrrd", ScalarType::U16, {2, 2, 2}, values).first);
    ASSERT_EQ(v.values.type(), ScalarType::U16);
    EXPECT_EQ(v.values.bytes(), 16u);
    const VolumeSampler trilinear(v, Interpolation::Trilinear);
    EXPECT_EQ(trilinear.value({0.25, 0.5, 0.75}), 31700.0);
    const VolumeSampler nearest(v, Interpolation::Nearest);
    EXPECT_EQ(nearest.value({0.75, 0.25, 0.75}), 43000.0);  // voxel (1, 0, 1)
    EXPECT_EQ(v.value_range(), (std::array<double, 2>{1000.0, 43400.0}));
}

// The same values stored as u8 .. f64 (read from a file of that type) and as f64 (a procedural
// "cells" field) give bitwise the same images, on every path: the SIMD packets (typed gathers) with
// and without empty-space skipping, the scalar path, shaded and unshaded, mip, nearest, tricubic.
TEST(VoxelArray, ImagesDoNotDependOnTheStorageType) {
    const std::array<std::int64_t, 3> dims{13, 11, 9};
    for (ScalarType t : kTypes) {
        SCOPED_TRACE(scalar_type_name(t));
        std::vector<double> values;
        for (int k = 0; k < dims[2]; ++k)
            for (int j = 0; j < dims[1]; ++j)
                for (int i = 0; i < dims[0]; ++i) {
                    const double r = std::hypot(i - 6.0, j - 5.0, k - 4.0);
                    values.push_back(typed_value(t, std::clamp(int(100.0 - 14.0 * r + (i * j + k) % 7), 0, 100)));
                }
        const fs::path file = write_nrrd_file(std::string("img_") + scalar_type_name(t) + ".nrrd", t, dims, values).first;
        const double lo = typed_value(t, 0), hi = typed_value(t, 100);

        FieldSpec cells;
        cells.kind = FieldSpec::Kind::Cells;
        cells.dims = dims;
        cells.values = values;
        Scene f64 = field_scene(cells);
        f64.image.width = 29;
        f64.image.height = 21;
        TransferSpec& tf = f64.volume().transfer;
        tf.domain = TransferSpec::Domain::Normalized;
        tf.window = std::array<double, 2>{lo, hi};
        tf.color = {{0.0, 0.1, 0.2, 0.9}, {0.5, 0.9, 0.5, 0.2}, {1.0, 1.0, 0.9, 0.6}};
        tf.opacity = {{0.0, 0.0}, {0.3, 0.0}, {0.6, 0.4}, {1.0, 0.9}};
        tf.opacity_unit_distance = 2.0;
        f64.render.step = 0.4;
        Scene typed = f64;
        typed.volume().source.field.reset();
        typed.volume().source.file = file;

        const auto expect_same = [&](const std::function<void(Scene&)>& change, const RenderOptions& options,
                                     const char* what) {
            SCOPED_TRACE(what);
            Scene a = f64, b = typed;
            change(a);
            change(b);
            const Image ia = render_scene(a, options), ib = render_scene(b, options);
            ASSERT_EQ(ia.pixels.size(), ib.pixels.size());
            double alpha = 0.0;
            std::size_t differ = 0;
            for (std::size_t i = 0; i < ia.pixels.size(); ++i) {
                if (std::bit_cast<std::uint64_t>(ia.pixels[i]) != std::bit_cast<std::uint64_t>(ib.pixels[i])) ++differ;
                if (i % ia.channels.size() == 3) alpha = std::max(alpha, ia.pixels[i]);
            }
            EXPECT_EQ(differ, 0u);
            EXPECT_GT(alpha, 0.05);  // not an empty image
        };
        // The typed gathers of each instruction set (AVX-512, AVX2, SSE4) against the f64 image of
        // the same instruction set.
        for (std::int64_t target : {HWY_AVX3, HWY_AVX2, HWY_SSE4}) {
            if ((hwy::SupportedTargets() & target) == 0) continue;
            hwy::SetSupportedTargetsForTest(target);
            const RenderOptions o{.threads = 1, .simd = true};
            expect_same([](Scene&) {}, o, hwy::TargetName(target));
            expect_same([](Scene& s) { s.volume().shading = ShadingSpec{}; }, o, hwy::TargetName(target));
            expect_same([](Scene& s) { s.render.projection = Projection::Minip; }, o, hwy::TargetName(target));
            hwy::SetSupportedTargetsForTest(0);
        }
        const RenderOptions simd{.threads = 1, .simd = true};
        RenderOptions scalar = simd;
        scalar.simd = false;
        RenderOptions no_skipping = simd;
        no_skipping.empty_space_skipping = false;
        const auto none = [](Scene&) {};
        expect_same(none, simd, "composite, SIMD + skipping");
        expect_same(none, no_skipping, "composite, SIMD");
        expect_same(none, scalar, "composite, scalar");
        const auto shaded = [](Scene& s) { s.volume().shading = ShadingSpec{}; };
        expect_same(shaded, simd, "shaded, SIMD");
        expect_same(shaded, scalar, "shaded, scalar");
        const auto cached = [](Scene& s) {
            s.volume().shading = ShadingSpec{};
            s.volume().gradient.cache = true;
        };
        expect_same(cached, simd, "shaded, gradient cache, SIMD");
        expect_same([](Scene& s) { s.render.projection = Projection::Mip; }, simd, "mip, SIMD");
        expect_same([](Scene& s) { s.render.projection = Projection::Mip; }, scalar, "mip, scalar");
        expect_same([](Scene& s) { s.volume().interpolation = Interpolation::Nearest; }, simd, "nearest");
        expect_same(
            [](Scene& s) {
                s.volume().interpolation = Interpolation::TricubicCatmullRom;
                s.volume().shading = ShadingSpec{};
            },
            simd, "tricubic, shaded (analytic gradient)");
        expect_same([](Scene& s) { s.volume().classify = VolumeSpec::Classify::Pre; }, simd, "pre-classified");
    }
}
