#include "image/PngText.h"

#include <cstdint>

namespace snell {

ImageText pngText(const std::string& bytes) {
    constexpr std::size_t kSignature = 8;
    auto word = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (std::size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<unsigned char>(bytes[at + i]);
        return v;
    };
    ImageText text;
    // Each chunk: its length, its type, its data, a CRC.
    for (std::size_t at = kSignature; at + 12 <= bytes.size();) {
        const std::size_t length = word(at);
        if (length > bytes.size() - at - 12) break;
        const std::string type = bytes.substr(at + 4, 4);
        if (type == "IEND") break;
        if (type == "tEXt") {
            const std::string data = bytes.substr(at + 8, length);
            const auto zero = data.find('\0');  // keyword, NUL, text
            if (zero != std::string::npos) text.push_back({data.substr(0, zero), data.substr(zero + 1)});
        }
        at += 12 + length;
    }
    return text;
}

}  // namespace snell
