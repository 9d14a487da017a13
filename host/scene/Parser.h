// Scene-file parser: SPEC §1 (syntax), §2 (commands and state), §7 (errors).
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scene/Scene.h"

namespace snell {

// Limits of the format as snell implements it (reported like any scene error).
struct ParseLimits {
    static constexpr int kMaxImageSize = 16384;
    static constexpr int kMaxSupersample = 64;
    static constexpr int kMaxGroupDepth = 4096;
    static constexpr std::size_t kMaxSpheres = 4'000'000;
    static constexpr std::size_t kMaxLights = 65'536;
    // Errors listed in a report; past that they are only counted, and past
    // kMaxCountedErrors the parser stops reading (garbage input stays cheap).
    static constexpr std::size_t kMaxReportedErrors = 20;
    static constexpr std::size_t kMaxCountedErrors = 10'000;
};

// A scene's errors, in the order found (SPEC §7 file order: lines top to
// bottom, tokens left to right; end-of-file checks such as a missing 'view'
// come last). what() is one "FILE:LINE:COL: error: MESSAGE" line per listed
// error, then, when some were left out, "FILE: error: N more errors not shown";
// lines joined by '\n', no final newline.
class ParseError : public std::runtime_error {
public:
    // A single error (a file that cannot be read, say).
    explicit ParseError(Diagnostic d);
    // `listed` is not empty; `notShown` more errors were found. When reading
    // stopped early (kMaxCountedErrors), `stoppedAtLine` is that line and
    // `notShown` is a lower bound; otherwise it is 0.
    ParseError(std::vector<Diagnostic> listed, std::size_t notShown, int stoppedAtLine);

    // The first error: the one SPEC §7 names.
    const Diagnostic& diagnostic() const { return diagnostics_.front(); }
    // Every listed error, first to last (at most kMaxReportedErrors).
    const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
    // Errors found but not listed; "at least" that many when notShownIsLowerBound().
    std::size_t notShown() const { return notShown_; }
    bool notShownIsLowerBound() const { return stoppedAtLine_ > 0; }

private:
    std::vector<Diagnostic> diagnostics_;
    std::size_t notShown_ = 0;
    int stoppedAtLine_ = 0;
};

// Parse scene text; `fileName` is used in messages. Throws ParseError with
// every error of the text.
Scene parseScene(std::string_view text, const std::string& fileName);

// The same parse without the throw: the scene as far as its good lines build
// it (a failed line has no effect) and the errors, if any. A scene with errors
// is for inspection (tests, tools), never for rendering; its warnings are empty.
struct ParseOutcome {
    Scene scene;
    std::optional<ParseError> error;
};
ParseOutcome parseSceneRecovering(std::string_view text, const std::string& fileName);

// Read and parse a file. Throws ParseError, also when the file cannot be read
// (reported at 1:1 with the reason).
Scene parseSceneFile(const std::string& path);

}  // namespace snell
