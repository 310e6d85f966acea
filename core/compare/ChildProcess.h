// Running a program as a child process and timing it (whole-process wall time: start-up, loading,
// rendering, writing), as `volref sweep` times each render.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace volref::compare {

struct ProcessRun {
    int status = -1;          // exit status; 128 + signal when killed by a signal; -1 when it could not start
    double seconds = 0.0;     // wall time from spawn to exit (steady clock)
    std::string first_error;  // the first line of its stderr
};

// Runs argv[0] (searched on PATH when it has no '/') with stdout discarded and stderr kept in `stderr_file`.
ProcessRun run_process(const std::vector<std::string>& argv, const std::filesystem::path& stderr_file);

// The median of `v` (mean of the two middle values for an even count); NaN for an empty v.
double median(std::vector<double> v);

// Whether `program` is found on PATH (an executable file).
bool on_path(const std::string& program);

// The running executable (/proc/self/exe).
std::filesystem::path self_executable();

}  // namespace volref::compare
