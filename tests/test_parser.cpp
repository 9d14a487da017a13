// Scene-file parser: SPEC §1 (syntax), §2 (commands, defaults); the real
// files of the course. Its errors (SPEC §7): test_parser_errors.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "parser_test_support.h"

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
