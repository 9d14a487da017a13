// The end of a run: the summary table on the terminal, and bench.md and
// bench.png by bench/summarize.py.
#include "bench/BenchParts.h"

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "bench/PovExport.h"

namespace snell::bench {

namespace {

std::string fixed(double v, int decimals) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(decimals) << v;
    return s.str();
}

// Per scene: the default's dispatch and error, its price, and the CPU
// reference at the same settings (the whole render, on all cores).
void sceneTable(const Collected& c, std::ostream& out) {
    out << std::left << std::setw(22) << "scene" << std::right << std::setw(12) << "default ms" << std::setw(12)
        << "mean error" << std::setw(12) << "price" << std::setw(20) << "CPU ms (runs)" << std::setw(12)
        << "GPU faster" << "\n";
    for (const Price& p : c.prices) {
        const auto cpu = c.cpuDefaultMs.find(p.scene);
        const std::string price =
            std::isnan(p.price) ? "-" : (p.upperBound ? "< " : "") + fixed(p.price, 2) + "x";
        out << std::left << std::setw(22) << p.scene << std::right << std::setw(12) << fixed(p.defaultMs, 3)
            << std::setw(12) << fixed(p.defaultMean, 4) << std::setw(12) << price << std::setw(20)
            << (cpu == c.cpuDefaultMs.end()
                    ? "-"
                    : fixed(cpu->second.ms.median, 3) + " (" + std::to_string(cpu->second.runs) + ")")
            << std::setw(12)
            << (cpu == c.cpuDefaultMs.end() ? "-" : fixed(cpu->second.ms.median / p.defaultMs, 1) + "x") << "\n";
    }
}

// The peers: the same tree in each, timed; POV-Ray's image against snell's.
void peerTable(const Collected& c, std::ostream& out) {
    out << "\npeers: depth " << kPeerDepth << " without a cut-off (POV-Ray's max_trace_level "
        << povTraceLevel(kPeerDepth) << "), one ray a pixel\n"
        << std::left << std::setw(16) << "scene" << std::right << std::setw(6) << "size" << std::setw(12)
        << "snell ms" << std::setw(16) << "POV-Ray ms" << std::setw(14) << "snell faster" << std::setw(20)
        << "commands ms" << "  POV-Ray's image against snell's\n";
    for (const Peer& p : c.peers) {
        out << std::left << std::setw(16) << p.scene << std::right << std::setw(6) << p.size << std::setw(12)
            << fixed(p.snellDispatchMs, 3);
        if (!p.povTraceMs) {
            out << "  POV-Ray: " << p.povNote << "\n";
            continue;
        }
        const std::string commands = fixed(p.snellCommandMs, 0) + " / " + fixed(*p.povCommandMs, 0);
        out << std::setw(16) << (number(*p.povTraceMs) + " (to " + number(p.povTraceResolutionMs) + ")")
            << std::setw(14) << ratioText(*p.povTraceMs, p.povTraceResolutionMs / 2, p.snellDispatchMs)
            << std::setw(20) << commands << "  " << describe(p.agreement) << "\n";
    }
}

}  // namespace

void printSummary(const Collected& c, int size, bool gpuTimed, std::ostream& out) {
    out << "snell bench at " << size << "x" << size << ": the dispatch's median ("
        << (gpuTimed ? "GPU timestamps" : "host timing") << "), mean error against the limit reference in 1/255, the price of the default, and the CPU "
           "reference at the same settings (the whole render, on all cores)\n";
    sceneTable(c, out);
    if (!c.peers.empty()) peerTable(c, out);
    out << describe(summarizePrices(c.prices)) << "\n";
}

// The first python3 (on PATH, else Debian's) that has matplotlib draws the
// plot; without one, the tables alone.
void writeTablesAndPlot(const BenchOptions& o, std::ostream& log) {
    const fs::path script = fs::path(o.sourceDir) / "bench" / "summarize.py";
    const fs::path out(o.outDir);
    if (!fs::exists(script)) {
        log << "snell: warning: no tables or plot: " << script.string() << " is not there (--source-dir)\n";
        return;
    }
    std::string python;
    for (const char* candidate : {"python3", "/usr/bin/python3"})
        if (std::system((std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
            python = candidate;
            break;
        }
    const bool plot = !python.empty();
    if (!plot) python = "python3";
    // Its tables to bench.md; its messages are shown where it fails.
    const std::string command = "(" + python + " " + quote(script.string()) + " " +
                                quote((out / "bench.json").string()) +
                                (plot ? " --plot " + quote((out / "bench.png").string()) : "") + " > " +
                                quote((out / "bench.md").string()) + ")";
    try {
        runCommand(command);
    } catch (const BenchError& e) {
        log << "snell: warning: bench/summarize.py failed, no tables or plot: " << e.what() << "\n";
        return;
    }
    log << "bench: wrote " << (out / "bench.md").string() << " (the tables)"
        << (plot ? " and " + (out / "bench.png").string() + " (the plot)" : "") << "\n";
    if (!plot)
        log << "snell: warning: no plot: no python3 here has matplotlib (Debian: apt-get install python3-matplotlib)\n";
}

}  // namespace snell::bench
