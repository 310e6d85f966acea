// Cancellation: how a long run stops early without leaving partial output (docs/robustness.md).
//
// The command line turns SIGINT and SIGTERM into request_cancel(signal) (async-signal-safe: one
// lock-free atomic store). The renderer checks cancel_requested() before each tile and throws
// Cancelled after its workers have finished; writers check it once more before renaming their
// temporary file into place (core/io/OutputFile.h) and delete that file instead. The command then
// exits with status 128 + signal (130 for SIGINT, 143 for SIGTERM), as a shell reports a process
// killed by that signal, after one line "volref: interrupted by SIGINT; no output written".
#pragma once
#include <string>

#include <cstdint>

#include "core/Conventions.h"
#include "core/Error.h"

namespace volref {

class Cancelled : public Error {
public:
    explicit Cancelled(int signal);
    int signal() const { return signal_; }

private:
    int signal_;
};

void request_cancel(int signal) noexcept;
bool cancel_requested() noexcept;
// Throws Cancelled if a cancel was requested.
void throw_if_cancelled();
// For tests and for programs that render again after a cancel: forget the request.
void reset_cancel() noexcept;
// Inside a loop over samples (k = 0, 1, ...): true when SIGINT / SIGTERM is requested, polled every
// conventions::kCancellationPollSamples iterations (the caller ends the ray; the render is abandoned).
inline bool cancel_polled(std::int64_t k) noexcept {
    return (k & (conventions::kCancellationPollSamples - 1)) == 0 && k > 0 && cancel_requested();
}

}  // namespace volref
