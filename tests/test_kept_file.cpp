// Files kept in the cache directory (vulkan/KeptFile.h): read back only under
// the header they were written with and whole, and at most so many of a kind.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>
#include <vector>

#include "temporary_directory.h"
#include "vulkan/KeptFile.h"

namespace fs = std::filesystem;

namespace {

using snell::testing::TemporaryDirectory;


std::size_t filesWith(const fs::path& directory, const std::string& extension) {
    std::size_t n = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(directory)) n += e.path().extension() == extension;
    return n;
}

}  // namespace

TEST(KeptFile, ReadBackOnlyUnderItsHeaderAndWhole) {
    TemporaryDirectory dir;
    ASSERT_FALSE(dir.path().empty());
    const std::vector<std::uint32_t> header{1, 2, 3};
    const std::string payload = "a driver's binary";
    const fs::path path = snell::vk::keptPath(fs::path(dir.path()) / "kind", 0xabcdefu, ".bin");
    EXPECT_EQ(path.filename(), "0000000000abcdef.bin");
    snell::vk::keep(path, header, std::span<const char>(payload.data(), payload.size()), 4);
    const std::vector<char> back = snell::vk::readKept(path, header);
    EXPECT_EQ(std::string(back.begin(), back.end()), payload);
    EXPECT_TRUE(snell::vk::readKept(path, std::vector<std::uint32_t>{1, 2, 4}).empty()) << "made for another input";
    EXPECT_TRUE(snell::vk::readKept(path, std::vector<std::uint32_t>{1, 2}).empty()) << "a shorter header";
    fs::resize_file(path, fs::file_size(path) - 1);
    EXPECT_TRUE(snell::vk::readKept(path, header).empty()) << "cut short";
    EXPECT_TRUE(snell::vk::readKept(fs::path(dir.path()) / "none.bin", header).empty());
}

TEST(KeptFile, KeepsAtMostSoManyOfItsKind) {
    TemporaryDirectory dir;
    ASSERT_FALSE(dir.path().empty());
    const std::vector<std::uint32_t> header{7};
    const std::string payload = "x";
    snell::vk::keep(snell::vk::keptPath(dir.path(), 1000, ".spv"), header, payload, 2);
    for (std::uint64_t key = 0; key < 5; ++key)
        snell::vk::keep(snell::vk::keptPath(dir.path(), key, ".bin"), header, payload, 3);
    EXPECT_EQ(filesWith(dir.path(), ".bin"), 3u);
    EXPECT_EQ(filesWith(dir.path(), ".spv"), 1u) << "another kind was counted";
    EXPECT_EQ(filesWith(dir.path(), ".bin") + filesWith(dir.path(), ".spv"),
              std::size_t(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator())))
        << "a temporary file was left";
}
