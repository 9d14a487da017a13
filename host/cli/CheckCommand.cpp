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
        c->add_flag("--json", json_,
                    "One JSON object on standard output, also when the scene has errors: \"errors\" and "
                    "\"warnings\", each with file, line, column and message, and without errors the statistics");
        return c;
    }

    // Statistics on standard output; errors and warnings (the same as
    // render's), in line order, on standard error.
    int run() override {
        const std::string path = sceneFile(scene_);
        ParseOutcome outcome = parseSceneArgument(scene_);
        if (outcome.error) {
            const ParseError errors = outcome.error->withWarnings(partialSceneWarnings(outcome.scene, path));
            if (json_) std::cout << errorsJson(outcome.scene.name, errors) << "\n" << std::flush;
            throw errors;
        }
        const SceneReport report = checkScene(outcome.scene, path);
        for (const Diagnostic& w : report.warnings) std::cerr << w.format("warning") << "\n";
        std::cout << (json_ ? report.json(outcome.scene) + "\n" : report.text(outcome.scene));
        return kExitSuccess;
    }

private:
    std::string scene_;
    bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> makeCheckCommand() { return std::make_unique<CheckCommand>(); }

}  // namespace snell::cli
