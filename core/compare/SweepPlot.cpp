#include "core/compare/SweepPlot.h"

#include <cstdio>
#include <fstream>

#include "core/Error.h"
#include "core/compare/ChildProcess.h"

namespace volref::compare {

namespace fs = std::filesystem;

namespace {

// A gnuplot double-quoted string: backslashes and double quotes escaped.
std::string quoted(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '\\' || c == '"') out += '\\';
        out += c;
    }
    return out + "\"";
}

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

}  // namespace

void plot_error_against_time(const PlotSpec& spec, const fs::path& work_dir, const fs::path& png, const fs::path& svg) {
    // Data: one block per series (index i), columns time, max abs, RMSE, point label; only points with
    // a positive time and error (a log axis has no 0).
    const fs::path data = work_dir / "sweep-plot.dat";
    std::ofstream d(data);
    std::vector<std::size_t> blocks;  // series with at least one point
    for (std::size_t s = 0; s < spec.series.size(); ++s) {
        const PlotSeries& ps = spec.series[s];
        bool any = false;
        for (std::size_t i = 0; i < ps.time.size(); ++i) {
            if (!(ps.time[i] > 0.0 && ps.max_abs[i] > 0.0 && ps.rmse[i] > 0.0)) continue;
            if (!any && !blocks.empty()) d << "\n\n";
            any = true;
            d << num(ps.time[i]) << ' ' << num(ps.max_abs[i]) << ' ' << num(ps.rmse[i]) << ' '
              << quoted(ps.point_labels[i]) << '\n';
        }
        if (any) blocks.push_back(s);
    }
    d.close();
    if (blocks.empty()) throw Error("sweep: nothing to plot: every render equals its reference (error 0)");

    std::string plot = "plot ";
    for (std::size_t b = 0; b < blocks.size(); ++b) {
        const PlotSeries& ps = spec.series[blocks[b]];
        const std::string suffix = ps.label.empty() ? std::string() : " (" + ps.label + ")";
        const std::string idx = quoted(data.string()) + " index " + std::to_string(b);
        const std::string colour = " lc " + std::to_string(b + 1);
        plot += idx + " using 1:2 with linespoints lw 2 pt 7 ps 1.2" + colour + " title " +
                quoted("max abs error" + suffix) + ", \\\n     ";
        plot += idx + " using 1:3 with linespoints lw 1.5 dt 2 pt 6" + colour + " title " +
                quoted("RMSE" + suffix) + ", \\\n     ";
        plot += idx + " using 1:2:4 with labels offset char 1.2,0.6 font \",9\" notitle, \\\n     ";
    }
    // The tolerance: a dotted line across the whole plot (an arrow in graph x, first y), and its key
    // entry (a NaN function draws nothing but a key line).
    std::string tolerance_line;
    if (spec.tolerance > 0.0) {
        tolerance_line = "set arrow from graph 0, first " + num(spec.tolerance) + " to graph 1, first " +
                         num(spec.tolerance) + " nohead dt 3 lw 1.5 lc rgb \"gray40\"\n";
        plot += "NaN with lines dt 3 lw 1.5 lc rgb \"gray40\" title " + quoted("tolerance " + num(spec.tolerance));
    } else {
        plot.resize(plot.size() - std::string(", \\\n     ").size());
    }

    // The title's lines (spec.title split at '\n'), each escaped, joined by gnuplot's "\n".
    std::string title;
    for (std::size_t start = 0; start <= spec.title.size();) {
        std::size_t end = spec.title.find('\n', start);
        if (end == std::string::npos) end = spec.title.size();
        const std::string line = quoted(spec.title.substr(start, end - start));
        title += title.empty() ? line.substr(0, line.size() - 1) : "\\n" + line.substr(1, line.size() - 2);
        start = end + 1;
    }
    title += "\"";
    const std::string common =
        "set logscale xy\n"
        "set format x \"%g\"\n"
        "set format y \"%.0e\"\n" + tolerance_line +
        "set xlabel \"median wall time per render, whole volref process (s)\"\n"
        "set ylabel \"error against the reference\"\n"
        "set title " + title + "\n"
        "set grid xtics ytics mxtics mytics lc rgb \"gray85\"\n"
        "set key inside top right opaque box\n"
        "set offsets graph 0.08, graph 0.15, graph 0.1, graph 0.1\n" + plot + "\n";
    const fs::path script = work_dir / "sweep-plot.gp";
    std::ofstream g(script);
    g << "# volref sweep: error against time (gnuplot " << "script; data in " << data.string() << ")\n"
      << "set terminal pngcairo size 900,680 font \"DejaVu Sans,10\" noenhanced\n"
      << "set output " << quoted(png.string()) << "\n"
      << common << "set output\n"
      << "set terminal svg size 900,680 font \"DejaVu Sans,10\" noenhanced\n"
      << "set output " << quoted(svg.string()) << "\n"
      << "replot\nset output\n";
    g.close();
    const ProcessRun run = run_process({"gnuplot", script.string()}, work_dir / "gnuplot.err");
    if (run.status != 0)
        throw Error("sweep: gnuplot failed (status " + std::to_string(run.status) + "): " + run.first_error);
    std::error_code ec;
    if (fs::file_size(png, ec) == 0 || ec || fs::file_size(svg, ec) == 0 || ec)
        throw Error("sweep: gnuplot wrote no plot (" + png.string() + ", " + svg.string() + ")");
}

}  // namespace volref::compare
