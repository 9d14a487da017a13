// Scene-file parser: SPEC §1 (syntax), §2 (commands and state), §7 (errors).
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "scene/Scene.h"

namespace snell {

// Limits of the format as snell implements it (reported like any scene error).
struct ParseLimits {
    static constexpr int kMaxImageSize = 16384;
    static constexpr int kMaxSupersample = 64;
    static constexpr int kMaxGroupDepth = 4096;
    static constexpr std::size_t kMaxSpheres = 4'000'000;
    static constexpr std::size_t kMaxLights = 65'536;
};

// A scene error: what() is "FILE:LINE:COL: error: MESSAGE" (SPEC §7).
class ParseError : public std::runtime_error {
public:
    explicit ParseError(Diagnostic d)
        : std::runtime_error(d.format("error")), diagnostic_(std::move(d)) {}
    const Diagnostic& diagnostic() const { return diagnostic_; }

private:
    Diagnostic diagnostic_;
};

// Parse scene text; `fileName` is used in messages. Throws ParseError.
Scene parseScene(std::string_view text, const std::string& fileName);

// Read and parse a file. Throws ParseError, also when the file cannot be read
// (reported at 1:1 with the reason).
Scene parseSceneFile(const std::string& path);

}  // namespace snell
