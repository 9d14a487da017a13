// snell's command line: a table of subcommands (host/cli/*Command.cpp), each
// owning its options and help; errors become exit statuses in ExitStatus.cpp.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "cli/OptionErrors.h"
#include "vulkan/VulkanContext.h"

#ifndef SNELL_VERSION
#define SNELL_VERSION "0.0.0"
#endif

namespace {

using namespace snell::cli;

const char* kExitStatuses =
    "Exit status: 0 success; 1 runtime failure (no Vulkan device, device lost, unwritable output);\n"
    "2 bad scene file (FILE:LINE:COL: error: ...) or command line (snell: error: ...); 128+N ended by signal N "
    "(Ctrl-C: 130).\ncompare: 0 the images agree, 1 they differ, 2 trouble.";

std::string versionText() {
    std::string text = std::string("snell ") + SNELL_VERSION;
    try {
        snell::vk::Context context;
        text += "\ndevice: " + context.deviceName() + " (" + context.driverInfo() + ")";
    } catch (const snell::vk::VulkanError& e) {
        text += "\ndevice: none (" + std::string(e.what()) + ")";
    }
    return text;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"snell: a Whitted-style ray tracer whose renderer is a Vulkan compute shader.\n"
                 "Scene format: docs/scene-format.md (installed with the documentation); man snell.",
                 "snell"};
    app.footer(kExitStatuses);
    app.require_subcommand(0, 1);
    bool version = false;
    app.add_flag("--version", version, "Print the version and the Vulkan device snell would use");

    std::vector<std::unique_ptr<Command>> commands;
    for (auto make : {makeRenderCommand, makePreviewCommand, makeBenchCommand, makeCheckCommand,
                      makeAssembleCommand, makeCompareCommand, makeDevicesCommand})
        commands.push_back(make());
    std::vector<std::pair<CLI::App*, Command*>> table;
    for (const auto& command : commands) table.emplace_back(command->define(app), command.get());

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One voice: the option library's errors read as snell's own.
        std::cerr << "snell: error: " << describeParseError(app, e) << "\n";
        return kExitInput;
    }
    if (version) {
        std::cout << versionText() << "\n";
        return kExitSuccess;
    }
    installSignalHandlers();
    for (const auto& [subcommand, command] : table)
        if (subcommand->parsed()) return runReportingErrors([command = command] { return command->run(); });
    std::cout << app.help();
    return kExitSuccess;
}
