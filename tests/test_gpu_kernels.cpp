// The kernel's forms and the BVH walk's variants trace the image of their
// twins, bit for bit: the specialisation folded in before the driver sees it
// or left to the driver, a shader object or its kept binary or a pipeline,
// the BVH read as texels or through its address, the walk's stack in
// registers or in an array.
#include <cctype>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "gpu/ComputeRenderer.h"
#include "gpu_test_support.h"
#include "image/ImageIO.h"
#include "scene/Parser.h"
#include "vulkan/VulkanContext.h"

namespace fs = std::filesystem;

namespace {

using snell::testing::context;
using snell::testing::pixelsThatDiffer;
using snell::testing::requireTheSameWalk;
using snell::testing::wholeImage;

// A scene file and a precision: a case for the kernel's forms below, named
// by the file's stem (and _fp64).
struct KernelCase {
    const char* file;
    snell::gpu::Precision precision = snell::gpu::Precision::Fp32;
};

std::string caseName(const testing::TestParamInfo<KernelCase>& info) {
    std::string n = fs::path(info.param.file).stem().string();
    for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return n + (info.param.precision == snell::gpu::Precision::Fp64 ? "_fp64" : "");
}

// The kernel with its specialisation folded in before the driver sees it
// (vulkan/SpecialisedModule.h) traces the image the driver's own
// specialisation traces, bit for bit: scenes of each kind of kernel (one
// sphere; refraction and amplifying glass; a BVH; traps; a BVH of amplifying
// glass), at the defaults.
class GpuSpecialisation : public testing::TestWithParam<KernelCase> {};

TEST_P(GpuSpecialisation, FoldedKernelTracesTheSameImage) {
    ASSERT_FALSE(context().cacheDirectory().empty());
    const fs::path modules = fs::path(context().cacheDirectory()) / "modules";
    const snell::Scene scene = snell::parseSceneFile(GetParam().file);
    const snell::RenderRequest request = wholeImage(scene, 48);
    snell::ComputeRenderer driverSpecialised(context(), scene, request.camera, {.foldSpecialisation = false});
    const snell::GpuRenderResult own = driverSpecialised.render(request, false);
    snell::ComputeRenderer folded(context(), scene, request.camera);
    const snell::GpuRenderResult image = folded.render(request, false);
    EXPECT_FALSE(driverSpecialised.kernelFolded());
    EXPECT_TRUE(folded.kernelFolded());
    EXPECT_FALSE(fs::is_empty(modules)) << "no folded module kept";
    ASSERT_EQ(image.image.rgb.size(), own.image.rgb.size());
    EXPECT_EQ(pixelsThatDiffer(own.image, image.image), 0u)
        << "pixels that differ between the driver's specialisation and the folded one";
}

INSTANTIATE_TEST_SUITE_P(Scenes, GpuSpecialisation,
                         testing::Values(KernelCase{SNELL_SOURCE_DIR "/scenes/basic.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/glass.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/grid.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/hard/glass-in-water-gap-0.scn"},
                                         KernelCase{SNELL_SHARED_DIR "/course-scenes/becker-SphereFlake2.scn"}),
                         caseName);

// Where the device has shader objects, a kernel is one whose driver binary is
// kept (vulkan/ShaderObject.h): made from SPIR-V the first time, from the
// binary after that, tracing the pipeline's image bit for bit both times.
// The validation layer of Debian 12 cannot check shader objects, so this
// context runs without it, whatever SNELL_VALIDATION says.
class GpuShaderObjects : public testing::TestWithParam<KernelCase> {};

TEST_P(GpuShaderObjects, KeptBinaryTracesThePipelinesImage) {
    const KernelCase& c = GetParam();
    snell::testing::TemporaryDirectory cache;
    ASSERT_FALSE(cache.path().empty());
    snell::vk::ContextOptions options;
    options.pipelineCachePath = cache.path() + "/pipelines.bin";
    snell::vk::Context objects(options);
    const snell::vk::ShaderObjects& support = objects.shaderObjects();
    if (!support.enabled) {
        EXPECT_NE(support.absence.find("the device lacks"), std::string::npos) << support.absence;
    }
    if (c.precision == snell::gpu::Precision::Fp64 && !objects.float64Supported())
        SNELL_CANNOT_TEST_HERE("this device has no shader doubles");
    const fs::path shaders = fs::path(cache.path()) / "shaders";
    const snell::Scene scene = snell::parseSceneFile(c.file);
    const snell::RenderRequest request = wholeImage(scene, 48);
    snell::ComputeRenderer pipeline(objects, scene, request.camera,
                                    {.precision = c.precision, .useShaderObjects = false});
    const snell::GpuRenderResult own = pipeline.render(request, false);
    EXPECT_STREQ(pipeline.kernelObject(), "pipeline");
    for (const char* expected : {"shader object", "shader binary"}) {
        snell::ComputeRenderer renderer(objects, scene, request.camera, {.precision = c.precision});
        const snell::GpuRenderResult image = renderer.render(request, false);
        EXPECT_STREQ(renderer.kernelObject(), support.enabled ? expected : "pipeline");
        ASSERT_EQ(image.image.rgb.size(), own.image.rgb.size());
        EXPECT_EQ(pixelsThatDiffer(own.image, image.image), 0u)
            << "pixels that differ between the pipeline and the " << renderer.kernelObject();
    }
    if (support.enabled) {
        EXPECT_FALSE(fs::is_empty(shaders)) << "no binary kept";
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, GpuShaderObjects,
                         testing::Values(KernelCase{SNELL_SOURCE_DIR "/scenes/basic.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/glass.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/grid.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/hard/glass-in-water-gap-0.scn"},
                                         KernelCase{SNELL_SOURCE_DIR "/scenes/glass.scn", snell::gpu::Precision::Fp64}),
                         caseName);

// The BVH walk reads the nodes as texels or through their device address,
// whichever the driver reads faster (shared_layout.h): both trace the same
// image, bit for bit, on every driver.
TEST(GpuBvhWords, AddressReadsTraceTheTexelsImage) {
    requireTheSameWalk({{SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp32},
                        {SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp64},
                        {SNELL_SHARED_DIR "/course-scenes/becker-SphereFlake2.scn", snell::gpu::Precision::Fp32}},
                       [](snell::RendererOptions& options, bool words) { options.readBvhWords = words; },
                       "the BVH's two views");
}


// The walk's stack lives in registers where it is short enough, else in an
// array (trace.comp, pushEntry): both trace the same image, bit for bit.
// SphereFlake4's stack (30 entries) is near the limit of 32.
TEST(GpuBvhStack, RegistersTraceTheArraysImage) {
    requireTheSameWalk({{SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp32},
                        {SNELL_SOURCE_DIR "/scenes/grid.scn", snell::gpu::Precision::Fp64},
                        {SNELL_SHARED_DIR "/course-scenes/becker-SphereFlake2.scn", snell::gpu::Precision::Fp32},
                        {SNELL_SHARED_DIR "/course-scenes/becker-SphereFlake4.scn", snell::gpu::Precision::Fp32}},
                       [](snell::RendererOptions& options, bool registers) { options.stackInRegisters = registers; },
                       "the two stacks", false, [](const snell::ComputeRenderer& renderer, bool registers) {
                           EXPECT_EQ(renderer.stackInRegisters(), registers);
                       });
}

}  // namespace
