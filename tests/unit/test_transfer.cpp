// Transfer functions and the optical model's formulas against closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "core/Error.h"
#include "transfer/OpacityCorrection.h"
#include "transfer/TransferFunction.h"

using namespace volref;

namespace {
Volume float_volume(std::vector<double> values) {
    Volume v;
    v.dims = {std::int64_t(values.size()), 1, 1};
    v.type = ScalarType::F32;
    v.values = std::move(values);
    return v;
}
}  // namespace

TEST(OpacityCorrection, PowerLaw) {
    // alpha_d = 1 - (1 - a)^(d / l), checked with pow for values where pow is accurate.
    for (double a : {0.1, 0.5, 0.9})
        for (double d : {0.25, 1.0, 3.0})
            for (double l : {0.5, 1.0, 2.0})
                EXPECT_NEAR(opacity_for_length(a, d, l), 1.0 - std::pow(1.0 - a, d / l), 1e-15);
    EXPECT_EQ(opacity_for_length(1.0, 0.1, 1.0), 1.0);
    EXPECT_EQ(opacity_for_length(0.5, 0.0, 1.0), 0.0);
    EXPECT_EQ(opacity_for_length(0.0, 5.0, 1.0), 0.0);
}

TEST(OpacityCorrection, SmallValuesKeepRelativeAccuracy) {
    // For a = 1e-12 and d / l = 1e-3: alpha = 1 - (1 - a)^(1e-3) = 1e-15 (1 + O(a)); the naive
    // 1 - pow(1 - a, x) has no correct digit here.
    const double alpha = opacity_for_length(1e-12, 1e-3, 1.0);
    EXPECT_NEAR(alpha / 1e-15, 1.0, 1e-9);
    EXPECT_NEAR(extinction(1e-12, 1.0), 1e-12, 1e-24);
}

TEST(TransferFunction, PiecewiseLinearRows) {
    TransferSpec spec;
    spec.color = {{0, 0, 0, 0}, {10, 1, 0.5, 0}, {20, 0, 1, 1}};
    spec.opacity = {{5, 0}, {15, 0.8}};
    const TransferFunction tf(spec, float_volume({0, 20}));
    EXPECT_DOUBLE_EQ(tf.opacity(0), 0.0);      // clamped below
    EXPECT_DOUBLE_EQ(tf.opacity(10), 0.4);     // halfway
    EXPECT_DOUBLE_EQ(tf.opacity(100), 0.8);    // clamped above
    const glm::dvec3 c = tf.color(15);
    EXPECT_DOUBLE_EQ(c.r, 0.5);
    EXPECT_DOUBLE_EQ(c.g, 0.75);
    EXPECT_DOUBLE_EQ(c.b, 0.5);
}

TEST(TransferFunction, JumpIsRightContinuous) {
    TransferSpec spec;
    spec.opacity = {{0, 0}, {5, 0}, {5, 1}, {10, 1}};
    const TransferFunction tf(spec, float_volume({0, 10}));
    EXPECT_DOUBLE_EQ(tf.opacity(4.999), 0.0);
    EXPECT_DOUBLE_EQ(tf.opacity(5.0), 1.0);
}

TEST(TransferFunction, NormalizedDomainAndDefaults) {
    TransferSpec spec;
    spec.domain = TransferSpec::Domain::Normalized;
    // Default window of u8 data is [0, 255]; default rows: white, opacity ramp 0 -> 1 over [0, 1].
    Volume v;
    v.dims = {2, 1, 1};
    v.type = ScalarType::U8;
    v.values = {10, 20};
    const TransferFunction tf(spec, v);
    EXPECT_DOUBLE_EQ(tf.coordinate(51), 0.2);
    EXPECT_DOUBLE_EQ(tf.opacity(51), 0.2);
    EXPECT_EQ(tf.color(3), glm::dvec3(1.0));
    // Float data: the window is the data's [min, max].
    const TransferFunction tf2(spec, float_volume({-2, 6}));
    EXPECT_DOUBLE_EQ(tf2.coordinate(0), 0.25);
    // An explicit window.
    spec.window = std::array<double, 2>{100, 300};
    const TransferFunction tf3(spec, v);
    EXPECT_DOUBLE_EQ(tf3.opacity(150), 0.25);
}

TEST(TransferFunction, EmptyWindowIsAnError) {
    TransferSpec spec;
    spec.domain = TransferSpec::Domain::Normalized;
    try {
        TransferFunction tf(spec, float_volume({3, 3}));
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("volume.transfer.window"), std::string::npos) << e.what();
    }
}
