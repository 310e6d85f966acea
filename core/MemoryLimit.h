// MemoryLimit: the most memory one allocation plan of volref may ask for, checked before anything is
// allocated (docs/robustness.md). A volume, an image or a gradient cache that would not fit is refused
// with a one-line Error naming what needed the memory, instead of dying in the allocator.
//
// The limit is process-wide: by default the machine's physical memory (sysconf(_SC_PHYS_PAGES) x
// page size); `volref --max-memory SIZE` (or the environment variable VOLREF_MAX_MEMORY) lowers or
// raises it. Each check compares one request (what is about to be allocated, plus what the caller
// says is already held) with the limit; volref does not track every byte it holds.
#pragma once
#include <cstddef>
#include <string>

namespace volref {

// The current limit in bytes.
std::size_t memory_limit();
void set_memory_limit(std::size_t bytes);
// The machine's physical memory in bytes (the default limit).
std::size_t physical_memory();

// Throws Error "<what>: needs N bytes (X GiB), more than the memory limit of Y GiB (--max-memory)"
// when bytes > memory_limit().
void check_memory(std::size_t bytes, const std::string& what);

// While alive, every check_memory on the calling thread also counts `bytes` as held: the memory the
// volumes prepared before the current one hold (several volumes), so that reading the next volume's
// file is refused before its allocation when the total would not fit. Nests (the counts add).
class HeldMemory {
public:
    explicit HeldMemory(std::size_t bytes);
    ~HeldMemory();
    HeldMemory(const HeldMemory&) = delete;
    HeldMemory& operator=(const HeldMemory&) = delete;

private:
    std::size_t bytes_;
};

// Parses a size: a number with an optional unit B, K/KB/KiB, M/MB/MiB, G/GB/GiB, T/TB/TiB (all
// binary: K = 1024; case-insensitive). Throws Error naming `what` for anything else or 0.
std::size_t parse_memory_size(const std::string& text, const std::string& what);

// "1.5 GiB", "12 MiB", "512 B": for messages.
std::string format_bytes(std::size_t bytes);

}  // namespace volref
