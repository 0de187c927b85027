// docs/cli.md: the CLI reference as Markdown (`fiblet help --markdown`).
#include <fmt/core.h>

#include "cli_common.hpp"
#include "cli_reference.hpp"

namespace fiblet::cli {
namespace {

std::string escape_cell(std::string s) {
    std::string out;
    for (char c : s) out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
    return out;
}

}  // namespace

std::string markdown_reference(CLI::App& app) {
    std::string md;
    md += "# fiblet command-line reference\n\n";
    md += "<!-- Generated from the CLI11 definitions by `fiblet help --markdown`; regenerate with\n"
          "     scripts/gen_cli_docs.sh (a test fails when this file is out of date). -->\n\n";
    md += app.get_description() + ".\n\n";
    md += "`fiblet --version` prints the version; `fiblet help SUBCOMMAND` (or `fiblet SUBCOMMAND --help`) "
          "prints the help of a subcommand.\n\n";
    md += "Conventions: every command that reports numbers takes `--json` and then prints one JSON object "
          "on stdout (an array of them for several inputs); progress goes to stderr, and only when stderr "
          "is a terminal; outputs are written atomically (never half-written, even on errors or signals); "
          "the exit code tells what went wrong (below).\n\n";
    md += "| subcommand | what it does |\n|---|---|\n";
    for (CLI::App* cmd : subcommands(app))
        md += fmt::format("| [`{}`](#fiblet-{}) | {} |\n", cmd->get_name(), cmd->get_name(),
                          escape_cell(cmd->get_description()));
    for (CLI::App* cmd : subcommands(app)) {
        md += fmt::format("\n## fiblet {}\n\n{}.\n\n```\n{}\n```\n\n", cmd->get_name(), cmd->get_description(),
                          usage_line(cmd));
        md += "| argument | value | description |\n|---|---|---|\n";
        for (const CLI::Option* o : documented_options(cmd)) {
            const std::string name = o->get_positional() && !o->nonpositional() ? o->get_name(true)
                                                                                 : o->get_name(false, true);
            md += fmt::format("| `{}` | {} | {} |\n", escape_cell(name), escape_cell(option_value(o)),
                              escape_cell(option_description(o)));
        }
    }
    md += "\n## Examples\n\n";
    for (const CliExample& e : cli_examples(app)) md += fmt::format("{}:\n\n```\n{}\n```\n\n", e.what, e.command);
    md += "## Exit codes\n\n| code | meaning |\n|---|---|\n";
    for (const ExitCodeInfo& e : exit_code_table()) md += fmt::format("| {} | {} |\n", e.code, e.meaning);
    return md;
}

}  // namespace fiblet::cli
