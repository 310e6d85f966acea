// The volref commands, each in its own file, free of CLI11 (which only main.cpp includes).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace volref::cli {

struct RenderArgs {
    std::filesystem::path scene;
    std::filesystem::path output;
    int threads = 0;
    bool no_skipping = false;  // --no-skipping: RenderOptions::empty_space_skipping = false
    std::vector<std::string> overrides;  // --set PATH=VALUE
};

// Renders args.scene to args.output; throws volref::Error on bad input. Returns the exit status.
int run_render(const RenderArgs& args);

}  // namespace volref::cli
