#include "single_dash_options.hpp"

#include <algorithm>
#include <cctype>
#include <map>

#include "command_words.hpp"
#include "unknown_options.hpp"
#include "fiblet/error.hpp"

namespace fiblet::cli {
namespace {

// MRtrix3's standard options and tckedit's, with fiblet's name for each.
const std::map<std::string, std::string>& mrtrix_spellings() {
    static const std::map<std::string, std::string> table = {
        {"force", "--force"},         {"quiet", "--quiet"},         {"nthreads", "--threads"},
        {"help", "--help"},           {"version", "--version"},     {"include", "--include"},
        {"exclude", "--exclude"},     {"minlength", "--min-length"}, {"maxlength", "--max-length"},
        {"number", "--number"},       {"skip", "--skip"},           {"inverse", "--inverse"},
        {"ends_only", "--ends-only"},
    };
    return table;
}

// MRtrix3's standard options that fiblet has no counterpart for.
const std::map<std::string, std::string>& mrtrix_without_counterpart() {
    static const std::map<std::string, std::string> table = {
        {"info", "fiblet prints a report unless --quiet"},
        {"debug", "fiblet has no debug output"},
        {"config", "fiblet reads no MRtrix3 configuration"},
    };
    return table;
}

bool has_option(const CLI::App& app, const std::string& name) {
    if (name == "--help") return app.get_help_ptr() != nullptr;
    return app.get_option_no_throw(name) != nullptr;
}

// An option that takes a value: the word after it is that value, whatever it looks like.
bool takes_value(const CLI::App& app, const std::string& word) {
    if (word.size() < 2 || word[0] != '-' || word.find('=') != std::string::npos) return false;
    const CLI::Option* o = app.get_option_no_throw(word);
    return o && !o->get_positional() && o->get_items_expected_max() > 0;
}

// -force, -json: a dash, then two or more characters starting with a letter.
// -j4 (a short option with its number attached) and -1,2,3 (a number) are not.
bool is_single_dash_word(const std::string& w) {
    if (w.size() < 3 || w[0] != '-' || w[1] == '-' || !std::isalpha(static_cast<unsigned char>(w[1]))) return false;
    return w.find_first_not_of("0123456789", 2) != std::string::npos;
}

// `-name` or `-name=value`: fiblet's spelling, or Error(invalid_argument) saying which one is meant.
std::string translate(const CLI::App& app, const std::string& word) {
    const std::size_t equals = std::min(word.find('='), word.size());
    const std::string name = word.substr(1, equals - 1), value = word.substr(equals);
    const auto mrtrix = mrtrix_spellings().find(name);
    if (mrtrix != mrtrix_spellings().end() && has_option(app, mrtrix->second)) return mrtrix->second + value;
    if (mrtrix != mrtrix_spellings().end())
        throw Error(Errc::invalid_argument, "'" + word + "': " + command_name(app) + " has no " + mrtrix->second +
                                                " option (MRtrix3's -" + name + "); see " + command_name(app) +
                                                " --help");
    if (const auto none = mrtrix_without_counterpart().find(name); none != mrtrix_without_counterpart().end())
        throw Error(Errc::invalid_argument, "'" + word + "': MRtrix3's -" + name + " has no counterpart in fiblet (" +
                                                none->second + ")");
    if (has_option(app, "--" + name))
        throw Error(Errc::invalid_argument,
                    "'" + word + "': long options take two dashes: --" + name + value);
    throw Error(Errc::invalid_argument, "'" + word + "': not an option of " + command_name(app) +
                                            did_you_mean(app, "--" + name) +
                                            " (a single dash is followed by one letter, e.g. -o FILE; long options "
                                            "take two dashes); see " + command_name(app) + " --help");
}

}  // namespace

std::vector<std::string> translate_single_dash_options(const CLI::App& app, std::vector<std::string> args) {
    const CLI::App* active = &app;
    bool value_next = false;
    for (std::string& word : args) {
        if (word == "--") break;  // the rest are operands
        if (value_next) {
            value_next = false;
            continue;
        }
        if (active == &app) {
            const auto sub = app.get_subcommands([&](const CLI::App* s) { return s->get_name() == word; });
            if (!sub.empty()) {
                active = sub.front();
                continue;
            }
        }
        if (is_single_dash_word(word)) word = translate(*active, word);
        value_next = takes_value(*active, word);
    }
    return args;
}

}  // namespace fiblet::cli
