// `snell preview`: a scene in a window, live (host/preview/).
#include "cli/Command.h"
#include "cli/ExitStatus.h"
#include "cli/Options.h"
#include "image/ImageIO.h"
#include "preview/Preview.h"
#include "scene/Parser.h"

namespace snell::cli {
namespace {

class PreviewCommand : public Command {
public:
    CLI::App* define(CLI::App& app) override {
        CLI::App* c = app.add_subcommand("preview", "Show a scene in a window, live: orbit, inspect, hot reload");
        c->footer(kPreviewKeys);
        c->add_option("scene", o_.scene, "Scene file (re-rendered when saved)")->required();
        c->add_option("-s,--size", o_.size, "Rendered image size in pixels (default: the scene's view n)")
            ->check(wholeNumber(1, 4096));
        addTreeOptions(*c, tree_, {"Initial maximum depth (default: 64)",
                                   "Stop rays whose weight falls below W (default: 1e-4)", 256});
        addDeviceOptions(*c, device_);
        c->add_flag("-q,--quiet", o_.quiet, "No warnings or reload timings on stderr");
        CLI::Option* frames =
            c->add_option("--frames", o_.frames, "Scripted: show N frames, then save --screenshot and exit")
                ->check(wholeNumber(1, std::numeric_limits<int>::max()));
        c->add_option("--screenshot", o_.screenshot, "Scripted: the PNG to save after --frames frames")->needs(frames);
        c->add_option("--orbit", o_.orbitDegrees, "Scripted: orbit the camera by DEGREES before the first frame")
            ->check(kFinite);
        c->add_option("--orbit-per-frame", o_.orbitPerFrame,
                      "Scripted: orbit the camera by DEGREES before every frame, as a drag would (the moving camera)")
            ->check(kFinite)->needs(frames);
        return c;
    }

    int run() override {
        // The window reloads the file when it is saved: standard input cannot be.
        if (o_.scene == "-") throw InputError("preview needs a scene file (it re-reads it when saved), not -");
        // The screenshot's place is checked before a window opens, not after its frames.
        if (!o_.screenshot.empty()) checkWritable(o_.screenshot);
        device_.readEnvironment();
        o_.depth = tree_.depth;
        o_.minWeight = tree_.minWeight;
        o_.supersample = tree_.supersample;
        o_.gpu = device_.gpu;
        o_.validation = device_.validation;
        o_.precision = device_.arithmetic();
        o_.traversal = device_.search();
        o_.rayQueries = device_.context().rayQueries;
        o_.cancel = interruptFlag();
        o_.pipelineCachePath = pipelineCachePath();
        runPreview(o_);
        return kExitSuccess;
    }

private:
    PreviewOptions o_;
    TreeOptions tree_;
    DeviceOptions device_;
};

}  // namespace

std::unique_ptr<Command> makePreviewCommand() { return std::make_unique<PreviewCommand>(); }

}  // namespace snell::cli
