#include "core/io/OutputFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <string>
#include <system_error>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace volref {

namespace fs = std::filesystem;

void check_output_folder(const fs::path& path) {
    const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(path.string() + ": the output folder " + dir.string() + " does not exist");
    if (fs::is_directory(path, ec)) throw Error(path.string() + ": is a folder");
    // access(W_OK) says yes to root on a read-only mount or in /proc: create (and remove) the
    // temporary file the writer will use, which is the real test.
    const fs::path probe = temporary_output_path(path);
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        const int err = errno;
        if (err != EEXIST)
            throw Error(path.string() + ": the output folder " + dir.string() + " is not writable (" +
                        std::strerror(err) + ")");
    } else {
        ::close(fd);
        fs::remove(probe, ec);
    }
}

void commit_output(const fs::path& tmp, const fs::path& path) {
    std::error_code ec;
    if (cancel_requested()) {
        fs::remove(tmp, ec);
        throw_if_cancelled();
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw Error(path.string() + ": cannot move the finished file into place: " + ec.message());
    }
}

fs::path temporary_output_path(const fs::path& path) {
    const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    // Built by appending: GCC 12 warns falsely on "." + std::string.
    std::string name(".");
    name.append(path.stem().string()).append(".volref-tmp-").append(std::to_string(::getpid()));
    name.append(path.extension().string());
    return dir / name;
}

}  // namespace volref
