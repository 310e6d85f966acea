// How `volref explain` and `volref trace` print numbers: the shortest decimal text that reads back as
// the same double (std::to_chars), so a printed value is the computed value, bit for bit, and short
// values stay short (0.1, not 0.10000000000000001). Non-finite values print as inf, -inf, nan.
#pragma once
#include <charconv>
#include <cmath>
#include <string>

namespace volref::explain {

inline std::string number(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

}  // namespace volref::explain
