// What the parser's tests share: parsing a text as t.scn, and expecting an
// error at a line and column (SPEC §7).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "scene/Parser.h"

namespace {

using snell::dvec3;
using snell::ParseError;
using snell::Scene;
namespace fs = std::filesystem;
using namespace std::string_literals;

inline Scene parse(const std::string& text) { return snell::parseScene(text, "t.scn"); }

inline dvec3 apply(const glm::dmat4& m, dvec3 p) { return dvec3(m * glm::dvec4(p, 1.0)); }

inline void expectNear(dvec3 a, dvec3 b, double tolerance = 1e-12) {
    EXPECT_NEAR(a.x, b.x, tolerance);
    EXPECT_NEAR(a.y, b.y, tolerance);
    EXPECT_NEAR(a.z, b.z, tolerance);
}

// Parse `text`, expect a ParseError whose first error (the one SPEC §7 names)
// is at line:column, its message containing every one of `words`
// (case-sensitive), and what() starting with it in SPEC §7 format.
inline void expectError(const std::string& text, int line, int column, std::vector<std::string> words = {}) {
    SCOPED_TRACE("input: " + text);
    try {
        parse(text);
        ADD_FAILURE() << "expected a ParseError at " << line << ":" << column;
    } catch (const ParseError& e) {
        EXPECT_EQ(e.diagnostic().location.line, line) << e.what();
        EXPECT_EQ(e.diagnostic().location.column, column) << e.what();
        EXPECT_EQ(e.diagnostic().location.file, "t.scn");
        const std::string prefix =
            "t.scn:" + std::to_string(line) + ":" + std::to_string(column) + ": error: ";
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(prefix, 0), 0u) << "what(): " << what;
        EXPECT_GT(what.size(), prefix.size()) << "empty message";
        for (const std::string& w : words)
            EXPECT_NE(what.find(w), std::string::npos) << "'" << w << "' not in: " << what;
    }
}

inline const std::string kView = "view 10 1\n";

}  // namespace
