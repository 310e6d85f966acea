#include "core/compare/SweepGrid.h"

#include "core/Error.h"

namespace volref::compare {

SweepParam parse_sweep_param(const std::string& text) {
    auto fail = [&](const std::string& why) { throw Error("--param '" + text + "': " + why); };
    const auto eq = text.find('=');
    if (eq == std::string::npos) fail("expected PATH=V1,V2,... (e.g. render.step=0.5,0.25)");
    SweepParam p;
    p.path = text.substr(0, eq);
    if (p.path.empty()) fail("empty scene path before '='");
    const std::string list = text.substr(eq + 1);
    int depth = 0;
    bool quoted = false;
    std::string current;
    auto push = [&] {
        if (current.empty()) fail("empty value in the list '" + list + "'");
        p.values.push_back(current);
        current.clear();
    };
    for (std::size_t i = 0; i < list.size(); ++i) {
        const char c = list[i];
        if (quoted) {
            if (c == '\\' && i + 1 < list.size()) current += list[i++];
            else if (c == '"') quoted = false;
        } else if (c == '"') {
            quoted = true;
        } else if (c == '[' || c == '{') {
            ++depth;
        } else if (c == ']' || c == '}') {
            if (--depth < 0) fail("unbalanced '" + std::string(1, c) + "'");
        } else if (c == ',' && depth == 0) {
            push();
            continue;
        }
        current += c;
    }
    if (quoted || depth != 0) fail("unclosed quote or bracket");
    push();
    return p;
}

std::vector<std::vector<std::string>> sweep_combinations(const std::vector<SweepParam>& params) {
    for (std::size_t i = 0; i < params.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (params[i].path == params[j].path) throw Error("--param " + params[i].path + ": given twice");
    std::vector<std::vector<std::string>> out{{}};
    for (const SweepParam& p : params) {
        std::vector<std::vector<std::string>> next;
        for (const auto& prefix : out)
            for (const std::string& v : p.values) {
                next.push_back(prefix);
                next.back().push_back(p.path + "=" + v);
            }
        out = std::move(next);
    }
    return out;
}

}  // namespace volref::compare
