#include "core/io/OutputFile.h"

#include <unistd.h>

#include <string>
#include <system_error>

#include "core/Error.h"

namespace volref {

namespace fs = std::filesystem;

void check_output_folder(const fs::path& path) {
    const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(path.string() + ": the output folder " + dir.string() + " does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
        throw Error(path.string() + ": the output folder " + dir.string() + " is not writable");
    if (fs::is_directory(path, ec)) throw Error(path.string() + ": is a folder");
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
