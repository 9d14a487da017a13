// libFuzzer target: any bytes as a scene file. The parser must either return
// a scene or report errors — never crash, hang or trip a sanitizer — and its
// report must keep SPEC §7's shape (checkReport).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "scene/Parser.h"

namespace {

// At most kMaxReportedErrors listed, one a line in file order (a missing
// 'view', found at the end, comes last at 1:1), the rest counted; what() is
// those lines and the "more errors" line, joined by '\n'.
void checkReport(const snell::ParseError& e) {
    const auto& listed = e.diagnostics();
    if (listed.empty() || listed.size() > snell::ParseLimits::kMaxReportedErrors) std::abort();
    if (listed.size() < snell::ParseLimits::kMaxReportedErrors && e.notShown() != 0) std::abort();
    for (std::size_t k = 1; k < listed.size(); ++k) {
        const bool missingViewLast = k + 1 == listed.size() && listed[k].location.line == 1 &&
                                     listed[k].location.column == 1;
        if (listed[k].location.line <= listed[k - 1].location.line && !missingViewLast) std::abort();
    }
    const std::string what = e.what();
    if (what.rfind(e.diagnostic().format("error"), 0) != 0 || what.back() == '\n') std::abort();
    const auto lines = static_cast<std::size_t>(std::count(what.begin(), what.end(), '\n')) + 1;
    if (lines != listed.size() + (e.notShown() > 0 ? 1 : 0)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const snell::ParseOutcome outcome = snell::parseSceneRecovering(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.scn");
    if (outcome.error) {
        checkReport(*outcome.error);
        // Beside errors, the parser's warnings are about lines that parsed.
        for (const snell::Diagnostic& w : outcome.scene.warnings)
            if (w.location.line <= 0) std::abort();
    }
    return 0;
}
