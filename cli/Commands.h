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
    bool error = false;        // --error: RenderOptions::error_estimate (step doubling, fixed integrator)
    std::vector<std::string> overrides;  // --set PATH=VALUE
    bool timing = false;       // --timing: print "volref: timing {...}" on stderr (docs/performance.md)
    int repeat = 1;            // --repeat N: render the frame N times after one set-up
};

// Renders args.scene to args.output; throws volref::Error on bad input. Returns the exit status.
int run_render(const RenderArgs& args);

// volref resample IN OUT --to cylindrical|spherical|cartesian --dims NX,NY,NZ [--shell JSON] ...
// Every value is kept as typed and checked by run_resample (one-line errors, exit status 1).
struct ResampleArgs {
    std::filesystem::path input;
    std::filesystem::path output;      // .nrrd
    std::string to;                    // cylindrical, spherical, cartesian
    std::string dims;                  // "nx,ny,nz" of the output grid
    std::string shell;                 // JSON text or a JSON file; "" = IN's volref_bounds (--to cartesian)
    std::string interpolation = "trilinear";
    std::string origin, spacing;       // "x,y,z" (--to cartesian; default: the shell's bounding box)
    std::string fill = "0";            // value of samples outside the source
    std::string type = "f64";          // f32, f64
    std::string encoding = "raw";      // raw, gzip
    std::string format;                // IN's format: "" (extension), nrrd, raw
};

// Resamples args.input to args.output (docs/shells.md); throws volref::Error on bad input.
int run_resample(const ResampleArgs& args);

}  // namespace volref::cli
