#include "input_files.hpp"

#include <algorithm>
#include <filesystem>

#include "cli_common.hpp"
#include "fiblet/error.hpp"

namespace fiblet::cli {
namespace {

namespace fs = std::filesystem;

bool has_extension(const fs::path& p, const std::vector<std::string>& extensions) {
    return std::find(extensions.begin(), extensions.end(), p.extension().string()) != extensions.end();
}

// A directory that is one input (a TRX directory), not a folder of inputs.
bool is_directory_input(const fs::path& p, const FileJobOptions& o) {
    return fs::is_directory(p) && has_extension(p, o.directory_inputs);
}

// The inputs below `dir`, sorted, as paths relative to it.
std::vector<fs::path> files_below(const std::string& dir, const FileJobOptions& o) {
    std::vector<fs::path> found;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        if (is_directory_input(it->path(), o)) {
            found.push_back(fs::relative(it->path(), dir));
            it.disable_recursion_pending();
        } else if (it->is_regular_file() && has_extension(it->path(), o.input_extensions)) {
            found.push_back(fs::relative(it->path(), dir));
        }
    }
    if (ec) throw Error(Errc::io, dir + ": cannot list the directory: " + ec.message());
    std::sort(found.begin(), found.end());
    return found;
}

std::string output_for(const FileJobOptions& o, const fs::path& input, const fs::path& below_dir) {
    fs::path name = input.filename();
    name.replace_extension(o.output_extension);
    if (o.output_dir.empty()) return (input.parent_path() / name).string();
    const fs::path out = fs::path(o.output_dir) / below_dir.parent_path() / name;
    make_output_dir(out.parent_path().string());
    return out.string();
}

}  // namespace

std::vector<FileJob> plan_file_jobs(const std::vector<std::string>& operands, const FileJobOptions& o) {
    if (!o.output_dir.empty()) make_output_dir(o.output_dir);
    std::vector<FileJob> jobs;
    for (std::string operand : operands) {
        while (operand.size() > 1 && operand.back() == '/') operand.pop_back();  // "x.trx/" names x.trx
        if (operand == "-") {  // standard input: no name to derive an output from
            if (o.output.empty()) throw Error(Errc::invalid_argument, "standard input (-) needs -o (- for standard output)");
            jobs.push_back({operand, o.output});
            continue;
        }
        if (!fs::is_directory(operand) || is_directory_input(operand, o)) {
            jobs.push_back({operand, output_for(o, operand, fs::path(operand).filename())});
            continue;
        }
        if (!o.recursive) throw Error(Errc::invalid_argument, operand + " is a directory (-r reads the files below it)");
        const auto below = files_below(operand, o);
        if (below.empty()) throw Error(Errc::invalid_argument, operand + ": no input file below this directory");
        for (const fs::path& rel : below)
            jobs.push_back({(fs::path(operand) / rel).string(), output_for(o, fs::path(operand) / rel, rel)});
    }
    if (!o.output.empty()) {
        if (jobs.size() > 1)
            throw Error(Errc::invalid_argument, "-o names one output: use --output-dir DIR for several inputs");
        jobs[0].output = o.output;
    }
    return jobs;
}

}  // namespace fiblet::cli
