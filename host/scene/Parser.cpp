#include "scene/Parser.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include "scene/SceneReader.h"
#include "scene/SceneWords.h"
#include "scene/Transform.h"

namespace snell {
namespace {

using namespace scenewords;

std::string tooLarge() {
    return "larger than snell's limit of 2 GiB for a scene (" + std::to_string(ParseLimits::kMaxSceneBytes) + " bytes)";
}

ReadLimits readLimits() { return {ParseLimits::kMaxSceneBytes, ParseLimits::kMaxLineBytes}; }

const std::vector<std::string_view> kSizeWords{"sphere", "material", "refraction"};

class Parser {
public:
    explicit Parser(std::string fileName) : file_(std::move(fileName)) {
        std::filesystem::path p(file_);
        scene_.name = p.stem().string();
    }

    // Reserve for the spheres and materials the text names at most (counts of
    // kSizeWords), so a million-sphere file is not copied as the vectors grow.
    void reserve(const std::vector<std::size_t>& counts) {
        const std::size_t spheres = std::min(counts[0], ParseLimits::kMaxSpheres);
        scene_.spheres.reserve(spheres);
        materialIndex_.reserve(std::min(spheres, counts[1] + counts[2]) + 1);
    }

    ParseOutcome run(SceneReader& reader) {
        std::string_view line;
        int stoppedAtLine = 0;
        while (reader.next(line)) {
            parseLineRecovering(line, reader.lineNumber());
            if (errors_.full()) {
                stoppedAtLine = reader.lineNumber();
                break;
            }
        }
        errors_.endOfInput();
        if (stoppedAtLine == 0) checkEndOfInput(reader);
        // Of a file read to its end: a group may be closed further on.
        if (reader.end() == ReadEnd::EndOfInput) addWarnings();
        return {std::move(scene_), errors_.take(stoppedAtLine)};
    }

private:
    // An error abandons the rest of its line (one error per line, so the
    // errors come in SPEC §7 file order); the next line is parsed as usual.
    void parseLineRecovering(std::string_view line, int lineNumber) {
        line_ = lineNumber;
        try {
            parseLine(line);
        } catch (LineError& e) {
            errors_.add(std::move(e.diagnostic));
            recoverFrom(commandWord(line));
        }
    }

    // A failed line changes no state, except what keeps one mistake from
    // being reported again by a later line: a group or groupend still opens or
    // closes its level (else its partner would be unmatched), and a view still
    // counts (else "missing 'view'" would follow). A misspelt command counts as
    // the one its hint names.
    void recoverFrom(const Token& word) {
        const std::string_view command = findCommand(word.text) ? word.text : closestCommand(word.text);
        if (command == "group") {
            openGroup(word.column);
        } else if (command == "groupend") {
            closeGroup();
        } else if (command == "view") {
            viewTried_ = true;
            if (word.text == "view" && viewLine_ == 0) viewLine_ = line_;
        }
    }

    // How reading ended. SPEC §2, §7: a missing view is an error at 1:1,
    // found (and listed) last; where reading stopped short, the view may
    // have been further on. A NUL byte was its line's error.
    void checkEndOfInput(const SceneReader& reader) {
        const std::string readLines = "; stopped reading after line " + std::to_string(reader.lineNumber());
        switch (reader.end()) {
            case ReadEnd::EndOfInput:
                if (viewLine_ != 0 || viewTried_) return;
                errors_.add(at(1, 1, "missing 'view' command: a scene needs exactly one 'view n d'"));
                return;
            case ReadEnd::LineTooLong:
                errors_.add(at(reader.lineNumber(), int(ParseLimits::kMaxLineBytes) + 1,
                               "line longer than snell's limit of 16 MiB (" +
                                   std::to_string(ParseLimits::kMaxLineBytes) +
                                   " bytes): this is not a scene file; stopped reading here"));
                return;
            case ReadEnd::TooLarge:
                errors_.add(at(0, 0, tooLarge() + readLines));
                return;
            case ReadEnd::ReadFailed:
                errors_.add(at(0, 0, "cannot read the input to its end" + readLines));
                return;
            case ReadEnd::NotYet:
            case ReadEnd::NulByte:
                return;
        }
    }

    // Line 0: about the input as a whole, without a position.
    Diagnostic at(int line, int column, std::string message) const {
        Diagnostic d;
        d.location = {file_, line, column};
        d.message = std::move(message);
        return d;
    }

