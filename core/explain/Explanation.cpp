#include "core/explain/Explanation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "core/explain/NumberFormat.h"

namespace volref::explain {

const Section& Explanation::find(const std::string& title) const {
    for (const Section& s : sections)
        if (s.title == title) return s;
    throw std::out_of_range("no section \"" + title + "\"");
}

const Step& Explanation::step(const std::string& title, const std::string& name) const {
    for (const Step& s : find(title).steps)
        if (s.name == name) return s;
    throw std::out_of_range("no step \"" + name + "\" in \"" + title + "\"");
}

namespace {

std::string value_text(const std::vector<double>& v) {
    if (v.size() == 1) return number(v[0]);
    std::string out = "(";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + number(v[i]);
    return out + ")";
}

nlohmann::json jnum(double v) {
    if (std::isfinite(v)) return v;
    return number(v);
}

nlohmann::json jvalue(const std::vector<double>& v) {
    if (v.size() == 1) return jnum(v[0]);
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(jnum(x));
    return a;
}

}  // namespace

std::string to_text(const Explanation& e) {
    std::ostringstream out;
    out << "volref explain " << e.topic << "\n";
    for (const Section& s : e.sections) {
        out << "\n" << s.title << "\n";
        if (!s.steps.empty()) {
            std::size_t wn = 0, wv = 0;
            std::vector<std::string> values;
            for (const Step& st : s.steps) {
                values.push_back(value_text(st.value));
                wn = std::max(wn, st.name.size());
                wv = std::max(wv, values.back().size());
            }
            for (std::size_t i = 0; i < s.steps.size(); ++i) {
                const Step& st = s.steps[i];
                std::string line = "  " + st.name + std::string(wn - st.name.size(), ' ') + " = " + values[i];
                if (!st.formula.empty()) line += std::string(wv - values[i].size(), ' ') + "   " + st.formula;
                out << line << "\n";
            }
        }
        if (!s.columns.empty()) {
            std::vector<std::vector<std::string>> cells;
            std::vector<std::size_t> w(s.columns.size());
            for (std::size_t c = 0; c < s.columns.size(); ++c) w[c] = s.columns[c].size();
            for (const auto& row : s.rows) {
                cells.emplace_back();
                for (std::size_t c = 0; c < row.size() && c < s.columns.size(); ++c) {
                    cells.back().push_back(number(row[c]));
                    w[c] = std::max(w[c], cells.back().back().size());
                }
            }
            auto line = [&](const std::vector<std::string>& v) {
                std::string l = " ";
                for (std::size_t c = 0; c < v.size(); ++c) l += " " + std::string(w[c] - v[c].size(), ' ') + v[c];
                out << l << "\n";
            };
            line(s.columns);
            for (const auto& c : cells) line(c);
        }
        for (const std::string& n : s.notes) out << "  " << n << "\n";
    }
    return out.str();
}

std::string to_json(const Explanation& e) {
    nlohmann::json j;
    j["topic"] = e.topic;
    nlohmann::json sections = nlohmann::json::array();
    for (const Section& s : e.sections) {
        nlohmann::json o;
        o["title"] = s.title;
        if (!s.steps.empty()) {
            nlohmann::json steps = nlohmann::json::object(), formulas = nlohmann::json::object();
            for (const Step& st : s.steps) {
                steps[st.name] = jvalue(st.value);
                if (!st.formula.empty()) formulas[st.name] = st.formula;
            }
            o["steps"] = steps;
            o["formulas"] = formulas;
        }
        if (!s.columns.empty()) {
            o["columns"] = s.columns;
            nlohmann::json rows = nlohmann::json::array();
            for (const auto& row : s.rows) {
                nlohmann::json r = nlohmann::json::object();
                for (std::size_t c = 0; c < row.size() && c < s.columns.size(); ++c) r[s.columns[c]] = jnum(row[c]);
                rows.push_back(r);
            }
            o["rows"] = rows;
        }
        if (!s.notes.empty()) o["notes"] = s.notes;
        sections.push_back(o);
    }
    j["sections"] = sections;
    return j.dump(2);
}

}  // namespace volref::explain
