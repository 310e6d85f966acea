// volref::Error: the one exception type for bad input. Its message is a single line that names the
// file, JSON path or byte at fault; the command line prints it after "volref: error: " and exits 1.
#pragma once
#include <stdexcept>
#include <string>

namespace volref {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace volref
