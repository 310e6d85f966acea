// The ray-marching core's accumulators (core/integrate/march/Accumulators.h) against closed forms
// and against each other: every integrator and profile composites through these classes, so each
// formula is checked here once, by a number computed another way.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/integrate/march/Accumulators.h"
#include "core/integrate/march/CompensatedSum.h"

namespace volref {
namespace {

// n equal segments of opacity a (per unit distance l) and length d, colour c: the closed form is
// A = 1 - (1 - a)^(n d / l) and C = c A (a constant colour is emitted in proportion to the opacity).
TEST(Accumulators, FrontToBackOpticalDepthMatchesTheClosedForm) {
    const double a = 0.3, d = 0.7, l = 2.0, c[3] = {0.2, 0.5, 1.0};
    FrontToBack<Scalar> acc;
    for (int k = 0; k < 25; ++k) {
        const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, a, d, l);
        acc.add(o.visible, o.solid, o.tau, o.alpha, c);
    }
    const double A = 1.0 - std::pow(1.0 - a, 25.0 * d / l);
    EXPECT_NEAR(acc.alpha(), A, 1e-15);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(acc.color(i), c[i] * A, 1e-15);
    EXPECT_NEAR(acc.transmittance(), 1.0 - A, 1e-15);
}

TEST(Accumulators, ProductRuleInFloatMatchesTheClosedFormToFloatRounding) {
    using F = ScalarLanes<float>;
    const float a = 0.3f, d = 0.7f, l = 2.0f, c[3] = {0.2f, 0.5f, 1.0f};
    FrontToBack<F, TransmittanceRule::Product> acc;
    for (int k = 0; k < 25; ++k) {
        const SampleOpacity<F> o = sample_opacity<F>(true, a, d, l);
        acc.add(o.visible, o.solid, o.tau, o.alpha, c);
    }
    const double A = 1.0 - std::pow(1.0 - double(a), 25.0 * double(d) / double(l));
    EXPECT_NEAR(acc.alpha(), A, 2e-6);
    EXPECT_NEAR(acc.color(1), 0.5 * A, 2e-6);
}

// A GPU shader's A += (1 - A) alpha with alpha = 1/2: A = 1 - 2^-n exactly; stopping at A >= 0.9
// happens after the fourth sample (A = 15/16), at A > 1 - 1/255 after the eighth (255/256).
TEST(Accumulators, OpacitySumAndItsTerminationByHand) {
    const double c[3] = {1.0, 1.0, 1.0};
    auto samples_until_stop = [&](const Termination& t) {
        FrontToBack<Scalar, TransmittanceRule::OpacitySum> acc;
        for (int k = 1; k <= 100; ++k) {
            acc.add(true, false, 0.0, 0.5, c);
            EXPECT_EQ(acc.alpha(), 1.0 - std::ldexp(1.0, -k));
            EXPECT_EQ(acc.color(0), acc.alpha());
            if (acc.stops(true, t)) return k;
        }
        return -1;
    };
    Termination at;
    at.test_alpha_at_least = true;
    at.alpha_at_least = 0.9;
    EXPECT_EQ(samples_until_stop(at), 4);
    Termination above;
    above.test_alpha_above = true;
    above.alpha_above = 1.0 - 1.0 / 255.0;
    EXPECT_EQ(samples_until_stop(above), 8);
}

// An opaque sample: C += T c, A = 1; the samples behind it are never composited by the callers.
TEST(Accumulators, SolidSampleMakesTheRayOpaque) {
    const double c1[3] = {1.0, 0.0, 0.0}, c2[3] = {0.0, 1.0, 0.0};
    FrontToBack<Scalar> acc;
    const SampleOpacity<Scalar> o1 = sample_opacity<Scalar>(true, 0.5, 1.0, 1.0);  // alpha 1/2
    acc.add(o1.visible, o1.solid, o1.tau, o1.alpha, c1);
    const SampleOpacity<Scalar> o2 = sample_opacity<Scalar>(true, 1.0, 1.0, 1.0);
    EXPECT_TRUE(o2.solid);
    EXPECT_FALSE(o2.partial);
    acc.add(o2.visible, o2.solid, o2.tau, o2.alpha, c2);
    EXPECT_EQ(acc.alpha(), 1.0);
    EXPECT_NEAR(acc.color(0), 0.5, 1e-16);
    EXPECT_NEAR(acc.color(1), 0.5, 1e-16);  // T = 1/2 in front of the opaque sample
    const SampleOpacity<Scalar> o0 = sample_opacity<Scalar>(true, 0.0, 1.0, 1.0);
    EXPECT_FALSE(o0.visible);
}

// Back to front over the same samples gives front to back's pixel (a second method), to rounding.
TEST(Accumulators, BackToFrontOverEqualsFrontToBack) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    struct S { double a, d, c[3]; };
    std::vector<S> s(200);
    for (S& x : s) x = {0.05 * u(rng), 0.5 + u(rng), {u(rng), u(rng), u(rng)}};
    FrontToBack<Scalar> f;
    BackToFront<Scalar> b;
    for (const S& x : s) {
        const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, x.a, x.d, 1.5);
        f.add(o.visible, o.solid, o.tau, o.alpha, x.c);
    }
    for (auto it = s.rbegin(); it != s.rend(); ++it) {
        const SampleOpacity<Scalar> o = sample_opacity<Scalar>(true, it->a, it->d, 1.5);
        b.add(o.visible, o.solid, o.tau, o.alpha, it->c);
    }
    EXPECT_NEAR(f.alpha(), b.alpha(), 1e-14);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(f.color(i), b.color(i), 1e-13);
}

