// libFuzzer target: any bytes as a scene file. The parser must either return
// a scene or throw ParseError — never crash, hang or trip a sanitizer.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene/Parser.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const snell::Scene scene = snell::parseScene(
            std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.scn");
        (void)scene;
    } catch (const snell::ParseError&) {
    }
    return 0;
}
