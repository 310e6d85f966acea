// volref convert IN OUT [--format F] [--type T] [--encoding raw|gzip]: a volume file to NRRD (.nrrd)
// or raw + JSON sidecar (.raw) (free of CLI11).
#pragma once
#include <filesystem>
#include <string>

namespace volref::cli {

struct ConvertArgs {
    std::filesystem::path input;
    std::filesystem::path output;  // .nrrd or .raw
    std::string format;            // IN's format; "" = from the extension
    std::string type;              // "" = f64 for NRRD, the input's type for raw
    std::string encoding = "raw";  // raw, gzip
};

// Reads args.input and writes args.output (temporary name, then renamed); throws volref::Error on bad
// input. Returns the exit status.
int run_convert(const ConvertArgs& args);

}  // namespace volref::cli
