// Scene-file parser: SPEC §1 (syntax), §2 (commands and state), §7 (errors).
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
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
    // Input is read as a stream, in bounded memory, and stops at these (an
    // endless pipe, /dev/zero): 2 GiB, four times the 0.52 GB of a scene of
    // kMaxSpheres as bench/make_scaling_scene.py writes it, and so that line
    // numbers fit an int; a line of 16 MiB, a million times a real one's.
    static constexpr std::uint64_t kMaxSceneBytes = 2'147'483'647;
    static constexpr std::size_t kMaxLineBytes = std::size_t{16} << 20;
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
    // `notShown` is a lower bound; otherwise it is 0. The listed errors from
    // index `endOfInput` on were found once the lines were read (a missing
    // 'view', say).
    ParseError(std::vector<Diagnostic> listed, std::size_t notShown, int stoppedAtLine,
               std::size_t endOfInput = SIZE_MAX);

    // The same errors reported with warnings (in line order, those about the
    // whole file last): what() interleaves them by line, as a compiler does,
    // each warning as "FILE:LINE:COL: warning: MESSAGE".
    ParseError withWarnings(std::vector<Diagnostic> warnings) const;

    // The first error: the one SPEC §7 names.
    const Diagnostic& diagnostic() const { return diagnostics_.front(); }
    // Every listed error, first to last (at most kMaxReportedErrors).
    const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
    // Errors found but not listed; "at least" that many when notShownIsLowerBound().
    std::size_t notShown() const { return notShown_; }
    bool notShownIsLowerBound() const { return stoppedAtLine_ > 0; }
    // The warnings of withWarnings (none otherwise).
    const std::vector<Diagnostic>& warnings() const { return warnings_; }

private:
    ParseError(const ParseError& errors, std::vector<Diagnostic> warnings);

    std::vector<Diagnostic> diagnostics_;
    std::size_t notShown_ = 0;
    int stoppedAtLine_ = 0;
    std::size_t endOfInput_ = SIZE_MAX;
    std::vector<Diagnostic> warnings_;
};

// Parse scene text; `fileName` is used in messages. Throws ParseError with
// every error of the text.
Scene parseScene(std::string_view text, const std::string& fileName);

// The same parse without the throw: the scene as far as its good lines build
// it (a failed line has no effect) and the errors, if any. A scene with errors
// is for inspection (tests, tools, the warnings about its lines), never for
// rendering.
struct ParseOutcome {
    Scene scene;
    std::optional<ParseError> error;
};
ParseOutcome parseSceneRecovering(std::string_view text, const std::string& fileName);

// Read and parse a stream (standard input, a pipe) as it arrives, in bounded
// memory: reading stops at the first NUL byte, at a line longer than
// kMaxLineBytes and past kMaxSceneBytes, each an error.
ParseOutcome parseSceneStreamRecovering(std::istream& in, const std::string& fileName);

// Read and parse a file, as a stream. A file that cannot be read, or is
// larger than kMaxSceneBytes, is an error of the whole file ("FILE: error: ...").
ParseOutcome parseSceneFileRecovering(const std::string& path);
// The same, throwing ParseError.
Scene parseSceneFile(const std::string& path);

}  // namespace snell
