#include "cli/ExitStatus.h"

#include <csignal>
#include <iostream>

#include "scene/Parser.h"

namespace snell::cli {
namespace {

std::atomic<bool> gInterrupted{false};
volatile std::sig_atomic_t gSignal = 0;

extern "C" void onSignal(int signal) {
    gSignal = signal;
    gInterrupted.store(true);
}

}  // namespace

void installSignalHandlers() {
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::signal(SIGHUP, onSignal);
}

const std::atomic<bool>* interruptFlag() { return &gInterrupted; }
bool interrupted() { return gInterrupted.load(); }
int interruptedStatus() { return 128 + (gSignal != 0 ? int(gSignal) : SIGINT); }

int runReportingErrors(const std::function<int()>& command) {
    try {
        const int status = command();
        return interrupted() ? interruptedStatus() : status;
    } catch (const ParseError& e) {
        std::cerr << e.what() << "\n";
        return kExitInput;
    } catch (const InputError& e) {
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitInput;
    } catch (const Interrupted& e) {
        std::cerr << "snell: interrupted; " << e.what() << "\n";
        return interruptedStatus();
    } catch (const std::exception& e) {
        // A failure that a signal caused (a cancelled render) is the signal's.
        if (interrupted()) {
            std::cerr << "snell: interrupted\n";
            return interruptedStatus();
        }
        std::cerr << "snell: error: " << e.what() << "\n";
        return kExitRuntime;
    }
}

}  // namespace snell::cli
