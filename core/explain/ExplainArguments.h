// The command line of `volref explain TOPIC OPTIONS` as a library call (cli/explain_command.cpp and the
// tests use it): parses the topic's options (docs/explain.md) and runs its calculator (Explain.h).
#pragma once
#include <string>
#include <vector>

#include "core/explain/Explanation.h"

namespace volref::explain {

// Throws volref::Error with a one-line message naming the option at fault (or the unknown topic).
Explanation from_arguments(const std::string& topic, const std::vector<std::string>& options);

// "trilinear, composite, ...": the topics, for messages and the usage text.
const char* topics();

}  // namespace volref::explain
