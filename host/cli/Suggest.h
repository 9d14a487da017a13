// "Did you mean ...?" for a misspelt subcommand or option, as the scene
// parser does for a misspelt scene command.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace snell::cli {

// The message for `error` when it comes from an unknown subcommand or
// option that is close to a real one (or an unknown subcommand at all);
// empty when CLI11's own message says it better.
std::string suggestFor(const CLI::App& app, const CLI::ParseError& error);

}  // namespace snell::cli
