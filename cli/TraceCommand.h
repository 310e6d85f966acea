// volref trace SCENE --pixel X,Y [--format csv|json] [-o FILE] [--no-skipping] [--set PATH=VALUE ...]
// Every sample along one pixel's ray (docs/trace.md), recorded by the integrator's own loop.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace volref::cli {

struct TraceArgs {
    std::filesystem::path scene;
    std::string pixel;                   // "X,Y"
    std::string format;                  // "csv", "json", "" = from -o's extension (.json), else csv
    std::filesystem::path output;        // "" = standard output
    bool no_skipping = false;            // --no-skipping: list the segments skipping would pass over too
    std::vector<std::string> overrides;  // --set PATH=VALUE
};

// Throws volref::Error on bad input. Returns the exit status.
int run_trace(const TraceArgs& args);

}  // namespace volref::cli
