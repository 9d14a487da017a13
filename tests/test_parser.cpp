// Scene-file parser: SPEC §1 (syntax), §2 (commands, defaults); the real
// files of the course. Its errors (SPEC §7): test_parser_errors.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <istream>
#include <map>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

#include "parser_test_support.h"
#include "scene/SceneReader.h"

namespace {

// ---------------------------------------------------------------- commands

TEST(Parser, MinimalSceneHasSpecDefaults) {
    const Scene s = parse("view 64 2.5\nsphere\n");
    EXPECT_EQ(s.imageSize, 64);
    EXPECT_DOUBLE_EQ(s.halfWidth, 2.5);
    EXPECT_EQ(s.supersample, 1);
    EXPECT_EQ(s.background, dvec3(0.0));
    EXPECT_EQ(s.ambient, dvec3(0.0));
    EXPECT_TRUE(s.lights.empty());
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_EQ(s.name, "t");
    ASSERT_EQ(s.spheres.size(), 1u);
    ASSERT_EQ(s.materials.size(), 1u);
    const snell::Material& m = s.materials[s.spheres[0].material];
    EXPECT_EQ(m.kd, dvec3(1.0));
    EXPECT_EQ(m.ks, dvec3(0.0));
    EXPECT_EQ(m.phong, 1.0);
    EXPECT_EQ(m.kt, dvec3(0.0));
    EXPECT_EQ(m.eta, 1.0002926);
    EXPECT_EQ(s.spheres[0].worldFromObject, glm::dmat4(1.0));
    EXPECT_TRUE(s.spheres[0].isTrueSphere);
    EXPECT_EQ(s.spheres[0].centre, dvec3(0.0));
    EXPECT_EQ(s.spheres[0].radius, 1.0);
    EXPECT_EQ(s.spheres[0].location.line, 2);
    EXPECT_EQ(s.spheres[0].location.column, 1);
}

TEST(Parser, ViewAnywhereInFile) {
    const Scene s = parse("sphere\nview 3 0.25\n");
    EXPECT_EQ(s.imageSize, 3);
    EXPECT_EQ(s.halfWidth, 0.25);
    EXPECT_EQ(s.spheres.size(), 1u);
}

TEST(Parser, ScaleMoveRotateBuildTheTransform) {
    const Scene s = parse(kView + "scale 2 3 4\nsphere\n" + "move 1 2 3\nsphere\n" +
                          "rotate 90 0 0 1\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 3u);
    // First: S(2,3,4).
    expectNear(apply(s.spheres[0].worldFromObject, {1, 1, 1}), {2, 3, 4});
    EXPECT_FALSE(s.spheres[0].isTrueSphere);
    // Second: S * T(1,2,3): the origin goes to S(1,2,3) = (2,6,12).
    expectNear(apply(s.spheres[1].worldFromObject, {0, 0, 0}), {2, 6, 12});
    // Third: S * T * R: x axis rotates to y, then T, then S: (1,0,0) -> (0,1,0) -> (1,3,3) -> (2,9,12).
    expectNear(apply(s.spheres[2].worldFromObject, {1, 0, 0}), {2, 9, 12});
}

TEST(Parser, LightIsNotTransformed) {
    const Scene s = parse(kView + "move 5 6 7\nscale 2 2 2\nlight 0.1 0.2 0.3 1 2 3\nlight 4 5 6 -1 -2 -3\n");
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].colour, dvec3(0.1, 0.2, 0.3));
    EXPECT_EQ(s.lights[0].position, dvec3(1, 2, 3));
    EXPECT_EQ(s.lights[1].colour, dvec3(4, 5, 6));  // above 1 is allowed
    EXPECT_EQ(s.lights[1].position, dvec3(-1, -2, -3));
}

TEST(Parser, BackgroundAmbientSupersampleLastOneWins) {
    const Scene s = parse(kView + "background 0.1 0.2 0.3\nambient 1 2 3\nsupersample 4\n" +
                          "background 0.4 0.5 0.6\nambient 0.7 0.8 0.9\nsupersample 2\n");
    EXPECT_EQ(s.background, dvec3(0.4, 0.5, 0.6));
    EXPECT_EQ(s.ambient, dvec3(0.7, 0.8, 0.9));
    EXPECT_EQ(s.supersample, 2);
}