    // Each open group, the outermost first; past a few, one more for the rest.
    void addWarnings() {
        constexpr std::size_t kListed = 10;
        const std::vector<SourceLocation>& open = groupStack_locations_;
        for (std::size_t k = 0; k < open.size() && k < kListed; ++k)
            scene_.warnings.push_back({open[k], "'group' is never closed by a 'groupend'; add one where the group should "
                                                "end (its transform and material apply to the end of the file)"});
        if (open.size() > kListed)
            scene_.warnings.push_back({open[kListed], "this 'group' and the " + std::to_string(open.size() - kListed - 1) +
                                                          " opened after it are never closed either"});
    }

    [[noreturn]] void fail(int column, std::string message) const {
        throw LineError{Diagnostic{{file_, line_, column}, std::move(message)}};
    }
    [[noreturn]] void fail(const Token& t, std::string message) const { fail(t.column, std::move(message)); }

    void parseLine(std::string_view line) {
        checkBytes(line);
        // SPEC §1: '#' starts a comment wherever it stands.
        if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
            line = line.substr(0, hash);
        tokens_.clear();
        for (std::size_t i = 0; i < line.size();) {
            if (line[i] == ' ' || line[i] == '\t') { ++i; continue; }
            std::size_t j = i;
            while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
            tokens_.push_back({line.substr(i, j - i), static_cast<int>(i) + 1});
            i = j;
        }
        if (!tokens_.empty()) command();
    }

    // Bytes first: NUL, stray CR and invalid UTF-8 anywhere on the line
    // (comments included) are errors, reported at the offending byte. A NUL
    // ends the input (SceneReader) and is the error of its line.
    void checkBytes(std::string_view line) const {
        if (const std::size_t nul = line.find('\0'); nul != std::string_view::npos)
            fail(static_cast<int>(nul) + 1, "NUL byte: a scene file is text, and this is not; stopped reading here");
        for (std::size_t i = 0; i < line.size();) {
            const char c = line[i];
            const int column = static_cast<int>(i) + 1;
            if (c == '\r') fail(column, "carriage return not followed by a line feed");
            const std::size_t n = utf8SequenceLength(line, i);
            if (n == 0) fail(column, "invalid UTF-8 byte sequence");
            i += n;
        }
    }

    const CommandSpec& lookUp(const Token& name) const {
        if (const CommandSpec* c = findCommand(name.text)) return *c;
        std::string message = "unknown command " + quoted(name.text);
        if (const std::string_view best = closestCommand(name.text); !best.empty())
            message += "; did you mean '" + std::string(best) + "'?";
        else
            message += " (commands: view, sphere, scale, move, rotate, light, background, "
                       "ambient, group, groupend, material, refraction, supersample)";
        fail(name, message);
    }

    // SPEC §7 file order on a line: the command token's errors, then the
    // arguments left to right, then extra arguments. Each command checks all
    // of them before it takes effect, so a failed line changes nothing.
    void command() {
        const Token& name = tokens_[0];
        spec_ = &lookUp(name);
        if (static_cast<int>(tokens_.size()) - 1 < spec_->arity) tooFewArguments();
        checkCommandToken(name);
        perform();
    }

    [[noreturn]] void tooFewArguments() const {
        const int given = static_cast<int>(tokens_.size()) - 1;
        fail(tokens_[0], "'" + std::string(spec_->name) + "' expects " + std::to_string(spec_->arity) +
                             " argument" + (spec_->arity == 1 ? "" : "s") + " (" + std::string(spec_->usage) +
                             "), got " + std::to_string(given));
    }

    // The errors that stand at the command token itself.
    void checkCommandToken(const Token& name) {
        const Op op = spec_->op;
        if (op == Op::View && viewLine_ != 0)
            fail(name, "second 'view' command (the first is at line " + std::to_string(viewLine_) +
                           "); a scene has exactly one");
        if (op == Op::GroupEnd && groupStack_.empty()) fail(name, "'groupend' without a matching 'group'");
        // Once past the depth limit, deeper groups are the same mistake.
        if (op == Op::Group && groupStack_.size() >= static_cast<std::size_t>(ParseLimits::kMaxGroupDepth) &&
            levelsBeyondLimit_ == 0)
            fail(name, "groups nested deeper than snell's limit of " +
                           std::to_string(ParseLimits::kMaxGroupDepth) + " levels");
        if (op == Op::Sphere) checkSphereToken(name);
        if (op == Op::Light && scene_.lights.size() >= ParseLimits::kMaxLights && !lightLimitReported_) {
            lightLimitReported_ = true;  // the later lights are the same mistake
            fail(name, "too many lights: snell's limit is " + std::to_string(ParseLimits::kMaxLights));
        }
    }

