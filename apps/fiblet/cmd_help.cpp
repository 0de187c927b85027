// fiblet help [SUBCOMMAND] — a subcommand's help; `fiblet help --markdown`
// (hidden) prints the whole CLI reference, docs/cli.md, from the CLI11
// definitions themselves so that the document cannot drift from the code
// (scripts/gen_cli_docs.sh regenerates it; a test compares).
#include <fmt/core.h>

#include <string>
#include <vector>

#include "cli_common.hpp"

namespace fiblet::cli {
namespace {

struct HelpArgs {
    std::string topic;
    bool markdown = false;
};

std::vector<CLI::App*> subcommands(CLI::App& app) {
    return app.get_subcommands([](CLI::App*) { return true; });
}

std::string escape_cell(std::string s) {
    std::string out;
    for (char c : s) out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
    return out;
}

std::string option_value(const CLI::Option* o) {
    if (o->get_type_size_max() == 0) return "";  // a flag
    std::string t = o->get_type_name();
    if (o->get_items_expected_max() > 1) t += " ...";
    return t;
}

std::string usage(const CLI::App* cmd) {
    std::string u = "fiblet " + cmd->get_name();
    bool has_options = false;
    for (const CLI::Option* o : cmd->get_options())
        if (o->nonpositional() && !o->get_group().empty()) has_options = true;
    if (has_options) u += " [OPTIONS]";
    for (const CLI::Option* o : cmd->get_options()) {
        if (!o->get_positional()) continue;
        std::string p = o->get_name(true) + (o->get_items_expected_max() > 1 ? "..." : "");
        u += " " + (o->get_required() ? p : "[" + p + "]");
    }
    return u;
}

std::string markdown(CLI::App& app) {
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
                          usage(cmd));
        md += "| argument | value | description |\n|---|---|---|\n";
        for (const CLI::Option* o : cmd->get_options()) {
            if (o->get_group().empty() || o == cmd->get_help_ptr()) continue;  // hidden, or -h on every command
            const std::string name = o->get_positional() && !o->nonpositional() ? o->get_name(true)
                                                                                 : o->get_name(false, true);
            std::string description = o->get_description();
            if (!o->get_default_str().empty()) description += " (default: " + o->get_default_str() + ")";
            if (o->get_required()) description += " (required)";
            md += fmt::format("| `{}` | {} | {} |\n", escape_cell(name), escape_cell(option_value(o)),
                              escape_cell(description));
        }
    }
    md += "\n## Exit codes\n\n| code | meaning |\n|---|---|\n";
    for (const ExitCodeInfo& e : exit_code_table()) md += fmt::format("| {} | {} |\n", e.code, e.meaning);
    return md;
}

void run(CLI::App& app, const HelpArgs& a) {
    if (a.markdown) {
        fmt::print("{}", markdown(app));
        return;
    }
    if (a.topic.empty()) {
        // Not app.help(): that would describe the selected subcommand, `help`.
        fmt::print("{}", app.get_formatter()->make_help(&app, "fiblet", CLI::AppFormatMode::Normal));
        return;
    }
    for (CLI::App* cmd : subcommands(app))
        if (cmd->get_name() == a.topic) {
            fmt::print("{}", cmd->help("fiblet"));
            return;
        }
    throw Error(Errc::invalid_argument, "no subcommand '" + a.topic + "' (fiblet help lists them)");
}

}  // namespace

void add_help(CLI::App& app) {
    auto args = std::make_shared<HelpArgs>();
    CLI::App* cmd = app.add_subcommand("help", "Print the help of fiblet or of one subcommand");
    cmd->add_option("subcommand", args->topic, "The subcommand to describe");
    cmd->add_flag("--markdown", args->markdown, "Print the whole reference as Markdown (docs/cli.md)")->group("");
    CLI::App* root = &app;
    cmd->callback([root, args] { run(*root, *args); });
}

}  // namespace fiblet::cli
