#include "core/InputFile.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "core/Error.h"
#include "core/MemoryLimit.h"

namespace volref::io {

std::string input_file_problem(const std::filesystem::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return std::strerror(errno);
    if (S_ISREG(st.st_mode)) return "";
    if (S_ISDIR(st.st_mode)) return "it is a directory";
    if (S_ISFIFO(st.st_mode)) return "it is a FIFO (volref reads regular files only)";
    if (S_ISCHR(st.st_mode)) return "it is a character device (volref reads regular files only)";
    if (S_ISBLK(st.st_mode)) return "it is a block device (volref reads regular files only)";
    if (S_ISSOCK(st.st_mode)) return "it is a socket (volref reads regular files only)";
    return "it is not a regular file";
}

std::uint64_t check_input_file(const std::filesystem::path& path, const std::string& where) {
    if (const std::string why = input_file_problem(path); !why.empty()) throw Error(where + ": cannot read file: " + why);
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(where + ": cannot read file: " + ec.message());
    return size;
}

std::uint64_t check_whole_file(const std::filesystem::path& path, const std::string& where) {
    const std::uint64_t size = check_input_file(path, where);
    check_memory(size > SIZE_MAX ? SIZE_MAX : std::size_t(size), where + ": reading the file");
    return size;
}

std::string read_file_bytes(const std::filesystem::path& path, const std::string& where_given) {
    const std::string where = where_given.empty() ? path.string() : where_given;
    const std::uint64_t size = check_whole_file(path, where);  // a regular file that fits in memory
    const std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) throw Error(where + ": cannot read file: " + std::strerror(errno));
    std::string bytes;
    bytes.reserve(static_cast<std::size_t>(size));
    std::vector<char> chunk(std::size_t(1) << 16);
    for (;;) {
        const std::size_t n = std::fread(chunk.data(), 1, chunk.size(), f.get());
        bytes.append(chunk.data(), n);
        if (n < chunk.size()) break;
    }
    if (std::ferror(f.get())) throw Error(where + ": cannot read file: " + std::strerror(errno));
    return bytes;
}

}  // namespace volref::io
