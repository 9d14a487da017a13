// Statistics of timed runs, and the subprocesses the bench runs (whole commands, POV-Ray).
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
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


namespace {

// Timed renders of one that took firstMs: none where it took kCpuSingleRunMs
// or more, else at least `runs`, and as many as fill kCpuBudgetMs.
int cpuRuns(double firstMs, int runs) {
    if (firstMs >= kCpuSingleRunMs) return 0;
    return std::clamp(int(std::ceil(kCpuBudgetMs / std::max(firstMs, 1e-3))), runs, std::max(runs, kCpuMaxRuns));
}

double timeOnce(const std::function<void()>& render) {
    const auto start = Clock::now();
    render();
    return msSince(start);
}

}  // namespace

CpuTiming timeCpu(const std::function<void()>& render, double firstMs, int runs) {
    const int n = cpuRuns(firstMs, runs);
    if (n == 0) return {{firstMs, firstMs, firstMs}, 1};
    std::vector<double> ms;
    for (int k = 0; k < n; ++k) ms.push_back(timeOnce(render));
    return {stats(ms), n};
}

std::pair<CpuTiming, CpuTiming> timeCpuSideBySide(const std::function<void()>& a, double firstA,
                                                  const std::function<void()>& b, double firstB, int runs) {
    const int n = std::min(cpuRuns(firstA, runs), cpuRuns(firstB, runs));
    if (n == 0) return {timeCpu(a, firstA, runs), timeCpu(b, firstB, runs)};
    std::vector<double> msA, msB;
    for (int k = 0; k < n; ++k) {
        msA.push_back(timeOnce(a));
        msB.push_back(timeOnce(b));
    }
    return {{stats(msA), n}, {stats(msB), n}};
}

std::string describe(const CpuTiming& t) {
    return number(t.ms.median) + " ms" + (t.runs > 1 ? " (median of " + std::to_string(t.runs) + ")" : "");
}

std::string ratioText(double a, double halfStep, double b) {
    if (!(a >= 0.0) || !(b > 0.0)) return "null";
    auto digits = [](double v, int n) {  // n significant digits, trailing zeros kept
        std::ostringstream s;
        s << std::fixed << std::setprecision(v > 0.0 ? std::max(0, n - 1 - int(std::floor(std::log10(v)))) : n);
        s << v;
        return s.str();
    };
    const double u = halfStep / a;  // a's relative uncertainty
    if (u <= 5e-3) return digits(a / b, u <= 5e-4 ? 3 : 2) + "x";
    const std::string low = digits(std::max(0.0, a - halfStep) / b, 2), high = digits((a + halfStep) / b, 2);
    if (a <= halfStep) return "below " + high + "x";
    return low == high ? high + "x" : low + "-" + high + "x";  // two digits where both ends round to them
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
