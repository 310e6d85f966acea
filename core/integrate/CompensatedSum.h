// CompensatedSum: Neumaier's variant of Kahan summation. The running error of each addition is kept
// in `c`, so a sum of a million terms of 1e-9 keeps (nearly) full double precision.
//   t = s + x;  c += (|s| >= |x|) ? (s - t) + x : (x - t) + s;  s = t;  value = s + c.
#pragma once
#include <cmath>

namespace volref {

class CompensatedSum {
public:
    void add(double x) {
        const double t = s_ + x;
        c_ += std::fabs(s_) >= std::fabs(x) ? (s_ - t) + x : (x - t) + s_;
        s_ = t;
    }
    double value() const { return s_ + c_; }

private:
    double s_ = 0.0, c_ = 0.0;
};

}  // namespace volref
