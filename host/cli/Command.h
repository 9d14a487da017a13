// One subcommand of snell, kept as git keeps its builtins: each owns its
// options, help text and run function (host/cli/*Command.cpp), and main.cpp
// is the table of them.
#pragma once

#include <memory>

#include <CLI/CLI.hpp>

namespace snell::cli {

class Command {
public:
    virtual ~Command() = default;
    // Adds the subcommand, with its options and help, to `app`.
    virtual CLI::App* define(CLI::App& app) = 0;
    // Runs it once the command line is parsed. Returns the exit status or
    // throws (ExitStatus.h maps what it throws to a message and a status).
    virtual int run() = 0;
};

std::unique_ptr<Command> makeRenderCommand();
std::unique_ptr<Command> makePreviewCommand();
std::unique_ptr<Command> makeBenchCommand();
std::unique_ptr<Command> makeCheckCommand();
std::unique_ptr<Command> makeAssembleCommand();
std::unique_ptr<Command> makeCompareCommand();
std::unique_ptr<Command> makeDevicesCommand();

}  // namespace snell::cli
