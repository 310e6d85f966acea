// volref sweep SCENE --param PATH=V1,V2,... [--param ...] [--reference adaptive|fine] [--repeat N]
//                    [--tolerance T] [-o DIR] [--threads N] [--set PATH=VALUE ...]      (docs/compare.md)
// Renders every combination of the parameters with the volref executable itself (a child process per
// render, N times, median wall time), measures each image against a reference, prints a table, writes
// DIR/sweep.csv, DIR/sweep.png and DIR/sweep.svg (gnuplot), and fits error = C h^p over render.step.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace volref::cli {

struct SweepArgs {
    std::filesystem::path scene;
    std::vector<std::string> params;     // --param PATH=V1,V2,...
    std::string reference;               // "", adaptive, fine ("": adaptive when this volref has it, else fine)
    int repeat = 3;                      // --repeat N >= 1
    double tolerance = 1e-3;             // --tolerance T > 0 (max abs per channel)
    std::filesystem::path output = ".";  // -o DIR
    int threads = 0;                     // --threads N, passed to every render (0: all cores)
    std::vector<std::string> overrides;  // --set PATH=VALUE, applied to every render before the parameters
};

// Throws volref::Error on bad input (exit status 1).
int run_sweep(const SweepArgs& args);

}  // namespace volref::cli
