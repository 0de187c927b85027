#include "cli_reference.hpp"

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

}  // namespace fiblet::cli
