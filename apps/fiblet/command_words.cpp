#include "command_words.hpp"

#include <cctype>

namespace fiblet::cli {
namespace {

// -x..., --name...: a dash then a letter (CLI11 reads -1 as a number unless an option -1 exists).
bool looks_like_option(const std::string& w) {
    if (w.size() < 2 || w[0] != '-') return false;
    const std::size_t first = w[1] == '-' ? 2 : 1;
    return first < w.size() && !std::isdigit(static_cast<unsigned char>(w[first])) && w[first] != '.';
}

bool takes_value(const CLI::App& app, const std::string& word) {
    if (word.find('=') != std::string::npos) return false;
    const CLI::Option* o = app.get_option_no_throw(word);
    return o && !o->get_positional() && o->get_items_expected_max() > 0;
}

}  // namespace

std::string option_name(const std::string& word) {
    if (word.rfind("--", 0) == 0) return word.substr(0, word.find('='));
    return word.substr(0, 2);
}

std::string command_name(const CLI::App& app) {
    return app.get_parent() ? "fiblet " + app.get_name() : "fiblet";
}

std::vector<CommandWord> classify_words(const CLI::App& app, const std::vector<std::string>& args) {
    using Kind = CommandWord::Kind;
    std::vector<CommandWord> out;
    const CLI::App* active = &app;
    bool value_next = false, operands_only = false;
    for (const std::string& word : args) {
        if (operands_only) {
            out.push_back({Kind::operand, active});
        } else if (value_next) {
            value_next = false;
            out.push_back({Kind::value, active});
        } else if (word == "--") {
            operands_only = true;
            out.push_back({Kind::end_of_options, active});
        } else if (const auto sub = active == &app ? app.get_subcommands([&](const CLI::App* s) {
                                                          return s->get_name() == word;
                                                      })
                                                    : std::vector<const CLI::App*>{};
                   !sub.empty()) {
            active = sub.front();
            out.push_back({Kind::subcommand, active});
        } else if (looks_like_option(word)) {
            value_next = takes_value(*active, word);
            out.push_back({Kind::option, active});
        } else {
            out.push_back({Kind::operand, active});
        }
    }
    return out;
}

}  // namespace fiblet::cli
