#include "vulkan/KeptFile.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace snell::vk {

namespace fs = std::filesystem;

void WordHash::add(std::uint32_t word) {
    for (int i = 0; i < 4; ++i) {
        hash_ ^= (word >> (8 * i)) & 0xffu;
        hash_ *= 0x100000001b3ull;
    }
}

void WordHash::add(std::span<const std::uint32_t> words) {
    for (std::uint32_t w : words) add(w);
}

fs::path keptPath(const fs::path& directory, std::uint64_t key, const char* extension) {
    char name[40];
    std::snprintf(name, sizeof name, "%016llx%s", static_cast<unsigned long long>(key), extension);
    return directory / name;
}

std::vector<char> readKept(const fs::path& path, std::span<const std::uint32_t> header) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {};
    const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::size_t start = (header.size() + 1) * sizeof(std::uint32_t);  // after the payload's length
    if (bytes.size() <= start) return {};
    std::vector<std::uint32_t> words(header.size() + 1);
    std::memcpy(words.data(), bytes.data(), start);
    if (!std::equal(header.begin(), header.end(), words.begin()) || words.back() != bytes.size() - start)
        return {};  // made from something else, or cut short
    return {bytes.begin() + std::ptrdiff_t(start), bytes.end()};
}

void keep(const fs::path& path, std::span<const std::uint32_t> header, std::span<const char> payload,
          std::size_t maxKept) {
    std::error_code ignored;
    const fs::path directory = path.parent_path();
    fs::create_directories(directory, ignored);
    const fs::path temporary = path.string() + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(temporary, std::ios::binary);
        const std::uint32_t length = std::uint32_t(payload.size());
        out.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size_bytes()));
        out.write(reinterpret_cast<const char*>(&length), sizeof length);
        out.write(payload.data(), std::streamsize(payload.size()));
        if (!out) {
            fs::remove(temporary, ignored);
            return;
        }
    }
    fs::rename(temporary, path, ignored);
    if (ignored) fs::remove(temporary, ignored);

    std::vector<std::pair<fs::file_time_type, fs::path>> kept;
    for (const fs::directory_entry& e : fs::directory_iterator(directory, ignored))
        if (e.path().extension() == path.extension()) kept.emplace_back(e.last_write_time(ignored), e.path());
    if (kept.size() <= maxKept) return;
    std::sort(kept.begin(), kept.end());
    for (std::size_t i = 0; i + maxKept < kept.size(); ++i) fs::remove(kept[i].second, ignored);
}

}  // namespace snell::vk
