#include "scene/SceneWords.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>

#include "common/EditDistance.h"

namespace snell::scenewords {

namespace {

constexpr std::array<CommandSpec, 13> kCommands{{
    {"view", Op::View, 2, "view n d"},
    {"sphere", Op::Sphere, 0, "sphere"},
    {"scale", Op::Scale, 3, "scale sx sy sz"},
    {"move", Op::Move, 3, "move x y z"},
    {"rotate", Op::Rotate, 4, "rotate angle x y z"},
    {"light", Op::Light, 6, "light r g b x y z"},
    {"background", Op::Background, 3, "background r g b"},
    {"ambient", Op::Ambient, 3, "ambient r g b"},
    {"group", Op::Group, 0, "group"},
    {"groupend", Op::GroupEnd, 0, "groupend"},
    {"material", Op::Material, 7, "material dr dg db sr sg sb p"},
    {"refraction", Op::Refraction, 4, "refraction r g b i"},
    {"supersample", Op::Supersample, 1, "supersample s"},
}};

}  // namespace

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

const CommandSpec* findCommand(std::string_view name) {
    for (const CommandSpec& c : kCommands)
        if (c.name == name) return &c;
    return nullptr;
}

std::string_view closestCommand(std::string_view name) {
    const std::string lowered = lower(name);
    std::string_view best;
    std::size_t bestDistance = 3;
    for (const CommandSpec& c : kCommands) {
        // The length difference bounds the distance: a long token costs no
        // quadratic work.
        const std::size_t lengthGap = std::max(lowered.size(), c.name.size()) -
                                      std::min(lowered.size(), c.name.size());
        if (lengthGap >= bestDistance) continue;
        const auto d = static_cast<std::size_t>(editDistance(lowered, c.name));
        if (d < bestDistance) { bestDistance = d; best = c.name; }
    }
    return best;
}

std::string quoted(std::string_view s) {
    std::string out = "'";
    const std::size_t limit = 40;
    for (std::size_t i = 0; i < s.size() && i < limit; ++i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        if (c < 0x20 || c >= 0x7f) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", c);
            out += buf;
        } else {
            out += static_cast<char>(c);
        }
    }
    if (s.size() > limit) out += "...";
    return out + "'";
}

std::size_t utf8SequenceLength(std::string_view s, std::size_t i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    std::size_t n;
    unsigned int cp;
    if (c < 0x80) return 1;
    if ((c & 0xe0) == 0xc0) { n = 2; cp = c & 0x1f; }
    else if ((c & 0xf0) == 0xe0) { n = 3; cp = c & 0x0f; }
    else if ((c & 0xf8) == 0xf0) { n = 4; cp = c & 0x07; }
    else return 0;
    if (i + n > s.size()) return 0;
    for (std::size_t k = 1; k < n; ++k) {
        const unsigned char cc = static_cast<unsigned char>(s[i + k]);
        if ((cc & 0xc0) != 0x80) return 0;
        cp = (cp << 6) | (cc & 0x3f);
    }
    // Overlong forms, surrogates and values past U+10FFFF are invalid.
    if ((n == 2 && cp < 0x80) || (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) ||
        (cp >= 0xd800 && cp <= 0xdfff) || cp > 0x10ffff)
        return 0;
    return n;
}

Token commandWord(std::string_view line) {
    std::size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '#') ++j;
    return {line.substr(i, j - i), static_cast<int>(i) + 1};
}

namespace {

// Does `warning` come before `error`? By line and column; without a line
// (about the whole input) after every line.
bool comesBefore(const Diagnostic& warning, const Diagnostic& error) {
    const SourceLocation& w = warning.location;
    const SourceLocation& e = error.location;
    if (w.line <= 0) return false;
    if (e.line <= 0) return true;
    return w.line != e.line ? w.line < e.line : w.column < e.column;
}

}  // namespace

std::string errorReport(const ErrorReport& r) {
    std::string out;
    auto add = [&out](const Diagnostic& d, const char* severity) {
        if (!out.empty()) out += '\n';
        out += d.format(severity);
    };
    std::size_t w = 0;
    auto warningsBefore = [&](const Diagnostic& error) {
        for (; w < r.warnings.size() && comesBefore(r.warnings[w], error); ++w) add(r.warnings[w], "warning");
    };
    Diagnostic afterTheLines;  // the errors found once the lines were read come after them
    afterTheLines.location.line = 0;
    for (std::size_t k = 0; k < r.listed.size(); ++k) {
        warningsBefore(k < r.endOfInput ? r.listed[k] : afterTheLines);
        add(r.listed[k], "error");
    }
    for (; w < r.warnings.size(); ++w) add(r.warnings[w], "warning");
    if (r.notShown == 0) return out;
    out += '\n' + r.listed.front().location.file + ": error: " + (r.stoppedAtLine > 0 ? "at least " : "") +
           std::to_string(r.notShown) + " more error" + (r.notShown == 1 ? "" : "s") + " not shown";
    if (r.stoppedAtLine > 0)
        out += " (stopped reading at line " + std::to_string(r.stoppedAtLine) + " after " +
               std::to_string(ParseLimits::kMaxCountedErrors) + " errors)";
    return out;
}

std::string argumentName(const CommandSpec& spec, int index) {
    // The usage names the arguments: "move x y z".
    std::string_view rest = spec.usage;
    for (int k = 0; k <= index && !rest.empty(); ++k) {
        const std::size_t space = rest.find(' ');
        if (k == index)
            return "'" + std::string(rest.substr(0, space)) + "' (argument " + std::to_string(index) + " of '" +
                   std::string(spec.usage) + "')";
        rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
    }
    return "argument " + std::to_string(index) + " of '" + std::string(spec.usage) + "'";
}

}  // namespace snell::scenewords
