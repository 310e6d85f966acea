#!/usr/bin/python3
"""Fits the polynomials of the fast profile's float log1p and expm1 (core/SimdLanes-inl.h: float_log1p,
float_expm1; conventions section 9b) and prints their coefficients as C++ hex floats, highest degree
first, as the code lists them. Run: /usr/bin/python3 scripts/fit_float_polynomials.py (Debian's numpy).

Each fits h, the part of the function's Taylor series from the cubic term on, divided by x^3:
  log1p(f) = f - f^2 / 2 + f^3 h(f),  f in [sqrt(1/2) - 1, sqrt(2) - 1], degree 7
  expm1(r) = r + r^2 / 2 + r^3 h(r),  r in [-ln 2 / 2, ln 2 / 2],     degree 3
by least squares on a Chebyshev basis, reweighted (Lawson's iteration) toward the minimax error of the
whole function, with h computed from its series near 0 (where the direct formula cancels). The script
prints each fit's largest relative error in double with the coefficients rounded to float; the float
evaluation's own error is Simd.FloatLog1pAndExpm1WithinTwoUlp's to measure (tests/unit/test_simd.cpp).
"""
import math

import numpy as np


def series_or_direct(x, series, direct):
    out = np.empty_like(x)
    near = np.abs(x) < 0.2
    out[near] = series(x[near])
    out[~near] = direct(x[~near])
    return out


def h_log1p(f):
    def series(x):  # 1/3 - x/4 + x^2/5 - ...
        acc = np.zeros_like(x)
        for n in range(40, 2, -1):
            acc = acc * x + (-1) ** (n + 1) / n
        return acc
    return series_or_direct(f, series, lambda x: (np.log1p(x) - x + x * x / 2) / x**3)


def h_expm1(r):
    def series(x):  # 1/3! + x/4! + ...
        acc = np.zeros_like(x)
        for n in range(30, 2, -1):
            acc = acc * x + 1.0 / math.factorial(n)
        return acc
    return series_or_direct(r, series, lambda x: (np.expm1(x) - x - x * x / 2) / x**3)


def fit(lo, hi, h, degree, whole, points=400001):
    x = np.linspace(lo, hi, points)
    y = h(x)
    scale = x * x  # the error of h enters the whole function times x^3; relative to it (~x): x^2
    weights = np.ones_like(x)
    for _ in range(40):
        c = np.polynomial.chebyshev.Chebyshev.fit(x, y, degree, domain=[lo, hi], w=np.sqrt(weights) * scale)
        p = c.convert(kind=np.polynomial.Polynomial, domain=[lo, hi], window=[lo, hi]).coef
        r = np.abs(np.polynomial.polynomial.polyval(x, p) - y) * scale
        weights = weights * (r / r.max() + 1e-2)
        weights /= weights.max()
    p32 = p.astype(np.float32)
    xs = x[np.abs(x) > 1e-7]
    err = np.max(np.abs(whole(xs, np.polynomial.polynomial.polyval(xs, p32.astype(np.float64))) / whole(xs, None) - 1))
    return p32, err


def main():
    log_whole = lambda f, hv: np.log1p(f) if hv is None else f + f * f * (-0.5 + f * hv)
    exp_whole = lambda r, hv: np.expm1(r) if hv is None else r + r * r * (0.5 + r * hv)
    for name, lo, hi, h, degree, whole in (
        ("log1p", math.sqrt(0.5) - 1, math.sqrt(2) - 1, h_log1p, 7, log_whole),
        ("expm1", -math.log(2) / 2, math.log(2) / 2, h_expm1, 3, exp_whole),
    ):
        p, err = fit(lo, hi, h, degree, whole)
        print(f"{name}: h of degree {degree} on [{lo:.6f}, {hi:.6f}], relative error {err:.3g}")
        print("  " + ", ".join(float.hex(float(c)).replace("0000000p", "p") for c in p[::-1]))


if __name__ == "__main__":
    main()
