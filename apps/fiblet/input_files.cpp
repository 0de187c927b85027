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
    if (!fs::is_directory(p)) return false;
    std::error_code ec;
    return has_extension(p, o.directory_inputs) ||
           (!o.directory_marker.empty() && fs::is_regular_file(p / o.directory_marker, ec));
}

// The inputs below `dir`, sorted, as paths relative to it.
std::vector<fs::path> files_below(const std::string& dir, const FileJobOptions& o) {
    std::vector<fs::path> found;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        // Lexically: a symlinked input maps to the link's own path below
        // `dir` (fs::relative would follow it, and its target's path may
        // climb out of --output-dir with "..").
        if (is_directory_input(it->path(), o)) {
            found.push_back(it->path().lexically_relative(dir));
            it.disable_recursion_pending();
        } else if (it->is_regular_file() && has_extension(it->path(), o.input_extensions)) {
            found.push_back(it->path().lexically_relative(dir));
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
    return (fs::path(o.output_dir) / below_dir.parent_path() / name).string();
}

// Two inputs that would write one output (x.tck and x.trk in a folder, or
// a/x.trk and b/x.trk into one --output-dir) are refused before anything is
// written: the second would overwrite the first (-f) or fail on it.
void check_distinct_outputs(const std::vector<FileJob>& jobs) {
    std::vector<std::pair<std::string, const FileJob*>> outputs;
    for (const FileJob& j : jobs) outputs.emplace_back(fs::path(j.output).lexically_normal().string(), &j);
    std::stable_sort(outputs.begin(), outputs.end(), [](auto& a, auto& b) { return a.first < b.first; });
    std::string clashes;
    for (std::size_t i = 1; i < outputs.size(); ++i)
        if (outputs[i].first == outputs[i - 1].first)
            clashes += "\n  " + outputs[i - 1].second->input + " and " + outputs[i].second->input + " -> " + outputs[i].first;
    if (!clashes.empty())
        throw Error(Errc::invalid_argument, "several inputs would write the same output (rename one, or use -o):" + clashes);
}

}  // namespace

std::vector<FileJob> plan_file_jobs(const std::vector<std::string>& operands, const FileJobOptions& o) {
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
    check_distinct_outputs(jobs);
    // Only now, with every output known and distinct: the folders they go to.
    if (!o.output_dir.empty()) {
        make_output_dir(o.output_dir);
        for (const FileJob& j : jobs) make_output_dir(fs::path(j.output).parent_path().string());
    }
    return jobs;
}

}  // namespace fiblet::cli
