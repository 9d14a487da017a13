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
#include <sstream>
#include <unordered_map>
#include <vector>

#include "scene/Transform.h"

namespace snell {
namespace {

struct Token {
    std::string_view text;
    int column = 1;
};

struct CommandSpec {
    std::string_view name;
    int arity;
    std::string_view usage;
};

constexpr std::array<CommandSpec, 13> kCommands{{
    {"view", 2, "view n d"},
    {"sphere", 0, "sphere"},
    {"scale", 3, "scale sx sy sz"},
    {"move", 3, "move x y z"},
    {"rotate", 4, "rotate angle x y z"},
    {"light", 6, "light r g b x y z"},
    {"background", 3, "background r g b"},
    {"ambient", 3, "ambient r g b"},
    {"group", 0, "group"},
    {"groupend", 0, "groupend"},
    {"material", 7, "material dr dg db sr sg sb p"},
    {"refraction", 4, "refraction r g b i"},
    {"supersample", 1, "supersample s"},
}};

int editDistance(std::string_view a, std::string_view b) {
    std::vector<int> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
    for (std::size_t i = 1; i <= a.size(); ++i) {
        int diagonal = row[0];
        row[0] = static_cast<int>(i);
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const int above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = above;
        }
    }
    return row[b.size()];
}

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

// A token printed in a message: long or binary tokens are shortened/escaped.
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

// Length of the valid UTF-8 sequence at s[i], or 0 if invalid.
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

class Parser {
public:
    Parser(std::string_view text, std::string fileName) : text_(text), file_(std::move(fileName)) {
        std::filesystem::path p(file_);
        scene_.name = p.stem().string();
    }

