// Scene-file parser: SPEC §7 (errors): each error at its FILE:LINE:COL, and
// every error of a file in one pass, with recovery.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "parser_test_support.h"

namespace {

// ---------------------------------------------------------------- errors

TEST(ParserErrors, UnknownCommand) {
    expectError(kView + "spehre\n", 2, 1, {"unknown command", "'spehre'", "sphere"});
    expectError(kView + "  bogus 1 2\n", 2, 3, {"unknown command", "'bogus'"});
    expectError(kView + "Sphere\n", 2, 1, {"unknown command", "sphere"});  // lower case only
    expectError("eyep 0 0 1\nview 10 1\n", 1, 1, {"unknown command"});
}

TEST(ParserErrors, TooFewArgumentsAtCommand) {
    expectError(kView + "scale 1 2\n", 2, 1, {"scale", "3"});
    expectError(kView + "  move\n", 2, 3, {"move"});
    expectError(kView + "rotate 1 2 3\n", 2, 1, {"rotate"});
    expectError(kView + "light 1 1 1 0 0\n", 2, 1, {"light"});
    expectError(kView + "background 1 1\n", 2, 1, {"background"});
    expectError(kView + "ambient\n", 2, 1, {"ambient"});
    expectError(kView + "material 1 1 1 0 0 0\n", 2, 1, {"material"});
    expectError(kView + "refraction 1 1 1\n", 2, 1, {"refraction"});
    expectError(kView + "supersample\n", 2, 1, {"supersample"});
    expectError("view 10\n", 1, 1, {"view"});
    // Too few wins over a bad value further right (the command is leftmost).
    expectError(kView + "scale 0 1\n", 2, 1, {"scale"});
}

TEST(ParserErrors, TooManyArgumentsAtFirstExtra) {
    expectError(kView + "move 1 2 3 4 5\n", 2, 12, {"too many"});
    expectError(kView + "sphere 1\n", 2, 8, {"too many"});
    expectError(kView + "group x\n", 2, 7, {"too many"});
    expectError(kView + "group\ngroupend x\n", 3, 10, {"too many"});
    expectError("view 10 1 1\n", 1, 11, {"too many"});
    expectError(kView + "supersample 2  3\n", 2, 16, {"too many"});
    expectError(kView + "light 1 1 1 0 0 0 0\n", 2, 19, {"too many"});
    expectError(kView + "material 1 1 1 0 0 0 1 9\n", 2, 24, {"too many"});
    expectError(kView + "refraction 1 1 1 1.5 9\n", 2, 22, {"too many"});
}

TEST(ParserErrors, NonNumeric) {
    expectError(kView + "move 1 abc 3\n", 2, 8, {"'abc'"});
    expectError(kView + "move 1 2 3x\n", 2, 10);
    expectError(kView + "move . 0 0\n", 2, 6);
    expectError(kView + "move e5 0 0\n", 2, 6);
    expectError(kView + "move 1e 0 0\n", 2, 6);
    expectError(kView + "move 1.2.3 0 0\n", 2, 6);
    expectError(kView + "move --1 0 0\n", 2, 6);
    expectError(kView + "move 1,5 0 0\n", 2, 6);
    expectError(kView + "move 0 0 -\n", 2, 10);
    expectError(kView + "background 0 0 one\n", 2, 16);
}

TEST(ParserErrors, NanAndInf) {
    expectError(kView + "move nan 0 0\n", 2, 6, {"'nan'"});
    expectError(kView + "move NaN 0 0\n", 2, 6);
    expectError(kView + "move -nan 0 0\n", 2, 6);
    expectError(kView + "move 0 inf 0\n", 2, 8, {"'inf'"});
    expectError(kView + "move 0 -inf 0\n", 2, 8);
    expectError(kView + "move 0 +Infinity 0\n", 2, 8);
    expectError(kView + "light 1 1 1 0 0 nan\n", 2, 17);
    expectError("view 10 inf\n", 1, 9);
}

TEST(ParserErrors, Overflow) {
    expectError(kView + "move 1e999 0 0\n", 2, 6, {"overflow"});
    expectError(kView + "move 0 -1e309 0\n", 2, 8, {"overflow"});
    expectError(kView + "scale 1 1 " + std::string(400, '9') + "\n", 2, 11, {"overflow"});
}

TEST(ParserErrors, NumberErrorsNameTheArgument) {
    expectError(kView + "light 1 1 one 0 0 0\n", 2, 11,
                {"expected a number for 'b' (argument 3 of 'light r g b x y z'), got 'one'"});
    expectError(kView + "material 1 1 1 0 abc 0 1\n", 2, 18, {"'sg' (argument 5 of 'material dr dg db sr sg sb p')"});
    expectError(kView + "rotate 30 0 0 nan\n", 2, 15, {"'z' (argument 4 of 'rotate angle x y z')", "finite"});
    expectError("view 10 0x1\n", 1, 9, {"'d' (argument 2 of 'view n d')", "hexadecimal"});
    expectError(kView + "scale 1 1e999 1\n", 2, 9, {"'sy' (argument 2 of 'scale sx sy sz')", "overflows"});
}

TEST(ParserErrors, HexFloat) {
    expectError(kView + "move 0x1p3 0 0\n", 2, 6, {"hexadecimal"});
    expectError(kView + "move 0 -0X10 0\n", 2, 8, {"hexadecimal"});
}

TEST(ParserErrors, NegativeColoursAndCoefficients) {
    expectError(kView + "background 0 -0.5 0\n", 2, 14);
    expectError(kView + "ambient 0.2 0.2 -1\n", 2, 17);
    expectError(kView + "light 1 -1 1 0 0 0\n", 2, 9);
    expectError(kView + "material 1 1 1 0 -0.1 0 1\n", 2, 18);
    expectError(kView + "refraction -1 0 0 1.5\n", 2, 12);
    // Negative light positions are fine.
    EXPECT_NO_THROW(parse(kView + "light 1 1 1 -1 -2 -3\n"));
}

TEST(ParserErrors, NegativePhongExponent) {
    expectError(kView + "material 1 1 1 0 0 0 -1\n", 2, 22, {"Phong"});
}

TEST(ParserErrors, ZeroScaleAtTheZero) {
    expectError(kView + "scale 1 0 1\n", 2, 9, {"zero"});
    expectError(kView + "scale 2 2 0.0\n", 2, 11, {"zero"});
    expectError(kView + "scale -0 2 2\n", 2, 7, {"zero"});
    // Negative factors are allowed.
    EXPECT_NO_THROW(parse(kView + "scale -1 2 -3\nsphere\n"));
}

TEST(ParserErrors, ZeroRotationAxisAtAxisFirstNumber) {
    expectError(kView + "rotate 45 0 0 0\n", 2, 11, {"axis"});
    expectError(kView + "rotate  45  0.0  -0  +0\n", 2, 13, {"axis"});
    // Any angle is fine with a non-zero axis, however short or long.
    EXPECT_NO_THROW(parse(kView + "rotate 720 1e-300 0 0\nrotate -30 1e300 1e300 0\nsphere\n"));
}

TEST(ParserErrors, ViewSize) {
    expectError("view 1.5 1\n", 1, 6, {"integer"});
    expectError("view 10. 1\n", 1, 6, {"integer"});
    expectError("view 1e2 1\n", 1, 6, {"integer"});
    expectError("view x 1\n", 1, 6);
    expectError("view 0 1\n", 1, 6);
    expectError("view -4 1\n", 1, 6);
    expectError("view 100000000000000000000000 1\n", 1, 6);
    expectError("view " + std::to_string(snell::ParseLimits::kMaxImageSize + 1) + " 1\n", 1, 6);
    EXPECT_EQ(parse("view " + std::to_string(snell::ParseLimits::kMaxImageSize) + " 1\n").imageSize,
              snell::ParseLimits::kMaxImageSize);
    EXPECT_EQ(parse("view 1 1\n").imageSize, 1);
}

TEST(ParserErrors, ViewHalfWidth) {
    expectError("view 10 0\n", 1, 9);
    expectError("view 10 -0.5\n", 1, 9);
    expectError("view 10 abc\n", 1, 9);
}

TEST(ParserErrors, MissingViewAtOneOne) {
    expectError("", 1, 1, {"view"});
    expectError("sphere\nmove 1 2 3\nsphere\n", 1, 1, {"view"});
    expectError("\n\n# only comments\n", 1, 1, {"view"});
}

TEST(ParserErrors, SecondViewAtItsCommand) {
    expectError(kView + "sphere\n  view 10 1\n", 3, 3, {"view"});
    expectError(kView + "view 20 2\n", 2, 1, {"view"});
}

TEST(ParserErrors, SecondViewWithBadArgumentReportsTheViewFirst) {
    // SPEC §7 file order: the second 'view' token (column 1) is itself the
    // offending token and stands left of its bad argument.
    expectError(kView + "view 0 1\n", 2, 1, {"view"});
    expectError(kView + "view 10 -1\n", 2, 1, {"view"});
}

TEST(ParserErrors, GroupendWithoutGroup) {
    expectError(kView + "groupend\n", 2, 1, {"groupend"});
    expectError(kView + "group\ngroupend\n groupend\n", 4, 2, {"groupend"});
}

TEST(ParserErrors, GroupNestingLimit) {
    const int limit = snell::ParseLimits::kMaxGroupDepth;
    std::string text = kView;
    for (int i = 0; i < limit; ++i) text += "group\n";
    EXPECT_NO_THROW(parse(text + "sphere\n"));
    text += "group\n";  // one too many, at line limit + 2
    expectError(text, limit + 2, 1, {"group", std::to_string(limit)});
}

TEST(ParserErrors, SupersampleZero) {
    expectError(kView + "supersample 0\n", 2, 13);
    expectError(kView + "supersample -2\n", 2, 13);
    expectError(kView + "supersample 1.5\n", 2, 13, {"integer"});
    expectError(kView + "supersample " + std::to_string(snell::ParseLimits::kMaxSupersample + 1) + "\n",
                2, 13);
}

TEST(ParserErrors, RefractionIndexNotPositive) {
    expectError(kView + "refraction 0 0 0 0\n", 2, 18);
    expectError(kView + "refraction 1 1 1 -1.5\n", 2, 18);
    // The index may be below 1 or far above it (course files use 25).
    EXPECT_NO_THROW(parse(kView + "refraction 1 1 1 0.5\nrefraction 1 1 1 25\n"));
}

TEST(ParserErrors, DegenerateTransformAtSphere) {
    expectError(kView + "scale 1e-200 1e-200 1e-200\nscale 1e-200 1e-200 1e-200\nmove 0 0 0\n  sphere\n", 5, 3,
                {"degenerate"});
    expectError(kView + "scale 1e200 1e200 1e200\nscale 1e200 1e200 1e200\nsphere\n", 4, 1, {"degenerate"});
    // The degenerate state alone (without a sphere) is not an error, and a
    // group restores a good transform.
    EXPECT_NO_THROW(parse(kView + "group\nscale 1e-200 1e-200 1e-200\nscale 1e-200 1e-200 1e-200\n"
                                  "groupend\nsphere\n"));
    // SPEC §5 range: tiny and huge spheres are fine.
    EXPECT_NO_THROW(parse(kView + "scale 1e-4 1e-4 1e-4\nsphere\nscale 1e10 1e10 1e10\nsphere\n"));
}

TEST(ParserErrors, NulByte) {
    const std::string text = kView + std::string("move 1 \0 2\n", 11);
    expectError(text, 2, 8, {"NUL"});
    // Even inside a comment.
    expectError(kView + std::string("sphere # \0\n", 11), 2, 10, {"NUL"});
}

TEST(ParserErrors, InvalidUtf8) {
    expectError(kView + "move 1 2 \xff\n", 2, 10, {"UTF-8"});
    expectError(kView + "# comment \xc3\x28\n", 2, 11, {"UTF-8"});      // bad continuation
    expectError(kView + "sphere #\xc0\xaf\n", 2, 9, {"UTF-8"});          // overlong
    expectError(kView + "sphere #\xed\xa0\x80\n", 2, 9, {"UTF-8"});      // surrogate
    expectError(kView + "sphere #\xe2\x82", 2, 9, {"UTF-8"});            // truncated at EOF
}

TEST(ParserErrors, LoneCarriageReturn) {
    expectError("view 10 1\rsphere\n", 1, 10);
    expectError(kView + "sphere\r\r\n", 2, 7);
    expectError(kView + "\r\r\nsphere\n", 2, 1);
    // The last line has no line end, so its final CR is a lone one too.
    expectError(kView + "\r", 2, 1);
    expectError(kView + "sphere\r", 2, 7);
}

TEST(ParserErrors, ErrorsInFileOrder) {
    // First bad token on the line wins.
    expectError(kView + "scale 0 x 1\n", 2, 7, {"zero"});
    expectError(kView + "scale x 0 1\n", 2, 7, {"'x'"});
    expectError(kView + "scale 1 1 0 extra\n", 2, 11, {"zero"});
    expectError(kView + "rotate nan 0 0 0\n", 2, 8);
    expectError(kView + "rotate 1 0 0 0 x\n", 2, 10, {"axis"});
    expectError(kView + "light -1 1 1 x 0 0\n", 2, 7);
    expectError(kView + "refraction 0 0 0 0 extra\n", 2, 18);
    expectError(kView + "material -1 1 1 0 0 0 -1\n", 2, 10);
    // First bad line wins.
    expectError(kView + "move 1 2 x\nscale 0 1 1\nbogus\n", 2, 10);
    expectError(kView + "bogus\nscale 0 1 1\n", 2, 1);
    // A byte-level error is found where it stands, after earlier lines' errors.
    expectError(kView + "scale 0 1 1\nsphere \xff\n", 2, 7);
    // A bad line before the view is reported there.
    expectError("scale 0 1 1\nview 10 1\n", 1, 7);
}

TEST(ParserErrors, ParseSceneFileMissingFile) {
    try {
        snell::parseSceneFile("/nonexistent-dir/none.scn");
        ADD_FAILURE() << "expected a ParseError";
    } catch (const ParseError& e) {
        // A file that cannot be opened has no position in it.
        EXPECT_EQ(std::string(e.what()).rfind("/nonexistent-dir/none.scn: error: cannot open scene file", 0), 0u)
            << e.what();
    }
}

// ---------------------------------------------------------------- every error

// The ParseError of `text`, which must have errors.
ParseError errorsOf(const std::string& text) {
    snell::ParseOutcome outcome = snell::parseSceneRecovering(text, "t.scn");
    if (outcome.error) return *outcome.error;
    ADD_FAILURE() << "expected errors in: " << text;
    snell::Diagnostic none;
    none.message = "no error";
    return ParseError(none);
}

// "LINE:COL" of each listed error, in the order listed.
std::vector<std::string> positionsOf(const ParseError& e) {
    std::vector<std::string> out;
    for (const snell::Diagnostic& d : e.diagnostics())
        out.push_back(std::to_string(d.location.line) + ":" + std::to_string(d.location.column));
    return out;
}

std::vector<std::string> positionsOf(const std::string& text) { return positionsOf(errorsOf(text)); }

std::vector<std::string> linesOf(const std::string& s) {
    std::vector<std::string> out;
    std::size_t start = 0;
    for (std::size_t nl; (nl = s.find('\n', start)) != std::string::npos; start = nl + 1)
        out.push_back(s.substr(start, nl - start));
    out.push_back(s.substr(start));
    return out;
}

// The scene that the good lines of `text` build, which must have errors.
Scene partialScene(const std::string& text) {
    snell::ParseOutcome outcome = snell::parseSceneRecovering(text, "t.scn");
    EXPECT_TRUE(outcome.error.has_value()) << "expected errors in: " << text;
    return std::move(outcome.scene);
}

TEST(ParserAllErrors, EveryErrorInFileOrderWithItsPosition) {
    const std::string text = kView + "move 1 x 3\nsphere\nscale 0 1 1\n  bogus\nlight 1 1 1 0 0 0 9\n"
                                     "material 1 1 1 0 0 0 -1\n";
    const ParseError e = errorsOf(text);
    EXPECT_EQ(positionsOf(e), (std::vector<std::string>{"2:8", "4:7", "5:3", "6:19", "7:22"}));
    EXPECT_EQ(e.notShown(), 0u);
    // The first is the one SPEC §7 names, and what() lists them all, one a line.
    EXPECT_EQ(e.diagnostic().location.line, 2);
    const std::vector<std::string> lines = linesOf(e.what());
    ASSERT_EQ(lines.size(), 5u) << e.what();
    EXPECT_EQ(lines[0], "t.scn:2:8: error: expected a number for 'y' (argument 2 of 'move x y z'), got 'x'");
    EXPECT_EQ(lines[1].rfind("t.scn:4:7: error: scale factor must not be zero", 0), 0u) << lines[1];
    EXPECT_EQ(lines[2].rfind("t.scn:5:3: error: unknown command 'bogus'", 0), 0u) << lines[2];
    EXPECT_EQ(lines[3].rfind("t.scn:6:19: error: too many arguments to 'light'", 0), 0u) << lines[3];
    EXPECT_EQ(lines[4].rfind("t.scn:7:22: error: material: Phong exponent p must be >= 0", 0), 0u) << lines[4];
    // parseScene throws the same report.
    try {
        parse(text);
        ADD_FAILURE() << "expected a ParseError";
    } catch (const ParseError& thrown) {
        EXPECT_STREQ(thrown.what(), e.what());
    }
}

TEST(ParserAllErrors, OneErrorALineTheFirstOnIt) {
    // The rest of a line is skipped after its first error.
    EXPECT_EQ(positionsOf(kView + "scale 0 x 1 extra\nmove 1 2 y\n"), (std::vector<std::string>{"2:7", "3:10"}));
    // Byte-level errors too, wherever they stand.
    EXPECT_EQ(positionsOf(kView + "move \xff x 0\nsphere # \xfe\nsphere\r\r\nscale 0 1 1\n"s),
              (std::vector<std::string>{"2:6", "3:10", "4:7", "5:7"}));
}

TEST(ParserAllErrors, NulByteStopsReading) {
    // No text file holds one (/dev/zero, a binary file): the lines before it
    // are parsed, and nothing after it is read.
    EXPECT_EQ(positionsOf(kView + "move 1 x 2\nsphere # \0 then\nbogus\n"s),
              (std::vector<std::string>{"2:8", "3:10"}));
    // It is its line's error, wherever it stands; a 'view' may have followed.
    const ParseError e = errorsOf("sphere\r \0\nview 10 1\n"s);
    EXPECT_EQ(positionsOf(e), std::vector<std::string>{"1:9"});
    EXPECT_NE(std::string(e.what()).find("NUL byte"), std::string::npos) << e.what();
}

TEST(ParserAllErrors, WarningsInterleavedByLine) {
    // Errors at 1:8 and 3:7, and a missing view found at the end of the input.
    const ParseError errors = errorsOf("move 1 x 2\nsphere\nscale 0 1 1\n");
    auto at = [](int line, int column, const std::string& message) {
        snell::Diagnostic d;
        d.location = {"t.scn", line, column};
        d.message = message;
        return d;
    };
    const ParseError both = errors.withWarnings(
        {at(1, 1, "w1"), at(3, 7, "w3 at the error"), at(3, 9, "w3 after it"), at(9, 1, "w9"), at(0, 0, "whole")});
    const std::vector<std::string> want{
        "t.scn:1:1: warning: w1",           "t.scn:1:8: error: expected a number",
        "t.scn:3:7: error: scale factor",   "t.scn:3:7: warning: w3 at the error",
        "t.scn:3:9: warning: w3 after it",  "t.scn:9:1: warning: w9",
        "t.scn:1:1: error: missing 'view'", "t.scn: warning: whole",
    };
    const std::vector<std::string> lines = linesOf(both.what());
    ASSERT_EQ(lines.size(), want.size()) << both.what();
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_EQ(lines[k].rfind(want[k], 0), 0u) << lines[k];
    EXPECT_EQ(both.diagnostics().size(), 3u);
    EXPECT_EQ(both.warnings().size(), 5u);
    EXPECT_TRUE(errors.warnings().empty());
}

TEST(ParserAllErrors, ListsTwentyThenCountsTheRest) {
    std::string text = kView;
    for (int i = 0; i < 30; ++i) text += "move 1 2 x\n";
    const ParseError e = errorsOf(text);
    ASSERT_EQ(e.diagnostics().size(), snell::ParseLimits::kMaxReportedErrors);
    EXPECT_EQ(e.diagnostics().back().location.line, 21);
    EXPECT_EQ(e.notShown(), 10u);
    EXPECT_FALSE(e.notShownIsLowerBound());
    const std::vector<std::string> lines = linesOf(e.what());
    ASSERT_EQ(lines.size(), 21u);
    EXPECT_EQ(lines[19].rfind("t.scn:21:10: error: ", 0), 0u) << lines[19];
    EXPECT_EQ(lines[20], "t.scn: error: 10 more errors not shown");
    EXPECT_EQ(linesOf(errorsOf(text + "bogus\n").what()).back(), "t.scn: error: 11 more errors not shown");
    std::string twentyOne = kView;
    for (int i = 0; i < 21; ++i) twentyOne += "bogus\n";
    EXPECT_EQ(linesOf(errorsOf(twentyOne).what()).back(), "t.scn: error: 1 more error not shown");
}

TEST(ParserAllErrors, StopsReadingAfterTenThousandErrors) {
    std::string text = kView;
    for (std::size_t i = 0; i < snell::ParseLimits::kMaxCountedErrors + 5; ++i) text += "bogus\n";
    const ParseError e = errorsOf(text);
    EXPECT_EQ(e.diagnostics().size(), snell::ParseLimits::kMaxReportedErrors);
    EXPECT_EQ(e.notShown(), snell::ParseLimits::kMaxCountedErrors - snell::ParseLimits::kMaxReportedErrors);
    EXPECT_TRUE(e.notShownIsLowerBound());
    EXPECT_EQ(linesOf(e.what()).back(),
              "t.scn: error: at least 9980 more errors not shown (stopped reading at line 10001 after 10000 errors)");
}

TEST(ParserAllErrors, MissingViewComesLastAndOnlyWithoutAnyViewLine) {
    // Found at the end of the file, so listed after the lines' errors.
    EXPECT_EQ(positionsOf("scale 0 1 1\nsphere\n"), (std::vector<std::string>{"1:7", "1:1"}));
    EXPECT_NE(errorsOf("scale 0 1 1\n").diagnostics().back().message.find("missing 'view'"), std::string::npos);
    // A view line that failed, however, is a view: no "missing 'view'" after it.
    EXPECT_EQ(positionsOf("view 0 1\nsphere\n"), std::vector<std::string>{"1:6"});
    EXPECT_EQ(positionsOf("view 10\nsphere\n"), std::vector<std::string>{"1:1"});
    EXPECT_EQ(positionsOf("view 10 1 2\n"), std::vector<std::string>{"1:11"});
    EXPECT_EQ(positionsOf("view 10 1 # \xff\n"), std::vector<std::string>{"1:13"});
    // So is a misspelt one that the hint names.
    EXPECT_EQ(positionsOf("View 10 1\nsphere\n"), std::vector<std::string>{"1:1"});
    EXPECT_EQ(positionsOf("veiw 10 1\n"), std::vector<std::string>{"1:1"});
    // A second view is a mistake of its own, even after a failed first one.
    EXPECT_EQ(positionsOf("view 0 1\nview 10 1\n"), (std::vector<std::string>{"1:6", "2:1"}));
}

TEST(ParserAllErrors, FailedCommandChangesNoState) {
    const Scene s = partialScene(kView + "material 0.5 0.5 0.5 0 0 0 2\nsphere\n"
                                         "material 0.1 0.1 0.1 x 0 0 7\nsphere\n"  // bad ks: no change
                                         "refraction 0.5 0.5 0.5 0\n"             // bad index: no change
                                         "move 1 0 0\nmove 5 x 5\nmove 1 0 0 9\nsphere\n"
                                         "background 1 1 -1\nsupersample 0\nlight 1 1 1 0 0\n");
    ASSERT_EQ(s.spheres.size(), 3u);
    EXPECT_EQ(s.spheres[1].material, s.spheres[0].material);
    const snell::Material& m = s.materials[s.spheres[2].material];
    EXPECT_EQ(m.kd, dvec3(0.5));
    EXPECT_EQ(m.ks, dvec3(0.0));
    EXPECT_EQ(m.phong, 2.0);
    EXPECT_EQ(m.kt, dvec3(0.0));
    EXPECT_EQ(m.eta, snell::kAirEta);
    EXPECT_EQ(s.spheres[2].centre, dvec3(1, 0, 0));
    EXPECT_EQ(s.background, dvec3(0.0));
    EXPECT_EQ(s.supersample, 1);
    EXPECT_TRUE(s.lights.empty());
    EXPECT_TRUE(s.warnings.empty());
    // Lines after a failed material parse as usual.
    EXPECT_EQ(positionsOf(kView + "material 1 1 1 0 0 0 -1\nmaterial 1 1 1 0 0 0 3\nsphere\nbogus\n"),
              (std::vector<std::string>{"2:22", "5:1"}));
}

TEST(ParserAllErrors, FailedScaleLeavesNoDegenerateTransform) {
    // The zero scale has no effect, so the sphere after it is fine.
    EXPECT_EQ(positionsOf(kView + "scale 1 0 1\nsphere\nscale 0 0 0 1\nsphere\n"),
              (std::vector<std::string>{"2:9", "4:7"}));
    // A degenerate transform, though, makes each sphere under it an error.
    EXPECT_EQ(positionsOf(kView + "scale 1e-200 1e-200 1e-200\nscale 1e-200 1e-200 1e-200\nsphere\nsphere\n"),
              (std::vector<std::string>{"4:1", "5:1"}));
}

TEST(ParserAllErrors, FailedGroupLinesKeepTheirNesting) {
    // A group with an error still opens a level, so its groupend matches...
    const Scene s = partialScene(kView + "group x\nmove 1 0 0\ngroupend\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 1u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(0.0));
    EXPECT_EQ(positionsOf(kView + "group x\ngroupend\n"), std::vector<std::string>{"2:7"});
    // ...and a groupend with an error still closes one.
    EXPECT_EQ(positionsOf(kView + "group\ngroupend x\ngroupend\n"), (std::vector<std::string>{"3:10", "4:1"}));
    // Also when the line fails on a byte, or misspells the command.
    EXPECT_EQ(positionsOf(kView + "group\rx\ngroupend\n"), std::vector<std::string>{"2:6"});
    EXPECT_EQ(positionsOf(kView + "gruop\ngroupend\n"), std::vector<std::string>{"2:1"});
    // An unmatched groupend is an error each time.
    EXPECT_EQ(positionsOf(kView + "groupend\ngroupend\n"), (std::vector<std::string>{"2:1", "3:1"}));
}

TEST(ParserAllErrors, NestingLimitReportedOnceAndItsGroupendsMatch) {
    const int limit = snell::ParseLimits::kMaxGroupDepth;
    std::string text = kView;
    for (int i = 0; i < limit; ++i) text += "group\n";
    // Three levels past the limit: one mistake, reported at the first.
    text += "group\nmove 1 0 0\ngroup\ngroup\nmove 1 0 0\ngroupend\ngroupend\ngroupend\nsphere\n";
    for (int i = 0; i < limit; ++i) text += "groupend\n";
    text += "bogus\n";
    const ParseError e = errorsOf(text);
    EXPECT_EQ(positionsOf(e),
              (std::vector<std::string>{std::to_string(limit + 2) + ":1", std::to_string(2 * limit + 11) + ":1"}));
    // Closing the levels past the limit restores the state of their first group.
    const Scene s = partialScene(text);
    ASSERT_EQ(s.spheres.size(), 1u);
    EXPECT_EQ(s.spheres[0].centre, dvec3(0.0));
}

TEST(ParserAllErrors, LightLimitReportedOnce) {
    std::string text = kView;
    for (std::size_t i = 0; i < snell::ParseLimits::kMaxLights + 3; ++i) text += "light 1 1 1 0 0 0\n";
    text += "light 1 1 1 0 0 x\n";  // still checked
    const std::size_t first = snell::ParseLimits::kMaxLights + 2;
    EXPECT_EQ(positionsOf(text), (std::vector<std::string>{std::to_string(first) + ":1",
                                                           std::to_string(first + 3) + ":17"}));
    EXPECT_EQ(partialScene(text).lights.size(), snell::ParseLimits::kMaxLights);
}

TEST(ParserAllErrors, FileLevelErrorsStaySingle) {
    try {
        snell::parseSceneFile("/nonexistent-dir/none.scn");
        ADD_FAILURE() << "expected a ParseError";
    } catch (const ParseError& e) {
        EXPECT_EQ(e.diagnostics().size(), 1u);
        EXPECT_EQ(e.notShown(), 0u);
        EXPECT_EQ(linesOf(e.what()).size(), 1u) << e.what();
    }
}

TEST(ParserAllErrors, GoodSceneHasNoErrorAndKeepsWarnings) {
    const snell::ParseOutcome outcome = snell::parseSceneRecovering(kView + "group\nsphere\n", "t.scn");
    EXPECT_FALSE(outcome.error.has_value());
    EXPECT_EQ(outcome.scene.spheres.size(), 1u);
    EXPECT_EQ(outcome.scene.warnings.size(), 1u);  // the group never closed
}


}  // namespace
