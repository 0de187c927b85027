// What each word of a fiblet command line is, as CLI11 will read it: the
// subcommand, an option, an option's value, or an operand. For the checks
// and rewrites made before parsing (unknown_options, mrtrix_output_order).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace fiblet::cli {

struct CommandWord {
    enum class Kind { subcommand, option, value, operand, end_of_options };
    Kind kind;
    const CLI::App* app;  // the (sub)command the word belongs to
};

// One entry per word of `args` (the program name left out). A value is the
// word after an option that takes one (whatever it looks like); every word
// after `--` is an operand; `-` and negative numbers are operands.
std::vector<CommandWord> classify_words(const CLI::App& app, const std::vector<std::string>& args);

// An option word's name: "--output" for --output=x.fft, "-j" for -j4.
std::string option_name(const std::string& word);

// "fiblet compress" (or "fiblet" for the top level).
std::string command_name(const CLI::App& app);

}  // namespace fiblet::cli
