// Statistics of timed runs, and the subprocesses the bench runs (whole commands, POV-Ray).
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <cstdio>
#include <sys/resource.h>
#include <sys/wait.h>

#include "common/Clock.h"

namespace snell::bench {

Stats stats(std::vector<double> v) {
    if (v.empty()) return {};
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return {median, v.front(), v.back()};
}

std::string number(double v) {
    if (!std::isfinite(v)) return "null";
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}


double peakRssMiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss / 1024.0;
}

// Runs a command (through the shell), returning its wall time in ms and its
// output; throws when it cannot run or fails.
double runCommand(const std::string& command, std::string* output) {
    const auto start = Clock::now();
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe) throw BenchError("cannot run: " + command);
    std::string text;
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) text.append(buffer, n);
    const int status = ::pclose(pipe);
    const double ms = msSince(start);
    if (output) *output = text;
    if (status != 0)
        throw BenchError("command failed (status " + std::to_string(WEXITSTATUS(status)) + "): " + command + "\n" +
                         text.substr(0, 2000));
    return ms;
}

std::string quote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

}  // namespace snell::bench
