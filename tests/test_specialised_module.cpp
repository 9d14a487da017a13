// The kernels' specialisation folded in ahead of the driver
// (vulkan/SpecialisedModule.h): made once, kept, read back, never from a file
// made for anything else, and at most so many kept. (That a folded kernel
// traces the same image is a GPU test: GpuSpecialisation.)
#include <gtest/gtest.h>
#include <stdlib.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <span>

#include "shared_layout.h"
#include "store_kernel_comp_spv.h"
#include "trace_comp_spv.h"
#include "temporary_directory.h"
#include "vulkan/SpecialisedModule.h"

namespace fs = std::filesystem;
using Words = std::vector<std::uint32_t>;

namespace {

constexpr std::uint32_t kSpirvMagic = 0x07230203;

using snell::testing::TemporaryDirectory;

std::size_t modulesKept(const std::string& directory) {
    std::error_code none;
    std::size_t n = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(fs::path(directory) / "modules", none))
        n += e.path().extension() == ".spv";
    return n;
}

// One sphere, lights, nothing else: the values a scene like scenes/basic.scn
// specialises the trace kernel with.
std::array<std::uint32_t, SNELL_SPEC_COUNT> oneSphere() {
    std::array<std::uint32_t, SNELL_SPEC_COUNT> v{};
    v[SNELL_SPEC_HAS_LIGHTS] = 1;
    v[SNELL_SPEC_SHADOWS] = 1;
    v[SNELL_SPEC_MAX_MEDIA] = 1;
    v[SNELL_SPEC_RAY_STACK] = 1;
    v[SNELL_SPEC_SPHERE_COUNT] = 1;
    v[SNELL_SPEC_BVH_DEPTH] = 1;
    v[SNELL_SPEC_SPHERES_IN_BLOCK] = 1;
    return v;
}

}  // namespace

TEST(SpecialisedModule, FoldedOnceThenReadBack) {
    TemporaryDirectory cache;
    ASSERT_FALSE(cache.path().empty());
    const std::span<const std::uint32_t> trace(snell_trace_comp_spv);
    auto values = oneSphere();
    const Words folded = snell::vk::specialisedModule(trace, values, cache.path());
    ASSERT_FALSE(folded.empty());
    EXPECT_EQ(folded[0], kSpirvMagic);
    // What the constants disable is gone: the module is smaller.
    EXPECT_LT(folded.size(), trace.size() * 9 / 10);
    EXPECT_EQ(modulesKept(cache.path()), 1u);
    EXPECT_EQ(snell::vk::specialisedModule(trace, values, cache.path()), folded);
    EXPECT_EQ(modulesKept(cache.path()), 1u) << "the kept module was not read back";

    // Another specialisation is another module.
    values[SNELL_SPEC_HAS_REFLECTION] = 1;
    const Words reflecting = snell::vk::specialisedModule(trace, values, cache.path());
    ASSERT_FALSE(reflecting.empty());
    EXPECT_NE(reflecting, folded);
    EXPECT_EQ(modulesKept(cache.path()), 2u);
}

TEST(SpecialisedModule, NoCacheDirectoryLeavesItToTheDriver) {
    EXPECT_TRUE(snell::vk::specialisedModule(std::span<const std::uint32_t>(snell_trace_comp_spv), oneSphere(), "")
                    .empty());
}

TEST(SpecialisedModule, DamagedFileIsMadeAgain) {
    TemporaryDirectory cache;
    const std::span<const std::uint32_t> trace(snell_trace_comp_spv);
    const Words folded = snell::vk::specialisedModule(trace, oneSphere(), cache.path());
    ASSERT_FALSE(folded.empty());
    const fs::path file = fs::directory_iterator(fs::path(cache.path()) / "modules")->path();
    fs::resize_file(file, fs::file_size(file) / 8 * 4);  // cut short, as by a full disk
    EXPECT_EQ(snell::vk::specialisedModule(trace, oneSphere(), cache.path()), folded);
    {
        // The right size, another module's words: its header says so.
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(8);
        const std::uint32_t other = 12345;
        f.write(reinterpret_cast<const char*>(&other), sizeof other);
    }
    EXPECT_EQ(snell::vk::specialisedModule(trace, oneSphere(), cache.path()), folded);
}

TEST(SpecialisedModule, KeepsAtMost256) {
    TemporaryDirectory cache;
    const std::span<const std::uint32_t> store(snell_store_kernel_comp_spv);
    std::array<std::uint32_t, 1> value{};
    for (std::uint32_t k = 0; k < 300; ++k) {
        value[0] = k;
        ASSERT_FALSE(snell::vk::specialisedModule(store, value, cache.path()).empty()) << k;
    }
    EXPECT_EQ(modulesKept(cache.path()), 256u);
}
