// Files a run keeps in snell's cache directory for the runs after it (kernels
// with their specialisation folded in, drivers' kernel binaries). Each starts
// with words saying what it was made from, checked on reading (a hash in its
// name alone could collide), then the length in bytes of what follows. Files
// are written under a temporary name and renamed, so a concurrent run never
// reads half of one, and beyond a count the oldest of their kind go. Keeping
// is best effort: a cache that cannot be written costs only time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

// FNV-1a, 64-bit, over 32-bit words (their bytes, least significant first).
class WordHash {
public:
    void add(std::uint32_t word);
    void add(std::span<const std::uint32_t> words);
    std::uint64_t value() const { return hash_; }

private:
    std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

// The file for `key` in `directory`: sixteen hexadecimal digits, then `extension` (".spv").
std::filesystem::path keptPath(const std::filesystem::path& directory, std::uint64_t key, const char* extension);

// What follows `header` in the file at `path`; empty where there is no such
// file, it starts otherwise, or it was cut short.
std::vector<char> readKept(const std::filesystem::path& path, std::span<const std::uint32_t> header);

// Writes `header` and `payload` to `path` (creating its directory), then
// removes the oldest files of its extension in that directory beyond `maxKept`.
void keep(const std::filesystem::path& path, std::span<const std::uint32_t> header, std::span<const char> payload,
          std::size_t maxKept);

}  // namespace snell::vk