    void checkSphereToken(const Token& name) {
        if (scene_.spheres.size() >= ParseLimits::kMaxSpheres && !sphereLimitReported_) {
            sphereLimitReported_ = true;  // the later spheres are the same mistake
            fail(name, "too many spheres: snell's limit is " + std::to_string(ParseLimits::kMaxSpheres));
        }
        if (!state_.transform.invertible())
            fail(name, "the current transform is degenerate (not invertible in double precision)");
    }

    void perform() {
        switch (spec_->op) {
            case Op::View: return view();
            case Op::Sphere: return sphere();
            case Op::Scale: return scale();
            case Op::Move: return move();
            case Op::Rotate: return rotate();
            case Op::Light: return light();
            case Op::Background: scene_.background = colourCommand("background"); return;
            case Op::Ambient: scene_.ambient = colourCommand("ambient"); return;
            case Op::Group: return group();
            case Op::GroupEnd: return groupEnd();
            case Op::Material: return material();
            case Op::Refraction: return refraction();
            case Op::Supersample: return supersample();
        }
    }

    // Called by each command after its arguments' own checks, before it takes effect.
    void endOfArguments() const {
        if (static_cast<int>(tokens_.size()) - 1 > spec_->arity) tooManyArguments();
    }

    [[noreturn]] void tooManyArguments() const {
        const int arity = spec_->arity;
        fail(tokens_[arity + 1], "too many arguments to '" + std::string(spec_->name) + "': expected " +
                                     std::to_string(arity) + " (" + std::string(spec_->usage) + ")");
    }

    // SPEC §1 number: decimal, optional sign and exponent; finite.
    double number(int index) {
        const Token& t = tokens_[index];
        const std::string_view s = t.text;
        std::size_t i = 0;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        if (i < s.size() && std::isalpha(static_cast<unsigned char>(s[i]))) {
            const std::string rest = lower(s.substr(i));
            if (rest == "nan" || rest == "inf" || rest == "infinity" || rest.rfind("nan(", 0) == 0)
                fail(t, quoted(s) + " is not allowed for " + argumentName(*spec_, index) + ": numbers must be finite");
        }
        if (i + 1 < s.size() && s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X'))
            fail(t, "hexadecimal number " + quoted(s) + " is not allowed for " + argumentName(*spec_, index) +
                        ": use decimal");
        std::size_t digits = 0;
        const std::size_t mantissaStart = i;
        while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) { ++i; ++digits; }
        if (i < s.size() && s[i] == '.') {
            ++i;
            while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) { ++i; ++digits; }
        }
        bool ok = digits > 0 && i > mantissaStart;
        if (ok && i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
            ++i;
            if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
            std::size_t expDigits = 0;
            while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) { ++i; ++expDigits; }
            ok = expDigits > 0;
        }
        if (!ok || i != s.size()) fail(t, "expected a number for " + argumentName(*spec_, index) + ", got " + quoted(s));
        // The syntax is checked: convert without allocating (from_chars takes no '+').
        const char* first = s.data() + (s[0] == '+' ? 1 : 0);
        double v = 0.0;
        const auto [end, error] = std::from_chars(first, s.data() + s.size(), v);
        if (error == std::errc::result_out_of_range) {
            // Overflow is an error (SPEC §1); underflow rounds towards zero.
            const std::string copy(s);
            v = std::strtod(copy.c_str(), nullptr);
        }
        if (!std::isfinite(v) || end != s.data() + s.size())
            fail(t, "number " + quoted(s) + " for " + argumentName(*spec_, index) + " overflows a double");
        return v;
    }

    // SPEC §1: n of view and s of supersample are plain integers.
    long long integer(int index, const char* what, long long minimum, long long maximum) {
        const Token& t = tokens_[index];
        std::string_view s = t.text;
        std::size_t i = 0;
        bool negative = false;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
        if (i == s.size()) fail(t, std::string(what) + " must be an integer, got " + quoted(s));
        long long value = 0;
        bool tooBig = false;
        for (; i < s.size(); ++i) {
            if (!std::isdigit(static_cast<unsigned char>(s[i])))
                fail(t, std::string(what) + " must be an integer, got " + quoted(s));
            if (value > 1'000'000'000'000LL) tooBig = true;
            else value = value * 10 + (s[i] - '0');
        }
        if (negative) value = -value;
        if (!tooBig && value < minimum)
            fail(t, std::string(what) + " must be at least " + std::to_string(minimum) + ", got " +
                        quoted(s));
        if (tooBig || value > maximum)
            fail(t, std::string(what) + " " + quoted(s) + " exceeds snell's limit of " +
                        std::to_string(maximum));
        return value;
    }

