// volref explain TOPIC [--json] OPTIONS (docs/explain.md): the parsing and the calculators are in
// core/explain/ (ExplainArguments.h, Explain.h); this prints the result as text or JSON.
#include <cstdio>
#include <iostream>
#include <string>

#include "cli/ExplainCommand.h"
#include "core/explain/ExplainArguments.h"

namespace volref::cli {

const char* explain_topics() { return explain::topics(); }

int run_explain(const ExplainArgs& in) {
    ExplainArgs args = in;  // --json may also come among the topic's options
    std::erase_if(args.args, [&](const std::string& s) { return s == "--json" && (args.json = true); });
    const explain::Explanation e = explain::from_arguments(args.topic, args.args);
    if (!args.json && e.topic == "texture-fetch" && e.sections.size() == 1 && !e.sections[0].rows.empty()) {
        // --points: a header line, then x,y,z,fetch per point (the fetch with 9 significant digits)
        std::string out = "x,y,z,fetch\n";
        char line[128];
        for (const auto& r : e.sections[0].rows) {
            std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g\n", r[0], r[1], r[2], r[3]);
            out += line;
        }
        std::cout << out;
        return 0;
    }
    if (e.topic == "volpack-scene") {  // the scene file itself (JSON either way)
        std::cout << e.sections.at(0).notes.at(0) << "\n";
        return 0;
    }
    std::cout << (args.json ? explain::to_json(e) + "\n" : explain::to_text(e));
    return 0;
}

}  // namespace volref::cli
