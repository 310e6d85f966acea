// CompensatedSum: Neumaier's variant of Kahan summation. The running error of each addition is kept
// in `c`, so a sum of a million terms of 1e-9 keeps (nearly) full double precision.
//   t = s + x;  c += (|s| >= |x|) ? (s - t) + x : (x - t) + s;  s = t;  value = s + c
// (compensated_add, march/Accumulators.h, the one copy of the formula).
#pragma once
#include "core/integrate/march/Accumulators.h"

namespace volref {

class CompensatedSum {
public:
    CompensatedSum() = default;
    // A sum handed over as its two parts (march/SpanStates.h): value() is s + c again, bit for bit.
    CompensatedSum(double s, double c) : s_(s), c_(c) {}
    double sum() const { return s_; }
    double compensation() const { return c_; }
    void add(double x) { compensated_add<Scalar>(s_, c_, x, true); }
    double value() const { return s_ + c_; }

private:
    double s_ = 0.0, c_ = 0.0;
};

}  // namespace volref
