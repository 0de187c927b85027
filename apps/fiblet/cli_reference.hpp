// The CLI's reference generated from its CLI11 definitions, so that no
// document can drift from the code: Markdown (docs/cli.md), a man page and
// a bash completion script (`fiblet help --markdown | --man | --bash-completion`).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace fiblet::cli {

std::vector<CLI::App*> subcommands(CLI::App& app);
// The options a reference lists: not hidden, not -h (on every command).
std::vector<const CLI::Option*> documented_options(const CLI::App* cmd);
// "fiblet compress [OPTIONS] inputs..."
std::string usage_line(const CLI::App* cmd);
// The value an option takes ("TEXT", "UINT ..."), empty for a flag.
std::string option_value(const CLI::Option* o);
// The description with its default and whether it is required.
std::string option_description(const CLI::Option* o);

// Worked examples for the man page and docs/cli.md: what it does, the command.
struct CliExample {
    const char* what;
    const char* command;
};
// Those whose commands this build has (render and view need the viewer).
std::vector<CliExample> cli_examples(CLI::App& app);

std::string markdown_reference(CLI::App& app);
std::string man_page(CLI::App& app);
std::string bash_completion(CLI::App& app);

}  // namespace fiblet::cli