// Seed 001's lerp: sum = sum + (col - sum) w. Two samples of col = (1, 0, 0, 1) with w = 1/2 from
// sum = 0: 1/2, then 3/4 on R and A.
TEST(Accumulators, LerpByHand) {
    BackToFront<Scalar, BackToFrontRule::Lerp> acc;
    const double c[3] = {1.0, 0.0, 0.0};
    acc.lerp(true, 0.5, c, 1.0);
    acc.lerp(false, 0.5, c, 1.0);  // a skipped sample changes nothing
    acc.lerp(true, 0.5, c, 1.0);
    EXPECT_EQ(acc.color(0), 0.75);
    EXPECT_EQ(acc.color(1), 0.0);
    EXPECT_EQ(acc.alpha(), 0.75);
}

TEST(Accumulators, ExtremumTakesTheFirstOfEqualValuesAndIgnoresNonFinite) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    const double v[] = {nan, 0.5, 2.0, inf, 2.0, -inf, 1.0};
    Extremum<Scalar> mip(true), minip(false);
    for (int k = 0; k < 7; ++k) {
        mip.add(true, v[k], double(k));
        minip.add(true, v[k], double(k));
    }
    EXPECT_TRUE(mip.any());
    EXPECT_EQ(mip.value(), 2.0);
    EXPECT_EQ(mip.where(), 2.0);
    EXPECT_EQ(minip.value(), 0.5);
    EXPECT_EQ(minip.where(), 1.0);
    Extremum<Scalar> none(true);
    none.add(true, nan, 0.0);
    none.add(false, 3.0, 1.0);  // a lane that is not alive
    EXPECT_FALSE(none.any());
}

// The midpoint rule integrates a linear field exactly: f(t) = 2 + 3 t on [0, 4] in segments of 0.5
// has mean 2 + 3 * 2 = 8 and integral 32.
TEST(Accumulators, LineIntegralOfALinearField) {
    LineIntegral<CompensatedSum> acc;
    LineIntegral<PlainSum> plain;
    for (int k = 0; k < 8; ++k) {
        const double t = 0.25 + 0.5 * k;
        acc.add((2.0 + 3.0 * t) * 0.5, 0.5);
        plain.add((2.0 + 3.0 * t) * 0.5, 0.5);
    }
    EXPECT_EQ(acc.integral(), 32.0);
    EXPECT_EQ(acc.length(), 4.0);
    EXPECT_EQ(acc.mean(), 8.0);
    EXPECT_EQ(plain.mean(), 8.0);
}

// Neumaier: 1 + 10^6 terms of 1e-10 is 1.0001 to within an ulp; the plain sum drifts by about 1e-11.
TEST(Accumulators, CompensatedSumKeepsFullPrecision) {
    CompensatedSum s;
    PlainSum p;
    s.add(1.0);
    p.add(1.0);
    for (int k = 0; k < 1000000; ++k) {
        s.add(1e-10);
        p.add(1e-10);
    }
    EXPECT_NEAR(s.value(), 1.0001, 2.3e-16);
    EXPECT_GT(std::fabs(p.value() - 1.0001), 1e-13);
}

}  // namespace
}  // namespace volref
