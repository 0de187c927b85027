#include "cli_reference.hpp"

#include <set>
#include <string>

namespace fiblet::cli {

std::vector<CLI::App*> subcommands(CLI::App& app) {
    return app.get_subcommands([](CLI::App*) { return true; });
}

std::vector<const CLI::Option*> documented_options(const CLI::App* cmd) {
    std::vector<const CLI::Option*> out;
    for (const CLI::Option* o : cmd->get_options())
        if (!o->get_group().empty() && o != cmd->get_help_ptr()) out.push_back(o);
    return out;
}

std::string option_value(const CLI::Option* o) {
    if (o->get_type_size_max() == 0) return "";  // a flag
    std::string t = o->get_type_name();
    if (o->get_items_expected_max() > 1) t += " ...";
    return t;
}

std::string option_description(const CLI::Option* o) {
    std::string description = o->get_description();
    if (!o->get_default_str().empty()) description += " (default: " + o->get_default_str() + ")";
    if (o->get_required()) description += " (required)";
    return description;
}

std::string usage_line(const CLI::App* cmd) {
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

std::vector<CliExample> cli_examples(CLI::App& app) {
    static const CliExample all[] = {
        {"Compress a tractogram (the official .fft layout; the report names the error)",
         "fiblet compress tracks.tck -o tracks.fft"},
        {"Compress a cohort's tree into another, in parallel, as the seekable zstd container",
         "fiblet compress -r subjects/ --output-dir compressed/ -z -j 8"},
        {"Decode back to MRtrix3's .tck (or .trk, TRX: the output's name says which)", "fiblet decompress tracks.fft -o tracks.tck"},
        {"Keep the fibers through two regions, as tckedit -include", "fiblet extract tracks.fft -o af.tck --include "
                                                                   "-40,-10,20,8 --include wm_mask.nii.gz"},
        {"The first 1000 fibers longer than 50 mm, as tckedit -number 1000 -minlength 50",
         "fiblet extract tracks.fft -o long.tck --min-length 50 --number 1000"},
        {"Check a file's integrity, and its error against the source", "fiblet verify tracks.fft && fiblet stats "
                                                                       "tracks.fft --reference tracks.tck"},
        {"Draw it as ray-cast tubes to a PNG, without a window", "fiblet render tracks.fft --style tubes -o tracks.png"},
        {"Explore it in a window, with the FOD glyphs of a slice", "fiblet view tracks.fft --odf fod.mif --odf-slice z:40"},
    };
    std::set<std::string> built;
    for (const CLI::App* cmd : subcommands(app)) built.insert(cmd->get_name());
    // Every word after "fiblet " must be a command of this build.
    auto runs_here = [&](const std::string& command) {
        for (std::size_t at = 0; (at = command.find("fiblet ", at)) != std::string::npos; at += 7) {
            const std::size_t from = at + 7;
            if (!built.count(command.substr(from, command.find(' ', from) - from))) return false;
        }
        return true;
    };
    std::vector<CliExample> examples;
    for (const CliExample& e : all)
        if (runs_here(e.command)) examples.push_back(e);
    return examples;
}

}  // namespace fiblet::cli
