// volref compare with non-finite pixels and the convention fits (issue 22; core/compare/ImageMetrics.h,
// Fits.h): vtk.js's float framebuffer holds NaN where alpha is 0.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/compare/Fits.h"
#include "core/compare/ImageMetrics.h"

using namespace volref;
using namespace volref::compare;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

// 16 x 16, pixel (x, y) = (0.01 (x + 1), 0.02 (y + 1) / 2, 0.3, 0.5).
Image ramp() {
    Image im(16, 16, {"R", "G", "B", "A"});
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            im.at(x, y, 0) = 0.01 * (x + 1);
            im.at(x, y, 1) = 0.01 * (y + 1);
            im.at(x, y, 2) = 0.3;
            im.at(x, y, 3) = 0.5;
        }
    return im;
}

void set_nan(Image& im, int x, int y) {
    for (int c = 0; c < 3; ++c) im.at(x, y, std::size_t(c)) = kNaN;
    im.at(x, y, 3) = 0.0;
}

}  // namespace

// NaN at the same pixel of both: agreeing, left out of the sums (max and mean over the finite values).
TEST(CompareNonFinite, AgreeingNaNIsLeftOutAndWithinTolerance) {
    Image a = ramp(), b = ramp();
    b.at(3, 4, 0) += 0.01;  // one finite difference of 0.01
    set_nan(a, 7, 7);
    set_nan(b, 7, 7);
    const ImageMetrics m = measure_difference(a, b, std::vector<double>(16 * 16 * 4, 0.02));
    EXPECT_EQ(m.non_finite_a, 1);
    EXPECT_EQ(m.non_finite_b, 1);
    EXPECT_EQ(m.non_finite_disagree, 0);
    EXPECT_EQ(m.overall.over, 0);
    EXPECT_NEAR(m.channels[0].max_abs, 0.01, 1e-15);
    EXPECT_NEAR(m.channels[0].mean_abs, 0.01 / 255.0, 1e-15);  // 255 finite R pairs
    EXPECT_NEAR(m.overall.max_abs, 0.01, 1e-15);
    ASSERT_TRUE(m.overall.ssim.has_value());
    EXPECT_TRUE(std::isfinite(*m.overall.ssim));
}

// NaN against a number, or +inf against -inf: over the tolerance, counted as disagreeing.
TEST(CompareNonFinite, DisagreeingNonFiniteIsOver) {
    Image a = ramp(), b = ramp();
    set_nan(a, 1, 1);
    a.at(2, 2, 1) = kInf;
    b.at(2, 2, 1) = -kInf;
    a.at(5, 5, 2) = kInf;
    b.at(5, 5, 2) = kInf;  // agrees
    const ImageMetrics m = measure_difference(a, b, std::vector<double>(16 * 16 * 4, 1.0));
    EXPECT_EQ(m.non_finite_a, 3);
    EXPECT_EQ(m.non_finite_b, 2);
    EXPECT_EQ(m.non_finite_disagree, 2);
    EXPECT_EQ(m.overall.over, 2);
    EXPECT_EQ(m.channels[0].max_abs, 0.0);  // R: only the NaN pair differs
    EXPECT_EQ(m.channels[3].max_abs, 0.5);  // A: 0 (set_nan) against 0.5, finite
    const std::vector<double> map = max_abs_difference_map(a, b);
    EXPECT_TRUE(std::isnan(map[1 * 16 + 1]));
    EXPECT_TRUE(std::isnan(map[2 * 16 + 2]));
    EXPECT_EQ(map[5 * 16 + 5], 0.0);
}

// The fit with NaN pixels (was "least-squares fit failed: Residual and Jacobian evaluation failed"):
// B = 1.25 A in colour recovers g = 1.25 exactly from the finite pixels.
TEST(CompareNonFinite, FitIgnoresNonFinitePixels) {
    Image a = ramp(), b = ramp();
    for (std::size_t i = 0; i < b.pixels.size(); ++i)
        if (i % 4 != 3) b.pixels[i] *= 1.25;
    set_nan(a, 0, 0);
    set_nan(b, 0, 0);
    set_nan(b, 9, 3);
    DifferenceExplanation e;
    ASSERT_NO_THROW(e = explain_difference(a, b));
    ASSERT_EQ(e.fits.size(), 3u);
    EXPECT_EQ(e.fits[0].model, "gain");
    EXPECT_NEAR(e.fits[0].values[0], 1.25, 1e-9);
    EXPECT_NE(e.verdict.find("colour gain"), std::string::npos) << e.verdict;
}

// A convention variant equal to A explains the difference completely and is named in the verdict; a
// variant that is not applicable is reported with its note.
TEST(CompareNonFinite, ConventionVariantIsFittedAndNamed) {
    Image a = ramp(), b = ramp();
    for (int y = 0; y < 16; ++y) b.at(3 + y % 5, y, 0) += 0.2;  // not a gain, an opacity exponent or a shift
    set_nan(a, 4, 4);
    set_nan(b, 4, 4);
    ConventionVariant flipped{"normal", "a flipped normal under one-sided lighting", true, "", a};
    ConventionVariant mip{"mip-opacity", "opacity correction applied to MIP", false, "the scene's projection is not mip or minip", {}};
    const DifferenceExplanation e = explain_difference(a, b, {flipped, mip});
    ASSERT_EQ(e.fits.size(), 5u);
    EXPECT_TRUE(e.fits[3].fitted);
    EXPECT_EQ(e.fits[3].residual_after, 0.0);
    EXPECT_NEAR(e.fits[3].residual_before, std::sqrt(16 * 0.04 / (255.0 * 4.0)), 1e-12);  // 255 finite pixels
    EXPECT_FALSE(e.fits[4].fitted);
    EXPECT_EQ(e.fits[4].note, "the scene's projection is not mip or minip");
    EXPECT_EQ(e.verdict.rfind("likely cause: a flipped normal under one-sided lighting", 0), 0u) << e.verdict;
}
