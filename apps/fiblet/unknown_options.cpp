#include "unknown_options.hpp"

#include <algorithm>
#include <utility>

#include "command_words.hpp"
#include "fiblet/error.hpp"

namespace fiblet::cli {
namespace {

bool has_option(const CLI::App& app, const std::string& name) {
    if (app.get_option_no_throw(name)) return true;
    const CLI::Option* help = app.get_help_ptr();
    return help && help->check_name(name);
}

// The long options of `app` ("--output"), help included.
std::vector<std::string> long_names(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::Option* o : app.get_options())
        for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    return names;
}

// How far a typo may be from the name meant: one edit in a short name, two
// from 5 letters, three from 9.
std::size_t allowed_edits(std::size_t letters) { return letters <= 4 ? 1 : letters <= 8 ? 2 : 3; }

// The long options close to `typed` (both with their dashes), closest first:
// within allowed_edits, or starting with it (--out: --output, --output-dir).
std::vector<std::string> close_options(const CLI::App& app, const std::string& typed) {
    const std::string_view word = std::string_view(typed).substr(2);
    std::vector<std::pair<std::size_t, std::string>> close;
    for (const std::string& name : long_names(app)) {
        const std::string_view candidate = std::string_view(name).substr(2);
        const std::size_t d = edit_distance(word, candidate);
        if (d <= allowed_edits(word.size()) || (word.size() >= 2 && candidate.starts_with(word)))
            close.emplace_back(d, name);
    }
    std::stable_sort(close.begin(), close.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> out;
    for (std::size_t i = 0; i < close.size() && i < 3; ++i) out.push_back(close[i].second);
    return out;
}

}  // namespace

std::string did_you_mean(const CLI::App& app, const std::string& long_name) {
    const std::vector<std::string> names = close_options(app, long_name);
    if (names.empty()) return "";
    std::string s = " (did you mean ";
    for (std::size_t i = 0; i < names.size(); ++i)
        s += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
    return s + "?)";
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
    // d[i][j]: distance between the first i characters of a and the first j of b (three rows kept).
    std::vector<std::size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        current[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                current[j] = std::min(current[j], before[j - 2] + 1);
        }
        std::swap(before, previous);
        std::swap(previous, current);
    }
    return previous[b.size()];
}

void reject_unknown_options(const CLI::App& app, const std::vector<std::string>& args) {
    const std::vector<CommandWord> words = classify_words(app, args);
    for (std::size_t i = 0; i < args.size(); ++i) {
        if (words[i].kind != CommandWord::Kind::option) continue;
        const CLI::App& command = *words[i].app;
        const std::string name = option_name(args[i]);
        if (has_option(command, name)) continue;
        const std::string close = name.rfind("--", 0) == 0 ? did_you_mean(command, name) : "";
        throw Error(Errc::invalid_argument,
                    "unknown option " + name + close + "; see " + command_name(command) + " --help");
    }
}

}  // namespace fiblet::cli
