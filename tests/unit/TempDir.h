// A temporary folder for one test, removed at its end: /tmp/volref_PREFIX_PID_TESTNAME.
#pragma once
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <gtest/gtest.h>
#include <unistd.h>

namespace volref::test {

struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& prefix = "test") {
        path = std::filesystem::temp_directory_path() /
               ("volref_" + prefix + "_" + std::to_string(::getpid()) + "_" + testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    // Writes `text` (bytes as given) to `name` below the folder, creating its folders; the file's path.
    std::filesystem::path write(const std::string& name, const std::string& text) const {
        const std::filesystem::path p = path / name;
        std::filesystem::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
};

}  // namespace volref::test
