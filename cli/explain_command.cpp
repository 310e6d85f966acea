// volref explain TOPIC [--json] OPTIONS (docs/explain.md): the parsing and the calculators are in
// core/explain/ (ExplainArguments.h, Explain.h); this prints the result as text or JSON.
#include <iostream>

#include "cli/ExplainCommand.h"
#include "core/explain/ExplainArguments.h"

namespace volref::cli {

const char* explain_topics() { return explain::topics(); }

int run_explain(const ExplainArgs& in) {
    ExplainArgs args = in;  // --json may also come among the topic's options
    std::erase_if(args.args, [&](const std::string& s) { return s == "--json" && (args.json = true); });
    const explain::Explanation e = explain::from_arguments(args.topic, args.args);
    std::cout << (args.json ? explain::to_json(e) + "\n" : explain::to_text(e));
    return 0;
}

}  // namespace volref::cli
