#include "cli/OptionErrors.h"

#include <cctype>
#include <regex>

#include "cli/Suggest.h"

namespace snell::cli {
namespace {

// An option as the command line names it: "--output", or "SCENE" for a positional.
std::string shownName(const CLI::Option& option) {
    if (!option.get_lnames().empty()) return "--" + option.get_lnames().front();
    if (!option.get_snames().empty()) return "-" + option.get_snames().front();
    std::string name = option.get_name();
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return name;
}

// The first required argument or option the command line left out.
std::string missingArgument(const CLI::App& command) {
    for (const CLI::Option* option : command.get_options())
        if (option->get_required() && option->count() == 0)
        {
            std::string description = option->get_description();
            if (!description.empty())
                description[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(description[0])));
            return std::string(option->nonpositional() ? "missing option " : "missing argument ") +
                   shownName(*option) + (description.empty() ? "" : ": " + description);
        }
    return "";
}

// What the rest of "-q=3" means: CLI11 takes -q, then "-=3" for more short options.
std::string shortOptionValue(const std::vector<std::string>& rest) {
    for (const std::string& argument : rest)
        if (argument.starts_with("-="))
            return "unexpected '" + argument.substr(1) + "' after a short option (a switch takes no value; another "
                   "option takes its value after a space: -s 64)";
    return "";
}

// Arguments nothing took: unknown options, or a word too many.
std::string leftOver(const std::vector<std::string>& rest) {
    for (const std::string& argument : rest)
        if (argument.size() > 1 && argument[0] == '-')
            return "unknown option '" + argument.substr(0, argument.find('=')) + "'";
    if (rest.empty()) return "";
    std::string words;
    for (const std::string& argument : rest) words += (words.empty() ? "'" : " '") + argument + "'";
    return (rest.size() > 1 ? "unexpected arguments " : "unexpected argument ") + words;
}

// A count of values in words: "one value", "4 values".
std::string values(const std::string& count) { return count == "1" ? "one value" : count + " values"; }

// The option `name` of the command, or null.
const CLI::Option* optionNamed(const CLI::App* command, const std::string& name) {
    if (!command) return nullptr;
    for (const CLI::Option* option : command->get_options())
        if (option->check_name(name)) return option;
    return nullptr;
}

// CLI11's own sentences, by the forms its errors take (CLI/Error.hpp), in words of the command line.
std::string reworded(const std::string& message, const CLI::App* command) {
    std::smatch m;
    if (std::regex_match(message, m, std::regex(R"((\S+): At Most (\d+) required but received (\d+))")))
        return m[1].str() + " takes " + values(m[2].str()) + ", not " + m[3].str() +
               (m[2].str() == "1" ? " (given more than once?)" : "");
    if (std::regex_match(message, m, std::regex(R"((\S+): At least (\d+) required but received (\d+))")) ||
        std::regex_match(message, m, std::regex(R"(Expected exactly (\d+) arguments to (\S+), got (\d+))")))
        return (m[1].str()[0] == '-' ? m[1].str() + " takes " + values(m[2].str())
                                     : m[2].str() + " takes " + values(m[1].str())) +
               ", not " + m[3].str();
    if (std::regex_match(message, m, std::regex(R"(Could not convert: (\S+) = (.*))"))) {
        const CLI::Option* option = optionNamed(command, m[1].str());
        if (option && option->get_expected_max() == 0)
            return m[1].str() + " is a switch and takes no value, not '" + m[2].str() + "'";
        return m[1].str() + ": cannot read '" + m[2].str() + "'";
    }
    if (std::regex_match(message, m, std::regex(R"((\S+): (too many inputs for a flag|Should be true/false.*))")))
        return m[1].str() + " is a switch and takes no value";
    if (std::regex_match(message, m, std::regex(R"((\S+) requires (\S+))")))
        return m[1].str() + " needs " + m[2].str() + " as well";
    if (std::regex_match(message, m, std::regex(R"((\S+) excludes (\S+))")))
        return m[1].str() + " and " + m[2].str() + " cannot be given together";
    return message;
}

}  // namespace

std::string describeParseError(const CLI::App& app, const CLI::ParseError& error) {
    const std::vector<CLI::App*> parsed = app.get_subcommands();
    const CLI::App* command = parsed.empty() ? nullptr : parsed.front();
    // Arguments nothing took explain what follows from them (a value taken
    // for the scene, a scene reported missing): they come first, a
    // misspelling with its suggestion (already in full).
    const std::vector<std::string> rest = command ? command->remaining() : app.remaining();
    std::string what = shortOptionValue(rest);
    if (what.empty() && !rest.empty())
        if (std::string hint = suggestFor(app, CLI::ExtrasError(rest)); !hint.empty()) return hint;
    if (what.empty()) what = leftOver(rest);
    if (what.empty() && dynamic_cast<const CLI::RequiredError*>(&error) && command) what = missingArgument(*command);
    if (what.empty()) what = reworded(error.what(), command);
    const std::string name = command ? command->get_name() : "";
    return (name.empty() ? "" : name + ": ") + what + " (see snell " + (name.empty() ? "" : name + " ") + "--help)";
}

}  // namespace snell::cli
