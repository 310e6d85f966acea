// volref compare A B [--tolerance X] [--tolerance-from-error] [--background R,G,B,A] [--heatmap OUT.png]
//                    [--heatmap-scale S] [--fit [--scene SCENE.json]] [--json]   (docs/compare.md)
// Exit status: 0 within tolerance, 1 not within tolerance, 2 usage errors and unreadable or
// incompatible inputs (so that a test calling it can tell "differs" from "could not compare").
#pragma once
#include <filesystem>
#include <string>

namespace volref::cli {

struct CompareArgs {
    std::filesystem::path a, b;
    double tolerance = 0.0;               // --tolerance X (absolute, per channel)
    bool tolerance_from_error = false;    // --tolerance-from-error: add the inputs' `error` channels
    std::string background;               // --background R,G,B,A: composite associated (EXR) inputs over it
    std::filesystem::path heatmap;        // --heatmap OUT.png
    double heatmap_scale = 0.0;           // --heatmap-scale S (0: the max abs difference)
    bool fit = false;                     // --fit: gain, opacity exponent, shift (Ceres)
    bool json = false;                    // --json: the report as JSON on stdout
    std::filesystem::path scene;          // --scene SCENE.json (with --fit): B's scene, re-rendered with
                                          // each convention changed (Fits.h, ConventionVariant)
};

// Returns 0 (within tolerance) or 1 (not); throws volref::Error on bad input (main exits 2 for compare).
int run_compare(const CompareArgs& args);

}  // namespace volref::cli
