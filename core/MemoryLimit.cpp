#include "core/MemoryLimit.h"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "core/Error.h"

namespace volref {

namespace {
std::atomic<std::size_t> g_limit{0};  // 0: not set, use physical_memory()
}

std::size_t physical_memory() {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return std::numeric_limits<std::size_t>::max();
    return std::size_t(pages) * std::size_t(page);
}

std::size_t memory_limit() {
    const std::size_t l = g_limit.load(std::memory_order_relaxed);
    return l ? l : physical_memory();
}

void set_memory_limit(std::size_t bytes) { g_limit.store(bytes, std::memory_order_relaxed); }

std::string format_bytes(std::size_t bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double v = double(bytes);
    int u = 0;
    while (v >= 1024.0 && u < 6) {
        v /= 1024.0;
        ++u;
    }
    char buf[64];
    if (u == 0)
        std::snprintf(buf, sizeof buf, "%zu B", bytes);
    else
        std::snprintf(buf, sizeof buf, "%.3g %s", v, units[u]);
    return buf;
}

namespace {
thread_local std::size_t held_on_this_thread = 0;  // HeldMemory's count
}  // namespace

HeldMemory::HeldMemory(std::size_t bytes) : bytes_(bytes) { held_on_this_thread += bytes; }
HeldMemory::~HeldMemory() { held_on_this_thread -= bytes_; }

void check_memory(std::size_t request, const std::string& what) {
    const std::size_t limit = memory_limit();
    const std::size_t bytes = request > SIZE_MAX - held_on_this_thread ? SIZE_MAX : request + held_on_this_thread;
    if (bytes > limit)
        throw Error(what + ": needs " + format_bytes(request) +
                    (held_on_this_thread ? " besides the " + format_bytes(held_on_this_thread) + " the earlier volumes hold" : std::string()) +
                    ", more than the memory limit of " + format_bytes(limit) + " (--max-memory)");
}

std::size_t parse_memory_size(const std::string& text, const std::string& what) {
    std::size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
    const std::string number = text.substr(0, i);
    std::string unit;
    for (std::size_t j = i; j < text.size(); ++j)
        if (!std::isspace(static_cast<unsigned char>(text[j]))) unit += char(std::tolower(static_cast<unsigned char>(text[j])));
    double scale = 0.0;
    if (unit.empty() || unit == "b") scale = 1.0;
    else if (unit == "k" || unit == "kb" || unit == "kib") scale = 0x1p10;
    else if (unit == "m" || unit == "mb" || unit == "mib") scale = 0x1p20;
    else if (unit == "g" || unit == "gb" || unit == "gib") scale = 0x1p30;
    else if (unit == "t" || unit == "tb" || unit == "tib") scale = 0x1p40;
    char* end = nullptr;
    const double v = number.empty() ? 0.0 : std::strtod(number.c_str(), &end);
    if (number.empty() || end != number.c_str() + number.size() || scale == 0.0 || !(v > 0.0))
        throw Error(what + ": expected a positive size such as 512M, 4G or 1.5GiB, got \"" + text + "\"");
    const double bytes = std::ceil(v * scale);
    if (!(bytes < 0x1p63)) throw Error(what + ": " + text + " is too large");
    return std::size_t(bytes);
}

}  // namespace volref
