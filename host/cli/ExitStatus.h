// How snell's commands end: the one place that maps what a command throws to
// a message on standard error and an exit status.
//   0 success · 1 runtime failure (Vulkan, files) · 2 bad scene, input or
//   command line · 128 + N ended by signal N (SIGINT 130, SIGHUP 129, SIGTERM 143)
#pragma once

#include <atomic>
#include <functional>
#include <stdexcept>

namespace snell::cli {

constexpr int kExitSuccess = 0;
constexpr int kExitRuntime = 1;
constexpr int kExitInput = 2;

// A bad command line or input file found after parsing: "snell: error: WHAT", status 2.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A command stopped by a termination signal: "snell: interrupted; WHAT", status 128 + N.
class Interrupted : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// SIGINT, SIGTERM and SIGHUP set the interrupt flag, which long-running
// commands poll so that they can stop cleanly (no partial output).
void installSignalHandlers();
const std::atomic<bool>* interruptFlag();
bool interrupted();
int interruptedStatus();

// Runs `command` and returns its status; what it throws becomes one message
// and a status: scene errors (already FILE:LINE:COL: error: …) and InputError
// 2, Interrupted (or anything thrown once a signal came) 128 + N, the rest 1.
int runReportingErrors(const std::function<int()>& command);

}  // namespace snell::cli
