// volref info FILE [--format F] [--json] [--bins N]: what a volume file holds (free of CLI11).
#pragma once
#include <filesystem>
#include <string>

namespace volref::cli {

struct InfoArgs {
    std::filesystem::path input;
    std::string format;  // "" = from the extension
    bool json = false;
    int bins = 16;
};

// Prints the summary on stdout; throws volref::Error on bad input. Returns the exit status.
int run_info(const InfoArgs& args);

}  // namespace volref::cli
