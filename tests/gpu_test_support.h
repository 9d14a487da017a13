// What the GPU test files share: the Vulkan context (gpu_test_context.h), a
// whole image at the defaults, pixels compared bit for bit, a walk rendered
// both ways, and the rule for a test that cannot test what it names here.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "gpu/ComputeRenderer.h"
#include "gpu_test_context.h"
#include "image/Image.h"
#include "render/RenderRequest.h"
#include "scene/Parser.h"

namespace snell::testing {

inline vk::Context& context() { return gpuContext(); }

// Under CI (CI=true) every GPU test must test what it names.
inline bool underCi() {
    const char* ci = std::getenv("CI");
    return ci && std::string(ci) == "true";
}

// A render of the whole image at `size`, at the defaults.
inline RenderRequest wholeImage(const Scene& scene, int size) {
    RenderRequest request;
    request.width = request.height = size;
    request.supersample = scene.supersample;
    request.camera = Camera::fromSpec(size, scene.halfWidth);
    request.trace = kDefaultSettings;
    return request;
}

// Pixels not the same bit for bit.
inline std::size_t pixelsThatDiffer(const Image& a, const Image& b) {
    std::size_t differ = 0;
    for (std::size_t i = 0; i + 2 < a.rgb.size(); i += 3) differ += !std::equal(&a.rgb[i], &a.rgb[i] + 3, &b.rgb[i]);
    return differ;
}

// A BVH scene, a precision: a case for the walk's variants below.
struct WalkCase {
    const char* file;
    gpu::Precision precision;
};

// Renders each case with `choose(options, false)` and again with
// `choose(options, true)`, checking each renderer with `check`, and requires
// the same image, bit for bit (and, with countRays, the same rays of each kind).
inline void requireTheSameWalk(std::initializer_list<WalkCase> cases,
                               const std::function<void(RendererOptions&, bool)>& choose, const char* what,
                               bool countRays = false,
                               const std::function<void(const ComputeRenderer&, bool)>& check = {}) {
    for (const WalkCase& c : cases) {
        const bool wide = c.precision == gpu::Precision::Fp64;
        SCOPED_TRACE(std::string(c.file) + (wide ? " fp64" : " fp32"));
        if (wide && !context().float64Supported()) continue;
        const Scene scene = parseSceneFile(c.file);
        const RenderRequest request = wholeImage(scene, 64);
        RendererOptions options{.precision = c.precision, .bvh = gpu::BvhMode::On, .traversal = gpu::Traversal::Walk};
        choose(options, false);
        ComputeRenderer rendererWithout(context(), scene, request.camera, options);
        if (check) check(rendererWithout, false);
        const GpuRenderResult without = rendererWithout.render(request, countRays);
        choose(options, true);
        ComputeRenderer rendererWith(context(), scene, request.camera, options);
        if (check) check(rendererWith, true);
        const GpuRenderResult with = rendererWith.render(request, countRays);
        ASSERT_EQ(with.image.rgb.size(), without.image.rgb.size());
        EXPECT_EQ(pixelsThatDiffer(without.image, with.image), 0u) << "pixels that differ between " << what;
        if (countRays) {
            EXPECT_GT(with.rays.shadow, 0u);
            EXPECT_EQ(with.rays.shadow, without.rays.shadow) << "shadow rays counted differently by " << what;
            EXPECT_EQ(with.rays.total(), without.rays.total()) << "rays counted differently by " << what;
        }
    }
}

}  // namespace snell::testing

// Where this device cannot take the path a test names (the test would compare
// a kernel with itself), the test is skipped saying why; under CI, where the
// GPU tests run on lavapipe and must test, it fails instead.
#define SNELL_CANNOT_TEST_HERE(reason)                                                  \
    do {                                                                                \
        if (snell::testing::underCi()) FAIL() << "cannot test here, under CI: " << (reason); \
        GTEST_SKIP() << (reason);                                                       \
    } while (0)
