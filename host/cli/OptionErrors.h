// The option library's (CLI11's) parse errors in snell's voice: what went
// wrong in the command line's own words, the subcommand named, and where
// its help is, for main to print as "snell: error: MESSAGE" (status 2).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace snell::cli {

// The message for `error`, thrown by app.parse(), without "snell: error: ":
// "render: --size: must be a whole number from 1 to 16384, not 'abc' (see
// snell render --help)". Arguments left over that look like options are
// named first, whatever CLI11 complained of, with a suggestion where one is
// close (Suggest.h).
std::string describeParseError(const CLI::App& app, const CLI::ParseError& error);

}  // namespace snell::cli
