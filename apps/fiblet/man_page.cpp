// fiblet(1): the CLI reference as a roff man page (`fiblet help --man`).
#include <fmt/core.h>

#include "cli_common.hpp"
#include "cli_reference.hpp"

namespace fiblet::cli {
namespace {

// roff: a backslash is written \e, a dash \-; a line starting with . or ' would be a request.
std::string roff(const std::string& s) {
    std::string out;
    for (char c : s) out += c == '\\' ? std::string("\\e") : c == '-' ? std::string("\\-") : std::string(1, c);
    if (!out.empty() && (out[0] == '.' || out[0] == '\'')) out.insert(0, "\\&");
    return out;
}

std::string option_names(const CLI::Option* o) {
    if (o->get_positional() && !o->nonpositional()) return "\\fI" + roff(o->get_name(true)) + "\\fR";
    std::string names;
    for (const std::string& s : o->get_snames()) names += (names.empty() ? "" : ", ") + ("\\fB\\-" + s + "\\fR");
    for (const std::string& l : o->get_lnames()) names += (names.empty() ? "" : ", ") + ("\\fB\\-\\-" + roff(l) + "\\fR");
    const std::string value = option_value(o);
    return value.empty() ? names : names + " \\fI" + roff(value) + "\\fR";
}

}  // namespace

std::string man_page(CLI::App& app) {
    std::string m = fmt::format(".TH FIBLET 1 \"\" \"fiblet {}\" \"User Commands\"\n", FIBLET_VERSION);
    m += ".SH NAME\nfiblet \\- " + roff(app.get_description().substr(app.get_description().find(':') + 2)) + "\n";
    m += ".SH SYNOPSIS\n";
    for (CLI::App* cmd : subcommands(app)) m += ".B " + roff(usage_line(cmd)) + "\n.br\n";
    m += ".SH DESCRIPTION\n" + roff(app.get_description()) + ".\n";
    m += ".PP\nOptions are written as in GNU tools (\\fB\\-o\\fR \\fIFILE\\fR, \\fB\\-\\-force\\fR); MRtrix3's "
         "single-dash spellings of the options fiblet has (\\fB\\-force\\fR, \\fB\\-quiet\\fR, "
         "\\fB\\-nthreads\\fR \\fIN\\fR, \\fB\\-minlength\\fR ...) are accepted, and any other single-dash word "
         "is an error that names the option meant.\n";
    for (CLI::App* cmd : subcommands(app)) {
        m += ".SH " + roff("fiblet " + cmd->get_name()) + "\n" + roff(cmd->get_description()) + ".\n";
        for (const CLI::Option* o : documented_options(cmd))
            m += ".TP\n" + option_names(o) + "\n" + roff(option_description(o)) + "\n";
    }
    m += ".SH ENVIRONMENT\n.TP\n.B FIBLET_NTHREADS\nThreads of compress and decompress when \\fB\\-\\-threads\\fR "
         "is not given.\n.TP\n.B MRTRIX_NTHREADS\nThe same, when FIBLET_NTHREADS is not set.\n";
    m += ".SH EXIT STATUS\n";
    for (const ExitCodeInfo& e : exit_code_table()) m += fmt::format(".TP\n.B {}\n{}\n", e.code, roff(e.meaning));
    m += ".SH EXAMPLES\n";
    for (const CliExample& e : cli_examples(app)) m += ".PP\n" + roff(e.what) + ":\n.RS\n.B " + roff(e.command) + "\n.RE\n";
    m += ".SH SEE ALSO\n.BR tckinfo (1),\n.BR tckedit (1),\n.BR zstd (1)\n";
    return m;
}

}  // namespace fiblet::cli