    double nonNegative(int index, const char* what) {
        const double v = number(index);
        if (v < 0.0) fail(tokens_[index], std::string(what) + " must be >= 0, got " + quoted(tokens_[index].text));
        return v;
    }

    dvec3 colour(int first, const char* what) {
        dvec3 c;
        for (int k = 0; k < 3; ++k) c[k] = nonNegative(first + k, what);
        return c;
    }

    dvec3 colourCommand(const char* what) {
        const dvec3 c = colour(1, what);
        endOfArguments();
        return c;
    }

    dvec3 vector(int first) {
        dvec3 v;
        for (int k = 0; k < 3; ++k) v[k] = number(first + k);
        return v;
    }

    void view() {
        const long long n = integer(1, "view: image size n", 1, ParseLimits::kMaxImageSize);
        const double d = number(2);
        if (!(d > 0.0)) fail(tokens_[2], "view: half-width d must be > 0, got " + quoted(tokens_[2].text));
        endOfArguments();
        viewLine_ = line_;
        scene_.imageSize = static_cast<int>(n);
        scene_.halfWidth = d;
    }

    void supersample() {
        const long long s = integer(1, "supersample: s", 1, ParseLimits::kMaxSupersample);
        endOfArguments();
        scene_.supersample = static_cast<int>(s);
    }

    void scale() {
        dvec3 s;
        for (int k = 0; k < 3; ++k) {
            s[k] = number(1 + k);
            if (s[k] == 0.0) fail(tokens_[1 + k], "scale factor must not be zero (the sphere would be degenerate)");
        }
        endOfArguments();
        state_.transform.scale(s);
    }

    void move() {
        const dvec3 v = vector(1);
        endOfArguments();
        state_.transform.translate(v);
    }

    void rotate() {
        const double degrees = number(1);
        const dvec3 axis = vector(2);
        if (axis == dvec3(0.0)) fail(tokens_[2], "rotation axis (0 0 0) has zero length");
        endOfArguments();
        state_.transform.rotate(degrees, axis);
    }

    void light() {
        Light l;
        l.colour = colour(1, "light colour");
        l.position = vector(4);
        endOfArguments();
        // Past the limit (reported once) the light is dropped.
        if (scene_.lights.size() < ParseLimits::kMaxLights) scene_.lights.push_back(l);
    }

    void material() {
        const dvec3 kd = colour(1, "material: diffuse kd");
        const dvec3 ks = colour(4, "material: specular ks");
        const double phong = nonNegative(7, "material: Phong exponent p");
        endOfArguments();
        state_.material.kd = kd;
        state_.material.ks = ks;
        state_.material.phong = phong;
    }

    void refraction() {
        const dvec3 kt = colour(1, "refraction: transmission kt");
        const double eta = number(4);
        if (!(eta > 0.0)) fail(tokens_[4], "refraction: index of refraction must be > 0, got " + quoted(tokens_[4].text));
        endOfArguments();
        state_.material.kt = kt;
        state_.material.eta = eta;
    }

    void group() {
        endOfArguments();
        openGroup(tokens_[0].column);
    }

    void groupEnd() {
        endOfArguments();
        closeGroup();
    }

    // Past the depth limit (reported once) a group only counts its level, and
    // closing the outermost such level restores the state at its group.
    void openGroup(int column) {
        if (groupStack_.size() < static_cast<std::size_t>(ParseLimits::kMaxGroupDepth)) {
            groupStack_.push_back(state_);
            groupStack_locations_.push_back({file_, line_, column});
        } else if (levelsBeyondLimit_++ == 0) {
            stateBeyondLimit_ = state_;
        }
    }

    // Does nothing without an open group: that is a failed groupend's recovery.
    void closeGroup() {
        if (levelsBeyondLimit_ > 0) {
            if (--levelsBeyondLimit_ == 0) state_ = stateBeyondLimit_;
        } else if (!groupStack_.empty()) {
            state_ = groupStack_.back();
            groupStack_.pop_back();
            groupStack_locations_.pop_back();
        }
    }

    void sphere() {
        endOfArguments();
        // Past the limit (reported once) the sphere is dropped.
        if (scene_.spheres.size() >= ParseLimits::kMaxSpheres) return;
        Sphere s;
        s.worldFromObject = state_.transform.worldFromObject();
        s.objectFromWorld = state_.transform.objectFromWorld();
        s.location = {line_, tokens_[0].column};
        s.material = internMaterial(state_.material);
        classifySphere(s);
        scene_.spheres.push_back(std::move(s));
    }

