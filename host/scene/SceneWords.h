// The words of a scene file (SPEC §1): tokens, the commands and their
// spellings, the bytes a line may hold, and the errors found in the order
// found. The parser (Parser.cpp) reads lines with these.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/Parser.h"

namespace snell::scenewords {

struct Token {
    std::string_view text;
    int column = 1;
};

enum class Op { View, Sphere, Scale, Move, Rotate, Light, Background, Ambient, Group, GroupEnd,
                Material, Refraction, Supersample };

struct CommandSpec {
    std::string_view name;
    Op op;
    int arity;
    std::string_view usage;
};

// Thrown to abandon the rest of a line at its first error.
struct LineError {
    Diagnostic diagnostic;
};

// A scene's errors in the order found: the first kMaxReportedErrors kept,
// every one counted.
class ErrorList {
public:
    void add(Diagnostic d) {
        if (listed_.size() < ParseLimits::kMaxReportedErrors) listed_.push_back(std::move(d));
        ++count_;
    }
    bool empty() const { return count_ == 0; }
    bool full() const { return count_ >= ParseLimits::kMaxCountedErrors; }
    // The lines are read: errors added from now on are about the input as a whole.
    void endOfInput() { endOfInput_ = listed_.size(); }
    std::optional<ParseError> take(int stoppedAtLine) {
        if (count_ == 0) return std::nullopt;
        const std::size_t notShown = count_ - listed_.size();
        return ParseError(std::move(listed_), notShown, stoppedAtLine, endOfInput_);
    }

private:
    std::vector<Diagnostic> listed_;
    std::size_t count_ = 0;
    std::size_t endOfInput_ = SIZE_MAX;
};

// The command of that name, or null.
const CommandSpec* findCommand(std::string_view name);
// The command a misspelt name most likely means (case aside, at most two
// edits away), or empty.
std::string_view closestCommand(std::string_view name);
std::string lower(std::string_view s);
// A token printed in a message: long or binary tokens are shortened/escaped.
std::string quoted(std::string_view s);
// Length of the valid UTF-8 sequence at s[i], or 0 if invalid.
std::size_t utf8SequenceLength(std::string_view s, std::size_t i);
// The first word of a raw line (up to a space, tab or '#'), bad bytes and all:
// what a line that failed was meant to do.
Token commandWord(std::string_view line);
// What a ParseError reports.
struct ErrorReport {
    const std::vector<Diagnostic>& listed;
    std::size_t notShown;
    int stoppedAtLine;
    std::size_t endOfInput;                 // listed[endOfInput...] were found after the lines
    const std::vector<Diagnostic>& warnings;  // in line order, those without a line last
};
// The errors as printed: each listed one, among the warnings by line, then
// how many more errors were not shown.
std::string errorReport(const ErrorReport& report);
// An argument of `spec` as messages name it, counted from 1:
// "'y' (argument 2 of 'move x y z')".
std::string argumentName(const CommandSpec& spec, int index);

}  // namespace snell::scenewords
