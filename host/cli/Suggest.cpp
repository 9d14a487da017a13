#include "cli/Suggest.h"

#include "common/EditDistance.h"

namespace snell::cli {
namespace {

// Up to a third of the word's letters may be wrong (at least one, at most three).
int allowedEdits(const std::string& word) { return std::clamp(int(word.size()) / 3, 1, 3); }

std::string unknownSubcommand(const CLI::App& app, const std::string& word) {
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        names.push_back(sub->get_name());
    const std::string_view best = nearestName(word, names, allowedEdits(word));
    if (!best.empty())
        return "unknown command '" + word + "'; did you mean '" + std::string(best) + "'? (snell --help lists them)";
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    return "unknown command '" + word + "' (commands: " + list + "; snell --help says more)";
}

std::string unknownOption(const CLI::App& command, const std::string& argument) {
    const std::string word = argument.substr(0, argument.find('='));
    std::vector<std::string> names;
    for (const CLI::Option* option : command.get_options()) {
        for (const std::string& n : option->get_lnames()) names.push_back("--" + n);
        for (const std::string& n : option->get_snames()) names.push_back("-" + n);
    }
    const std::string_view best = nearestName(word, names, allowedEdits(word));
    if (best.empty()) return "";
    return command.get_name() + ": unknown option '" + word + "'; did you mean '" + std::string(best) + "'? (snell " +
           command.get_name() + " --help lists them)";
}

}  // namespace

std::string suggestFor(const CLI::App& app, const CLI::ParseError& error) {
    if (dynamic_cast<const CLI::ExtrasError*>(&error) == nullptr) return "";
    const std::vector<CLI::App*> parsed = app.get_subcommands();
    if (parsed.empty()) {
        // No subcommand matched: the first word that is not an option was meant to be one.
        for (const std::string& word : app.remaining())
            if (!word.empty() && word[0] != '-') return unknownSubcommand(app, word);
        return "";
    }
    for (const CLI::App* command : parsed)
        for (const std::string& argument : command->remaining())
            if (argument.size() > 1 && argument[0] == '-')
                if (std::string hint = unknownOption(*command, argument); !hint.empty()) return hint;
    return "";
}

}  // namespace snell::cli