    Scene run() {
        // Reserve for the spheres and materials the text can name at most, so
        // a million-sphere file is not copied as the vectors grow.
        auto occurrences = [this](std::string_view word) {
            std::size_t count = 0;
            for (std::size_t at = text_.find(word); at != std::string_view::npos; at = text_.find(word, at + 1))
                ++count;
            return count;
        };
        const std::size_t sphereCount = std::min(occurrences("sphere"), ParseLimits::kMaxSpheres);
        scene_.spheres.reserve(sphereCount);
        materialIndex_.reserve(std::min(sphereCount, occurrences("material") + occurrences("refraction")) + 1);
        std::size_t pos = 0;
        int lineNumber = 1;
        while (pos < text_.size()) {
            std::size_t end = pos;
            while (end < text_.size() && text_[end] != '\n') ++end;
            std::string_view line = text_.substr(pos, end - pos);
            // CRLF; a CR not followed by LF (even at the end of the file) is an error.
            if (end < text_.size() && !line.empty() && line.back() == '\r') line.remove_suffix(1);
            parseLine(line, lineNumber);
            pos = end + 1;
            ++lineNumber;
        }
        if (!viewLocation_) fail(1, 1, "missing 'view' command: a scene needs exactly one 'view n d'");
        for (const SourceLocation& open : groupStack_locations_)
            scene_.warnings.push_back({open, "'group' is never closed by a 'groupend'"});
        for (std::size_t m = 0; m < scene_.materials.size(); ++m) {
            if (scene_.materials[m].amplifies()) {
                scene_.warnings.push_back(
                    {amplifyingLocation_[m],
                     "material has ks + kt > 1 in some channel: its ray tree can gain weight "
                     "with depth (SPEC §4); float output in diverging channels is a partial sum"});
            }
        }
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(int line, int column, std::string message) const {
        throw ParseError(Diagnostic{{file_, line, column}, std::move(message)});
    }
    [[noreturn]] void fail(const Token& t, std::string message) const {
        fail(line_, t.column, std::move(message));
    }

    void parseLine(std::string_view line, int lineNumber) {
        line_ = lineNumber;
        // Bytes first: NUL, stray CR and invalid UTF-8 anywhere on the line
        // (comments included) are errors, reported at the offending byte.
        for (std::size_t i = 0; i < line.size();) {
            const char c = line[i];
            if (c == '\0') fail(lineNumber, static_cast<int>(i) + 1, "NUL byte in scene file");
            if (c == '\r')
                fail(lineNumber, static_cast<int>(i) + 1,
                     "carriage return not followed by a line feed");
            const std::size_t n = utf8SequenceLength(line, i);
            if (n == 0) fail(lineNumber, static_cast<int>(i) + 1, "invalid UTF-8 byte sequence");
            i += n;
        }
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

    const CommandSpec& lookUp(const Token& name) const {
        for (const CommandSpec& c : kCommands)
            if (c.name == name.text) return c;
        std::string message = "unknown command " + quoted(name.text);
        const std::string lowered = lower(name.text);
        std::string_view best;
        int bestDistance = 3;
        for (const CommandSpec& c : kCommands) {
            const int d = lowered == c.name ? 0 : editDistance(lowered, c.name);
            if (d < bestDistance) { bestDistance = d; best = c.name; }
        }
        if (!best.empty()) message += "; did you mean '" + std::string(best) + "'?";
        else message += " (commands: view, sphere, scale, move, rotate, light, background, "
                        "ambient, group, groupend, material, refraction, supersample)";
        fail(name, message);
    }

    void command() {
        const Token& name = tokens_[0];
        const CommandSpec& spec = lookUp(name);
        const int given = static_cast<int>(tokens_.size()) - 1;
        if (given < spec.arity)
            fail(name, "'" + std::string(spec.name) + "' expects " + std::to_string(spec.arity) +
                           " argument" + (spec.arity == 1 ? "" : "s") + " (" +
                           std::string(spec.usage) + "), got " + std::to_string(given));
        // Errors that belong to the command token come first, then the
        // arguments left to right, then extra arguments (SPEC §7 file order).
        const std::string_view n = spec.name;
        if (n == "view" && viewLocation_)
            fail(name, "second 'view' command (the first is at line " + std::to_string(viewLocation_->line) +
                           "); a scene has exactly one");
        if (n == "groupend" && groupStack_.empty()) fail(name, "'groupend' without a matching 'group'");
        if (n == "group" && groupStack_.size() >= static_cast<std::size_t>(ParseLimits::kMaxGroupDepth))
            fail(name, "groups nested deeper than snell's limit of " +
                           std::to_string(ParseLimits::kMaxGroupDepth) + " levels");
        if (n == "sphere" && scene_.spheres.size() >= ParseLimits::kMaxSpheres)
            fail(name, "too many spheres: snell's limit is " + std::to_string(ParseLimits::kMaxSpheres));
        if (n == "sphere" && !state_.transform.invertible())
            fail(name, "the current transform is degenerate (not invertible in double precision)");
        if (n == "light" && scene_.lights.size() >= ParseLimits::kMaxLights)
            fail(name, "too many lights: snell's limit is " + std::to_string(ParseLimits::kMaxLights));
        if (n == "view") view();
        else if (n == "sphere") sphere();
        else if (n == "scale") scale();
        else if (n == "move") move();
        else if (n == "rotate") rotate();
        else if (n == "light") light();
        else if (n == "background") scene_.background = colour(1, "background");
        else if (n == "ambient") scene_.ambient = colour(1, "ambient");
        else if (n == "group") group();
        else if (n == "groupend") groupEnd();
        else if (n == "material") material();
        else if (n == "refraction") refraction();
        else if (n == "supersample") supersample();
        if (given > spec.arity)
            fail(tokens_[spec.arity + 1], "too many arguments to '" + std::string(spec.name) +
                                              "': expected " + std::to_string(spec.arity) +
                                              " (" + std::string(spec.usage) + ")");
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
                fail(t, quoted(s) + " is not allowed: numbers must be finite");
        }
        if (i + 1 < s.size() && s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X'))
            fail(t, "hexadecimal number " + quoted(s) + " is not allowed: use decimal");
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
        if (!ok || i != s.size()) fail(t, "expected a number, got " + quoted(s));
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
            fail(t, "number " + quoted(s) + " overflows a double");
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

    void view() {
        const long long n = integer(1, "view: image size n", 1, ParseLimits::kMaxImageSize);
        const double d = number(2);
        if (!(d > 0.0)) fail(tokens_[2], "view: half-width d must be > 0, got " + quoted(tokens_[2].text));
        viewLocation_ = here(tokens_[0]);
        scene_.imageSize = static_cast<int>(n);
        scene_.halfWidth = d;
    }

    void supersample() {
        scene_.supersample = static_cast<int>(
            integer(1, "supersample: s", 1, ParseLimits::kMaxSupersample));
    }

    void scale() {
        dvec3 s;
        for (int k = 0; k < 3; ++k) {
            s[k] = number(1 + k);
            if (s[k] == 0.0) fail(tokens_[1 + k], "scale factor must not be zero (the sphere would be degenerate)");
        }
        state_.transform.scale(s);
    }

    void move() {
        dvec3 v;
        for (int k = 0; k < 3; ++k) v[k] = number(1 + k);
        state_.transform.translate(v);
    }

    void rotate() {
        const double degrees = number(1);
        dvec3 axis;
        for (int k = 0; k < 3; ++k) axis[k] = number(2 + k);
        if (axis == dvec3(0.0)) fail(tokens_[2], "rotation axis (0 0 0) has zero length");
        state_.transform.rotate(degrees, axis);
    }

    void light() {
        Light l;
        l.colour = colour(1, "light colour");
        for (int k = 0; k < 3; ++k) l.position[k] = number(4 + k);
        scene_.lights.push_back(l);
    }

    void material() {
        state_.material.kd = colour(1, "material: diffuse kd");
        state_.material.ks = colour(4, "material: specular ks");
        state_.material.phong = nonNegative(7, "material: Phong exponent p");
    }

    void refraction() {
        state_.material.kt = colour(1, "refraction: transmission kt");
        const double eta = number(4);
        if (!(eta > 0.0)) fail(tokens_[4], "refraction: index of refraction must be > 0, got " + quoted(tokens_[4].text));
        state_.material.eta = eta;
    }

    void group() {
        groupStack_.push_back(state_);
        groupStack_locations_.push_back(here(tokens_[0]));
    }

    void groupEnd() {
        state_ = groupStack_.back();
        groupStack_.pop_back();
        groupStack_locations_.pop_back();
    }

    void sphere() {
        Sphere s;
        s.worldFromObject = state_.transform.worldFromObject();
        s.objectFromWorld = state_.transform.objectFromWorld();
        s.location = {line_, tokens_[0].column};
        s.material = internMaterial(state_.material, here(tokens_[0]));
        classifySphere(s);
        scene_.spheres.push_back(std::move(s));
    }

    std::uint32_t internMaterial(const Material& m, const SourceLocation& where) {
        // Most scenes reuse a handful of materials: deduplicate them.
        if (!scene_.materials.empty() && scene_.materials[lastMaterial_] == m) return lastMaterial_;
        const auto [it, inserted] = materialIndex_.try_emplace(m, static_cast<std::uint32_t>(scene_.materials.size()));
        if (inserted) {
            scene_.materials.push_back(m);
            amplifyingLocation_.push_back(where);
        }
        return lastMaterial_ = it->second;
    }

    SourceLocation here(const Token& t) const { return {file_, line_, t.column}; }

    struct State {
        Transform transform;
        Material material;
    };

    std::string_view text_;
    std::string file_;
    int line_ = 1;
    std::vector<Token> tokens_;
    Scene scene_;
    State state_;
    std::vector<State> groupStack_;
    std::vector<SourceLocation> groupStack_locations_;
    std::optional<SourceLocation> viewLocation_;
    std::vector<SourceLocation> amplifyingLocation_;
    std::uint32_t lastMaterial_ = 0;
    std::unordered_map<Material, std::uint32_t, MaterialHash> materialIndex_;
};

}  // namespace

Scene parseScene(std::string_view text, const std::string& fileName) {
    return Parser(text, fileName).run();
}

Scene parseSceneFile(const std::string& path) {
    // File-level failures are reported at 1:1 of the file (SPEC §7 format).
    auto fileError = [&path](const std::string& message) {
        Diagnostic d;
        d.location.file = path;
        d.message = message;
        return ParseError(std::move(d));
    };
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw fileError("is a directory, not a scene file");
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw fileError(std::string("cannot open scene file: ") + std::strerror(errno));
    std::string text;
    const std::streamoff size = in.tellg();
    if (size > 0) {
        text.resize(static_cast<std::size_t>(size));
        in.seekg(0);
        in.read(text.data(), size);
    } else {
        // Not a regular file (a pipe, say): read until the end.
        in.clear();
        in.seekg(0);
        std::ostringstream buffer;
        buffer << in.rdbuf();
        text = buffer.str();
    }
    if (in.bad()) throw fileError("cannot read scene file");
    return parseScene(text, path);
}

}  // namespace snell
