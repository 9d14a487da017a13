// libFuzzer target: parse, then render what parses with the CPU reference on a
// tiny image (4×4, at most 2×2 samples, depth 8) — the shading, medium-stack
// and BVH code must hold for any scene, with no NaN trap or sanitizer report.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "reference/CpuRenderer.h"
#include "scene/Parser.h"

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
    request.trace = {8, 1e-3};
    request.threads = 1;
    const snell::CpuRenderer renderer(scene);
    const snell::Image image = renderer.render(request);
    (void)image;
    return 0;
}
