#include "core/integrate/packet/PairFetch.h"

#include <atomic>
#include <cstdlib>
#include <string>

#include "core/Error.h"

namespace volref {

namespace {

std::atomic<int> g_pair_fetch{int(PairFetch::Auto)};

// Auto: the variable, else the CPU's vendor (PairFetch.h says why).
bool auto_gathers() {
    if (const char* v = std::getenv("VOLREF_PAIR_FETCH")) {
        const std::string s(v);
        if (s == "gathers") return true;
        if (s == "loads") return false;
        throw Error("VOLREF_PAIR_FETCH: '" + s + "' is neither loads nor gathers");
    }
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __builtin_cpu_init();
    return __builtin_cpu_is("intel");
#else
    return false;
#endif
}

}  // namespace

void set_pair_fetch(PairFetch how) { g_pair_fetch.store(int(how), std::memory_order_relaxed); }

bool pair_fetch_gathers() {
    const PairFetch how = PairFetch(g_pair_fetch.load(std::memory_order_relaxed));
    if (how != PairFetch::Auto) return how == PairFetch::Gathers;
    static const bool gathers = auto_gathers();
    return gathers;
}

}  // namespace volref
