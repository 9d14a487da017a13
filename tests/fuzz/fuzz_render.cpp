// libFuzzer target: parse, then render what parses with the CPU reference on a
// tiny image (4×4, at most 2×2 samples): once as a fixed tree (depth 8), once
// under a tolerance with its cut-off steps, a tree budget and, for amplifying
// scenes, the steps below the floor. The shading, medium-stack, BVH and
// stepping code must hold for any scene: no sanitizer report, no NaN in the
// image, and bounds that are numbers.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "reference/CpuRenderer.h"
#include "scene/Parser.h"

namespace {

void renderChecked(const snell::CpuRenderer& renderer, const snell::RenderRequest& request) {
    std::vector<float> bounds;
    snell::RenderRequest r = request;
    r.boundImage = &bounds;
    const snell::Image image = renderer.render(r);
    for (const float v : image.rgb)
        if (std::isnan(v)) std::abort();  // a NaN colour: a bug in the tree, not in the scene
    for (const float b : bounds)
        if (std::isnan(b) || b < 0.0f) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    snell::Scene scene;
    try {
        scene = snell::parseScene(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.scn");
    } catch (const snell::ParseError&) {
        return 0;
    }
    // Keep each run short: a few hundred spheres and lights at most.
    if (scene.spheres.size() > 256 || scene.lights.size() > 64) return 0;
    snell::RenderRequest request;
    request.width = request.height = 4;
    request.supersample = std::min(scene.supersample, 2);
    request.camera = snell::Camera::fromSpec(4, scene.halfWidth);
    request.threads = 1;
    const snell::CpuRenderer renderer(scene);
    request.trace = {.maxDepth = 8, .minWeight = 1e-3};
    renderChecked(renderer, request);
    // The default's path: a tolerance, its steps and estimates, a small budget.
    request.trace = snell::kDefaultSettings;
    request.trace.treeBudget = 256;
    renderChecked(renderer, request);
    return 0;
}
