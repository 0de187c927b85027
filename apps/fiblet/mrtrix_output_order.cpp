#include "mrtrix_output_order.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

#include "command_words.hpp"

namespace fiblet::cli {
namespace {

bool names_fft(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".fft" || ext == ".fftz";
}

bool exists(const std::string& path) {
    std::error_code ec;  // a dangling symbolic link exists too
    return std::filesystem::exists(std::filesystem::symlink_status(path, ec));
}

}  // namespace

std::vector<std::string> mrtrix_output_order(const CLI::App& app, std::vector<std::string> args) {
    using Kind = CommandWord::Kind;
    const std::vector<CommandWord> words = classify_words(app, args);
    const auto command = std::find_if(words.begin(), words.end(), [](const CommandWord& w) {
        return w.kind == Kind::subcommand && w.app->get_name() == "compress";
    });
    if (command == words.end()) return args;
    const CLI::App& compress = *command->app;
    const CLI::Option* refusing[] = {compress.get_option_no_throw("--output"), compress.get_option_no_throw("--output-dir"),
                                     compress.get_option_no_throw("--recursive")};
    std::vector<std::size_t> operands;
    for (std::size_t i = 0; i < args.size(); ++i) {
        if (words[i].app != &compress) continue;
        if (words[i].kind == Kind::operand) operands.push_back(i);
        if (words[i].kind == Kind::option &&
            std::ranges::find(refusing, compress.get_option_no_throw(option_name(args[i]))) != std::end(refusing))
            return args;
    }
    if (operands.size() != 2 || !names_fft(args[operands[1]]) || exists(args[operands[1]])) return args;
    const std::string output = "--output=" + args[operands[1]];
    args.erase(args.begin() + std::ptrdiff_t(operands[1]));
    args.insert(args.begin() + std::ptrdiff_t(command - words.begin()) + 1, output);
    return args;
}

}  // namespace fiblet::cli
