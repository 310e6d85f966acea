// Shared pieces of the libFuzzer targets (docs/robustness.md): a per-process scratch folder for the
// input as a file (the readers take paths), and the memory limit every target runs under, so a header
// asking for a huge volume is a volref::Error like any other bad input (core/MemoryLimit.h), not an
// out-of-memory report from libFuzzer. Anything but volref::Error escaping a reader is a finding.
#pragma once
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/MemoryLimit.h"

namespace volref::fuzz {

// 256 MiB: far above every seed, far below libFuzzer's default -rss_limit_mb=2048.
inline constexpr std::size_t kFuzzMemoryLimit = std::size_t(256) << 20;

inline const std::filesystem::path& scratch_folder() {
    static const std::filesystem::path dir = [] {
        const auto d = std::filesystem::temp_directory_path() / ("volref-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        set_memory_limit(kFuzzMemoryLimit);
        return d;
    }();
    return dir;
}

// Writes the input to scratch_folder()/name and returns the path.
inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
    const std::filesystem::path p = scratch_folder() / name;
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return p;
}

}  // namespace volref::fuzz
