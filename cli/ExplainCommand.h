// volref explain TOPIC [--json] OPTIONS: a formula worked step by step by the renderer's own functions
// (core/explain/Explain.h, docs/explain.md). main.cpp hands over the topic and the raw option tokens;
// run_explain parses them, so every bad value is a one-line volref::Error naming its option (exit 1).
#pragma once
#include <string>
#include <vector>

namespace volref::cli {

struct ExplainArgs {
    std::string topic;              // trilinear, composite, opacity-correction, classify-isovalue,
                                    // classify-boundary, shade, coords, intersect, ray
    bool json = false;              // --json
    std::vector<std::string> args;  // the topic's options, as typed
};

int run_explain(const ExplainArgs& args);

// The topics, for the usage text.
const char* explain_topics();

}  // namespace volref::cli
