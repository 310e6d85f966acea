// The parameter grid of `volref sweep`: each --param PATH=V1,V2,... names a scene key (as for
// `volref render --set`) and its values; the sweep renders every combination, the first --param
// varying slowest. Values are split at commas outside brackets, braces and double quotes, so
// `volume.transfer.opacity[1]=[0.5,0.2],[0.5,0.4]` gives two arrays.
#pragma once
#include <string>
#include <vector>

namespace volref::compare {

struct SweepParam {
    std::string path;                 // e.g. render.step
    std::vector<std::string> values;  // e.g. 0.5, 0.25 (each as it would follow "PATH=" in --set)
};

// Parses "PATH=V1,V2,..."; throws volref::Error("--param 'TEXT': ...") when there is no '=', the path or a
// value is empty, or a bracket or quote is not closed.
SweepParam parse_sweep_param(const std::string& text);

// Every combination as a list of --set overrides "PATH=VALUE", in the order of `params`; the last
// parameter varies fastest. Throws volref::Error when a path is given twice.
std::vector<std::vector<std::string>> sweep_combinations(const std::vector<SweepParam>& params);

}  // namespace volref::compare
