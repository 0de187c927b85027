// fiblet help [SUBCOMMAND] — a subcommand's help; `fiblet help --markdown`
// (hidden; --man and --bash-completion likewise give the man page and the
// completion script) prints the whole CLI reference, docs/cli.md, from the CLI11
// definitions themselves so that the document cannot drift from the code
// (scripts/gen_cli_docs.sh regenerates it; a test compares).
#include <fmt/core.h>

#include <string>
#include <vector>

#include "cli_common.hpp"
#include "cli_reference.hpp"

namespace fiblet::cli {
namespace {

struct HelpArgs {
    std::string topic;
    bool markdown = false, man = false, bash = false;
};

void run(CLI::App& app, const HelpArgs& a) {
    if (a.markdown + a.man + a.bash > 1) throw Error(Errc::invalid_argument, "one of --markdown, --man, --bash-completion");
    if (a.markdown || a.man || a.bash) {
        fmt::print("{}", a.markdown ? markdown_reference(app) : a.man ? man_page(app) : bash_completion(app));
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
    cmd->add_flag("--man", args->man, "Print the man page fiblet(1) (roff)")->group("");
    cmd->add_flag("--bash-completion", args->bash, "Print the bash completion script")->group("");
    CLI::App* root = &app;
    cmd->callback([root, args] { run(*root, *args); });
}

}  // namespace fiblet::cli