    std::uint32_t internMaterial(const Material& m) {
        // Most scenes reuse a handful of materials: deduplicate them.
        if (!scene_.materials.empty() && scene_.materials[lastMaterial_] == m) return lastMaterial_;
        const auto [it, inserted] = materialIndex_.try_emplace(m, static_cast<std::uint32_t>(scene_.materials.size()));
        if (inserted) scene_.materials.push_back(m);
        return lastMaterial_ = it->second;
    }

    SourceLocation here(const Token& t) const { return {file_, line_, t.column}; }

    struct State {
        Transform transform;
        Material material;
    };

    std::string file_;
    int line_ = 1;
    std::vector<Token> tokens_;
    const CommandSpec* spec_ = nullptr;  // the current line's command
    Scene scene_;
    State state_;
    std::vector<State> groupStack_;
    std::vector<SourceLocation> groupStack_locations_;
    int levelsBeyondLimit_ = 0;  // open groups past kMaxGroupDepth
    State stateBeyondLimit_;
    int viewLine_ = 0;        // the first line whose command is 'view', 0 if none
    bool viewTried_ = false;  // a failed line meant a 'view' (recoverFrom)
    bool sphereLimitReported_ = false;
    bool lightLimitReported_ = false;
    ErrorList errors_;
    std::uint32_t lastMaterial_ = 0;
    std::unordered_map<Material, std::uint32_t, MaterialHash> materialIndex_;
};

}  // namespace


ParseError::ParseError(Diagnostic d) : ParseError(std::vector<Diagnostic>{std::move(d)}, 0, 0) {}

ParseError::ParseError(std::vector<Diagnostic> listed, std::size_t notShown, int stoppedAtLine, std::size_t endOfInput)
    : std::runtime_error(errorReport({listed, notShown, stoppedAtLine, endOfInput, {}})),
      diagnostics_(std::move(listed)),
      notShown_(notShown),
      stoppedAtLine_(stoppedAtLine),
      endOfInput_(endOfInput) {}

ParseError::ParseError(const ParseError& errors, std::vector<Diagnostic> warnings)
    : std::runtime_error(errorReport(
          {errors.diagnostics_, errors.notShown_, errors.stoppedAtLine_, errors.endOfInput_, warnings})),
      diagnostics_(errors.diagnostics_),
      notShown_(errors.notShown_),
      stoppedAtLine_(errors.stoppedAtLine_),
      endOfInput_(errors.endOfInput_),
      warnings_(std::move(warnings)) {}

ParseError ParseError::withWarnings(std::vector<Diagnostic> warnings) const {
    return ParseError(*this, std::move(warnings));
}

ParseOutcome parseSceneRecovering(std::string_view text, const std::string& fileName) {
    SceneReader reader(text, readLimits());
    Parser parser(fileName);
    parser.reserve(countOccurrences(text.substr(0, ParseLimits::kMaxSceneBytes), kSizeWords));
    return parser.run(reader);
}

ParseOutcome parseSceneStreamRecovering(std::istream& in, const std::string& fileName) {
    SceneReader reader(in, readLimits());
    return Parser(fileName).run(reader);
}

Scene parseScene(std::string_view text, const std::string& fileName) {
    ParseOutcome outcome = parseSceneRecovering(text, fileName);
    if (outcome.error) throw std::move(*outcome.error);
    return std::move(outcome.scene);
}

ParseOutcome parseSceneFileRecovering(const std::string& path) {
    // A file that cannot be read has no position to report: "FILE: error: ...".
    auto fileError = [&path](const std::string& message) {
        Diagnostic d;
        d.location = {path, 0, 0};
        d.message = message;
        Scene named;
        named.name = std::filesystem::path(path).stem().string();
        return ParseOutcome{std::move(named), ParseError(std::move(d))};
    };
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) return fileError("is a directory, not a scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in) return fileError(std::string("cannot open scene file: ") + std::strerror(errno));
    // A regular file's size is known before reading it.
    Parser parser(path);
    if (std::filesystem::is_regular_file(path, ec)) {
        // Its size is known before reading it, and it can be read twice.
        if (const auto size = std::filesystem::file_size(path, ec); !ec && size > ParseLimits::kMaxSceneBytes)
            return fileError("the file's " + std::to_string(size) + " bytes are " + tooLarge());
        parser.reserve(countOccurrences(in, kSizeWords));
        in.clear();
        in.seekg(0);
    }
    SceneReader reader(in, readLimits());
    return parser.run(reader);
}

Scene parseSceneFile(const std::string& path) {
    ParseOutcome outcome = parseSceneFileRecovering(path);
    if (outcome.error) throw std::move(*outcome.error);
    return std::move(outcome.scene);
}

}  // namespace snell
