#include "core/Cancellation.h"

#include <atomic>
#include <csignal>

namespace volref {

namespace {
std::atomic<int> g_signal{0};  // 0: no request; else the signal (or -1 for a request without one)
static_assert(std::atomic<int>::is_always_lock_free, "request_cancel must be async-signal-safe");

std::string signal_name(int s) {
    if (s == SIGINT) return "SIGINT";
    if (s == SIGTERM) return "SIGTERM";
    return "signal " + std::to_string(s);
}
}  // namespace

Cancelled::Cancelled(int signal)
    : Error("interrupted by " + signal_name(signal) + "; no output written"), signal_(signal) {}

void request_cancel(int signal) noexcept { g_signal.store(signal == 0 ? -1 : signal, std::memory_order_relaxed); }
bool cancel_requested() noexcept { return g_signal.load(std::memory_order_relaxed) != 0; }
void reset_cancel() noexcept { g_signal.store(0, std::memory_order_relaxed); }

void throw_if_cancelled() {
    const int s = g_signal.load(std::memory_order_relaxed);
    if (s != 0) throw Cancelled(s);
}

}  // namespace volref
