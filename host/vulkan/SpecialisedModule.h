// A shader module with its specialisation constants folded in before the
// driver sees it. lavapipe translates and optimises the whole of a module's
// SPIR-V at every pipeline creation, inlining code that the constants disable
// before it finds that code dead; fixing the constants and removing that code
// first (SPIRV-Tools' optimizer) took 14–21 ms off lavapipe's 53–81 ms of
// pipeline creation (docs/log/targets.md, "Against the targets"). The folding costs
// about 40 ms itself, so it pays only when kept: it is done once per module
// and specialisation and read back from a cache directory after that.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

// `module` with specialisation constant i fixed to values[i] (its 32-bit
// pattern; a bool's is 0 or 1) and the code the constants disable removed:
// read from `cacheDirectory`, or made and written there. Empty where there
// is no cache directory or the folding failed: the driver then specialises
// the module as given. A cache that cannot be written costs only time.
std::vector<std::uint32_t> specialisedModule(std::span<const std::uint32_t> module,
                                             std::span<const std::uint32_t> values,
                                             const std::string& cacheDirectory);

}  // namespace snell::vk