TEST(Parser, MaterialAndRefraction) {
    const Scene s = parse(kView + "material 0.1 0.2 0.3 0.4 0.5 0.6 20\nrefraction 0.7 0.8 0.9 1.5\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 1u);
    const snell::Material& m = s.materials[s.spheres[0].material];
    EXPECT_EQ(m.kd, dvec3(0.1, 0.2, 0.3));
    EXPECT_EQ(m.ks, dvec3(0.4, 0.5, 0.6));
    EXPECT_EQ(m.phong, 20.0);
    EXPECT_EQ(m.kt, dvec3(0.7, 0.8, 0.9));
    EXPECT_EQ(m.eta, 1.5);
}

TEST(Parser, MaterialKeepsRefractionAndViceVersa) {
    const Scene s = parse(kView + "refraction 1 1 1 1.33\nmaterial 0.5 0.5 0.5 0 0 0 3\nsphere\n" +
                          "refraction 0 0 0 2\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    const snell::Material& a = s.materials[s.spheres[0].material];
    const snell::Material& b = s.materials[s.spheres[1].material];
    EXPECT_EQ(a.kd, dvec3(0.5));
    EXPECT_EQ(a.kt, dvec3(1.0));
    EXPECT_EQ(a.eta, 1.33);
    EXPECT_EQ(b.kd, dvec3(0.5));  // material unchanged by refraction
    EXPECT_EQ(b.phong, 3.0);
    EXPECT_EQ(b.kt, dvec3(0.0));
    EXPECT_EQ(b.eta, 2.0);
}

TEST(Parser, ZeroPhongExponentAllowed) {
    const Scene s = parse(kView + "material 1 1 1 1 1 1 0\nsphere\n");
    EXPECT_EQ(s.materials[s.spheres[0].material].phong, 0.0);
}

TEST(Parser, GroupRestoresTransformMaterialAndRefraction) {
    const Scene s = parse(kView + "move 1 0 0\ngroup\nmove 0 5 0\nscale 2 2 2\n" +
                          "material 0.1 0.1 0.1 0.2 0.2 0.2 7\nrefraction 0.5 0.5 0.5 1.5\nsphere\ngroupend\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(1, 5, 0));
    EXPECT_EQ(s.spheres[0].radius, 2.0);
    EXPECT_EQ(s.materials[s.spheres[0].material].eta, 1.5);
    EXPECT_EQ(s.spheres[1].centre, dvec3(1, 0, 0));
    EXPECT_EQ(s.spheres[1].radius, 1.0);
    EXPECT_EQ(s.materials[s.spheres[1].material], snell::Material{});
    EXPECT_TRUE(s.warnings.empty());
}

TEST(Parser, NestedGroups) {
    const Scene s = parse(kView + "group\nmove 1 0 0\ngroup\nmove 1 0 0\nsphere\ngroupend\nsphere\n" +
                          "groupend\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 3u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(2, 0, 0));
    EXPECT_EQ(s.spheres[1].centre, dvec3(1, 0, 0));
    EXPECT_EQ(s.spheres[2].centre, dvec3(0, 0, 0));
}

TEST(Parser, At256NestedGroupsSupported) {
    std::string text = kView;
    for (int i = 0; i < 256; ++i) text += "group\nmove 1 0 0\n";
    text += "sphere\n";
    for (int i = 0; i < 256; ++i) text += "groupend\n";
    text += "sphere\n";
    const Scene s = parse(text);
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(256, 0, 0));
    EXPECT_EQ(s.spheres[1].centre, dvec3(0, 0, 0));
    EXPECT_TRUE(s.warnings.empty());
}

TEST(Parser, UnclosedGroupIsAWarningNotAnError) {
    const Scene s = parse(kView + "sphere\ngroup\nsphere\n");
    EXPECT_EQ(s.spheres.size(), 2u);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_EQ(s.warnings[0].location.line, 3);
    EXPECT_EQ(s.warnings[0].location.column, 1);
    EXPECT_NE(s.warnings[0].message.find("group"), std::string::npos);
}

TEST(Parser, ManyUnclosedGroupsAreCounted) {
    // The outermost ten, then one warning for the rest, at the first of them.
    std::string text = kView;
    for (int i = 0; i < 4000; ++i) text += "group\n";
    const Scene s = parse(text);
    ASSERT_EQ(s.warnings.size(), 11u);
    EXPECT_EQ(s.warnings[9].location.line, 11);
    EXPECT_EQ(s.warnings[10].location.line, 12);
    EXPECT_NE(s.warnings[10].message.find("the 3989 opened after it are never closed"), std::string::npos)
        << s.warnings[10].message;
}

TEST(Parser, NumberForms) {
    // SPEC §1: 1, -0.5, +.5, 5., 2e-3, 2E-3.
    const Scene s = parse(kView + "light 1 0 0.5 -0.5 +.5 5.\nlight 2e-3 2E-3 1e+2 -1E2 0 +0\n");
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].colour, dvec3(1, 0, 0.5));
    EXPECT_EQ(s.lights[0].position, dvec3(-0.5, 0.5, 5.0));
    EXPECT_EQ(s.lights[1].colour, dvec3(0.002, 0.002, 100));
    EXPECT_EQ(s.lights[1].position, dvec3(-100, 0, 0));
}

// ---------------------------------------------------------------- syntax

TEST(Parser, Comments) {
    const Scene s = parse("# a comment first on the line\nview 10 1 # after the arguments\n"
                          "#sphere\n   # indented comment\nmove 1 2 0.5#x\nsphere#glued\n"
                          "material 1 1 1 0 0 0 2# glued to last\nsphere # sphere\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(1, 2, 0.5));
    EXPECT_EQ(s.materials[s.spheres[1].material].phong, 2.0);
}

TEST(Parser, CommentedOutCommandIsNotRun) {
    // A '#' ahead of a bad command hides it entirely.
    const Scene s = parse(kView + "#eyep 0 0 0\n#scale 0 0 0\nsphere\n");
    EXPECT_EQ(s.spheres.size(), 1u);
}

TEST(Parser, CrLfAndNoFinalNewline) {
    const Scene s = parse("view 10 1\r\nmove 1 0 0\r\n\r\nsphere\r\nsphere");
    EXPECT_EQ(s.imageSize, 10);
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(1, 0, 0));
    EXPECT_EQ(s.spheres[1].location.line, 5);
    // Line numbers count CRLF lines once each.
    expectError("view 10 1\r\n\r\nbogus\r\n", 3, 1, {"unknown command"});
    // A last line without a line end that has an error is still located.
    expectError("view 10 1\nmove 1 2 z", 2, 10);
}

TEST(Parser, TabsAndSpacesSeparateTokens) {
    const Scene s = parse("view\t10\t1\n\tmove \t1\t 2  3\t\nsphere\t\n   \n\t\n");
    ASSERT_EQ(s.spheres.size(), 1u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(1, 2, 3));
    // A tab is one column (SPEC §7).
    expectError(kView + "\tmove\t1\tx\t3\n", 2, 9, {"'x'"});
}

TEST(Parser, TrailingSpacesAllowed) {
    const Scene s = parse("view 10 1   \nmove 1 0 0 \nsphere  \n");
    EXPECT_EQ(s.spheres.size(), 1u);
}

TEST(Parser, ValidUtf8InCommentAccepted) {
    const Scene s = parse(kView + "# caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80\nsphere\n");
    EXPECT_EQ(s.spheres.size(), 1u);
}

// ---------------------------------------------------------------- input

using snell::ReadEnd;
using snell::SceneReader;

std::vector<std::string> linesOf(SceneReader& reader) {
    std::vector<std::string> lines;
    for (std::string_view line; reader.next(line);) lines.emplace_back(line);
    return lines;
}

// An endless stream of one byte, as /dev/zero or an endless pipe.
class Endless : public std::streambuf {
public:
    explicit Endless(char c) : block_(4096, c) {}

private:
    int_type underflow() override {
        setg(block_.data(), block_.data(), block_.data() + block_.size());
        return traits_type::to_int_type(block_[0]);
    }
    std::string block_;
};

constexpr snell::ReadLimits kSmall{1'000'000, 100};

TEST(SceneReader, StreamAndTextGiveTheSameLines) {
    // Lines across the stream's chunks (64 KiB), CR LF, a last line without LF.
    std::string text;
    for (int i = 0; i < 20000; ++i) text += "line " + std::to_string(i) + (i % 3 ? "\n" : "\r\n");
    text += "last";
    SceneReader fromText(text, kSmall);
    std::istringstream in(text);
    SceneReader fromStream(in, kSmall);
    const std::vector<std::string> lines = linesOf(fromText);
    ASSERT_EQ(lines.size(), 20001u);
    EXPECT_EQ(lines[0], "line 0");
    EXPECT_EQ(lines[19999], "line 19999");
    EXPECT_EQ(lines[20000], "last");
    EXPECT_EQ(linesOf(fromStream), lines);
    EXPECT_EQ(fromText.end(), ReadEnd::EndOfInput);
    EXPECT_EQ(fromStream.end(), ReadEnd::EndOfInput);
}

TEST(SceneReader, StopsAtTheFirstNulByte) {
    // /dev/zero: its first byte is the last read.
    Endless zeros('\0');
    std::istream in(&zeros);
    SceneReader endless(in, kSmall);
    EXPECT_EQ(linesOf(endless), std::vector<std::string>{std::string(1, '\0')});
    EXPECT_EQ(endless.end(), ReadEnd::NulByte);
    EXPECT_EQ(endless.lineNumber(), 1);
    // The line holding it ends at it; no line after it is read.
    const std::string withNul = "ab\ncd\0ef\ngh\n"s;
    SceneReader text(withNul, kSmall);
    EXPECT_EQ(linesOf(text), (std::vector<std::string>{"ab", "cd\0"s}));
    EXPECT_EQ(text.end(), ReadEnd::NulByte);
    EXPECT_EQ(text.lineNumber(), 2);
}

TEST(SceneReader, StopsAtALineLongerThanTheLimit) {
    Endless xs('x');
    std::istream in(&xs);
    SceneReader endless(in, kSmall);
    EXPECT_TRUE(linesOf(endless).empty());
    EXPECT_EQ(endless.end(), ReadEnd::LineTooLong);
    EXPECT_EQ(endless.lineNumber(), 1);
    // 100 bytes are a line, 101 are not (its CR counts).
    const std::string text = "ab\n" + std::string(100, 'x') + "\n" + std::string(100, 'y') + "\r\nok\n";
    SceneReader reader(text, kSmall);
    EXPECT_EQ(linesOf(reader), (std::vector<std::string>{"ab", std::string(100, 'x')}));
    EXPECT_EQ(reader.end(), ReadEnd::LineTooLong);
    EXPECT_EQ(reader.lineNumber(), 3);
}

TEST(SceneReader, StopsPastTheSizeLimit) {
    const std::string text = "aa\nbb\ncc\n";
    for (const std::uint64_t limit : {6u, 7u, 8u, 9u, 100u}) {
        SCOPED_TRACE(limit);
        const std::vector<std::string> want =
            limit < 9 ? std::vector<std::string>{"aa", "bb"} : std::vector<std::string>{"aa", "bb", "cc"};
        const ReadEnd end = limit < 9 ? ReadEnd::TooLarge : ReadEnd::EndOfInput;
        SceneReader fromText(text, {limit, 100});
        EXPECT_EQ(linesOf(fromText), want);
        EXPECT_EQ(fromText.end(), end);
        std::istringstream in(text);
        SceneReader fromStream(in, {limit, 100});
        EXPECT_EQ(linesOf(fromStream), want);
        EXPECT_EQ(fromStream.end(), end);
    }
    // An endless pipe of lines ends at the limit.
    Endless newlines('\n');
    std::istream in(&newlines);
    SceneReader endless(in, {100'000, 100});
    EXPECT_EQ(linesOf(endless).size(), 100'000u);
    EXPECT_EQ(endless.end(), ReadEnd::TooLarge);
}

TEST(SceneReader, SkipsAByteOrderMarkAtTheStart) {
    SceneReader text("\xef\xbb\xbfview\n\xef\xbb\xbfx\n", kSmall);
    EXPECT_EQ(linesOf(text), (std::vector<std::string>{"view", "\xef\xbb\xbfx"}));
    std::istringstream in("\xef\xbb\xbf");
    SceneReader onlyTheMark(in, kSmall);
    EXPECT_TRUE(linesOf(onlyTheMark).empty());
}

TEST(SceneReader, CountsWordsThatChunksCut) {
    // "sphere" across the first 64 KiB boundary of the stream.
    const std::string text = std::string(65533, '#') + "sphere\nsphere spheresphere\nmaterial";
    const std::vector<std::string_view> words{"sphere", "material", "none"};
    const std::vector<std::size_t> want{4, 1, 0};
    EXPECT_EQ(snell::countOccurrences(text, words), want);
    std::istringstream in(text);
    EXPECT_EQ(snell::countOccurrences(in, words), want);
    // A stream's count ends at a NUL byte, as reading does.
    std::istringstream withNul("sphere\0sphere"s);
    EXPECT_EQ(snell::countOccurrences(withNul, words), (std::vector<std::size_t>{1, 0, 0}));
}

TEST(ParserInput, ByteOrderMarkAccepted) {
    const Scene s = parse("\xef\xbb\xbfview 10 1\nsphere\n");
    EXPECT_EQ(s.spheres.size(), 1u);
    // Columns count from after it, as an editor shows them.
    expectError("\xef\xbb\xbfview 10 x\n", 1, 9, {"'x'"});
    // Elsewhere it is no mark but bytes of a word.
    expectError(kView + "\xef\xbb\xbfsphere\n", 2, 1, {"unknown command"});
}

TEST(ParserInput, StreamParsesAsText) {
    std::string text = kView;
    for (int i = 0; i < 5000; ++i) text += "group\nmove " + std::to_string(i) + " 0 -5\nsphere\ngroupend\n";
    text += "move 1 x 2\nbogus\n";
    std::istringstream in(text);
    const snell::ParseOutcome streamed = snell::parseSceneStreamRecovering(in, "t.scn");
    const snell::ParseOutcome whole = snell::parseSceneRecovering(text, "t.scn");
    ASSERT_TRUE(streamed.error && whole.error);
    EXPECT_STREQ(streamed.error->what(), whole.error->what());
    EXPECT_EQ(streamed.scene.spheres.size(), 5000u);
    EXPECT_EQ(whole.scene.spheres.size(), 5000u);
}

TEST(ParserInput, LineLongerThanTheLimitStopsReading) {
    const std::size_t limit = snell::ParseLimits::kMaxLineBytes;
    // Spaces: the line would parse, but no scene has such a line.
    const std::string text = kView + "move 1 2 3" + std::string(limit, ' ') + "\nbogus\n";
    expectError(text, 2, static_cast<int>(limit) + 1, {"16 MiB"});
    snell::ParseOutcome outcome = snell::parseSceneRecovering(text, "t.scn");
    ASSERT_TRUE(outcome.error);
    EXPECT_EQ(outcome.error->diagnostics().size(), 1u);
}

// ---------------------------------------------------------------- real files

TEST(ParserFiles, CourseScenesParseWithReadmeSphereCounts) {
    const std::map<std::string, std::size_t> expected = {
        {"becker-1n.scn", 6},          {"becker-refract.scn", 10},     {"becker-SphereFlake1.scn", 11},
        {"becker-SphereFlake2.scn", 92}, {"becker-SphereFlake3.scn", 821}, {"becker-SphereFlake4.scn", 7382},
        {"gonzalez-1n.scn", 6},        {"gonzalez-originalTest.scn", 3},
    };
    std::map<std::string, std::size_t> found;
    for (const auto& entry : fs::directory_iterator(SNELL_SOURCE_DIR "/../shared/course-scenes")) {
        if (entry.path().extension() != ".scn") continue;
        const std::string name = entry.path().filename().string();
        SCOPED_TRACE(name);
        try {
            const Scene s = snell::parseSceneFile(entry.path().string());
            found[name] = s.spheres.size();
            EXPECT_GT(s.imageSize, 0);
            EXPECT_GT(s.halfWidth, 0.0);
        } catch (const ParseError& e) {
            ADD_FAILURE() << e.what();
        }
    }
    EXPECT_EQ(found, expected);
}

TEST(ParserFiles, CourseSceneQuirks) {
    const std::string dir = SNELL_SOURCE_DIR "/../shared/course-scenes/";
    const Scene gonzalez = snell::parseSceneFile(dir + "gonzalez-1n.scn");
    EXPECT_FALSE(gonzalez.warnings.empty());  // last group never closed
    EXPECT_NE(gonzalez.ambient, dvec3(0.0));
    const Scene flake = snell::parseSceneFile(dir + "becker-SphereFlake1.scn");
    EXPECT_EQ(flake.supersample, 8);
    const Scene refract = snell::parseSceneFile(dir + "becker-refract.scn");
    EXPECT_EQ(refract.imageSize, 2000);
    EXPECT_GT(refract.ellipsoidCount(), 0u);
}

TEST(ParserFiles, ProjectScenesParse) {
    const fs::path dir = SNELL_SOURCE_DIR "/scenes";
    if (!fs::exists(dir)) return;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (!entry.is_regular_file() || entry.path().extension() != ".scn") continue;
        SCOPED_TRACE(entry.path().string());
        try {
            const Scene s = snell::parseSceneFile(entry.path().string());
            EXPECT_GT(s.imageSize, 0);
        } catch (const ParseError& e) {
            ADD_FAILURE() << e.what();
        }
    }
}

}  // namespace
