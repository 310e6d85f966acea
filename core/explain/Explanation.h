// Explanation: what `volref explain TOPIC` prints, as data: named sections of steps (a name, the
// formula it evaluates, its value: a number or a vector) or tables (columns and rows of numbers).
// The calculators (Explain.h) fill it with the values the renderer's own functions return; to_text
// prints it as readable tables, to_json for programs (docs/explain.md). Numbers are printed as the
// shortest text that reads back as the same double (NumberFormat.h).
#pragma once
#include <string>
#include <vector>

namespace volref::explain {

struct Step {
    std::string name;                // unique within its section, e.g. "f12", "alpha"
    std::vector<double> value;       // one number or a vector
    std::string formula;             // how it is computed (may be empty)
};

struct Section {
    std::string title;
    std::vector<Step> steps;                      // a list of steps, or
    std::vector<std::string> columns;             // a table: column names
    std::vector<std::vector<double>> rows;        //          and rows (one number per column)
    std::vector<std::string> notes;               // lines of text printed after it
};

struct Explanation {
    std::string topic;
    std::vector<Section> sections;

    Section& section(const std::string& title) {
        sections.push_back(Section{title, {}, {}, {}, {}});
        return sections.back();
    }
    // The step `name` of the section titled `title` (throws std::out_of_range if absent).
    const Step& step(const std::string& title, const std::string& name) const;
    double value(const std::string& title, const std::string& name) const { return step(title, name).value.at(0); }
    const Section& find(const std::string& title) const;
};

inline void add(Section& s, std::string name, double v, std::string formula = {}) {
    s.steps.push_back(Step{std::move(name), {v}, std::move(formula)});
}
inline void add(Section& s, std::string name, std::vector<double> v, std::string formula = {}) {
    s.steps.push_back(Step{std::move(name), std::move(v), std::move(formula)});
}

std::string to_text(const Explanation& e);
// {"topic": T, "sections": [{"title": ..., "steps": {name: value, ...}, "formulas": {name: formula},
//   "columns": [...], "rows": [{column: value, ...}], "notes": [...]}]}; a vector value is an array;
// non-finite numbers are the strings "inf", "-inf", "nan".
std::string to_json(const Explanation& e);

}  // namespace volref::explain
