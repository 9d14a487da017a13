// `snell check`: what a scene holds and what looks wrong in it, without rendering.
#include <iostream>

#include "check/SceneCheck.h"
#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "cli/Options.h"

namespace snell::cli {
namespace {

class CheckCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        CLI::App* c = app.add_subcommand(
            "check", "Parse a scene and report what it holds and what looks wrong, without rendering");
        c->add_option("scene", scene_, kSceneHelp)->required();
        c->add_flag("--json", json_, "One JSON object on standard output");
        return c;
    }

    // Statistics on standard output, warnings (the same as render's) on standard error.
    int run() override {
        const Scene scene = readScene(scene_);
        const SceneReport report = checkScene(scene, sceneFile(scene_));
        for (const Diagnostic& w : report.warnings) std::cerr << w.format("warning") << "\n";
        std::cout << (json_ ? report.json(scene) + "\n" : report.text(scene));
        return kExitSuccess;
    }

private:
    std::string scene_;
    bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> makeCheckCommand() { return std::make_unique<CheckCommand>(); }

}  // namespace snell::cli
