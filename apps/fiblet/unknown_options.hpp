// An option the subcommand does not have (`--optput`), reported before
// anything else is parsed or checked, with the options it is closest to:
// "unknown option --optput (did you mean --output?)". CLI11 alone would take
// the word after it for an operand and report that path first.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace fiblet::cli {

// Throws Error(Errc::invalid_argument) naming the first unknown option of
// `args` (the program name left out, single-dash spellings already
// translated).
void reject_unknown_options(const CLI::App& app, const std::vector<std::string>& args);

// " (did you mean --output?)": the long options of `app` close to
// `long_name` (with its dashes), or "" when none is.
std::string did_you_mean(const CLI::App& app, const std::string& long_name);

// Optimal string alignment distance (Levenshtein with transpositions of
// adjacent characters): "optput" -> "output" 1, "stye" -> "style" 1.
std::size_t edit_distance(std::string_view a, std::string_view b);

}  // namespace fiblet::cli
