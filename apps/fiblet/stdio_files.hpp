// `-` as an input or output file means standard input or output, as in
// MRtrix3 and zstd. The library reads and writes seekable files (a .tck's
// count and an .fft's index are written last, at their place), so the data
// is spooled through a temporary file in $TMPDIR (removed afterwards):
// stdin is copied to it before the command reads it, the output is copied
// to stdout once complete — a pipe never receives half a file.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <string>

#include "fiblet/error.hpp"
#include "fiblet/output_file.hpp"

namespace fiblet::cli {

inline bool is_stdio(const std::string& path) { return path == "-"; }

// A temporary file named ...`suffix` (e.g. ".tck"), removed by the destructor.
class SpoolFile {
public:
    explicit SpoolFile(const std::string& suffix);
    ~SpoolFile();
    SpoolFile(const SpoolFile&) = delete;
    SpoolFile& operator=(const SpoolFile&) = delete;
    const std::string& path() const { return path_; }
    void fill_from_stdin();    // Error{io} on a read or write failure
    void copy_to_stdout() const;

private:
    std::string path_;
    std::optional<PendingTemporary> pending_;  // removed on a fatal signal too
};

// The file to read for `input`: itself, or for `-` a spool filled from stdin.
std::string readable_path(const std::string& input, const std::string& suffix, std::optional<SpoolFile>& spool);
// The file to write for `output`: itself, or for `-` a spool (copy_to_stdout() once complete).
std::string writable_path(const std::string& output, const std::string& suffix, std::optional<SpoolFile>& spool);

// `e` with the spools' temporary names replaced by what the user gave:
// "standard input" / "standard output" (an error about bad input on `-`
// named /tmp/fiblet-stdio-XXXXXX.tck, a file the user never saw).
Error named_for_user(const Error& e, const std::optional<SpoolFile>& stdin_spool,
                     const std::optional<SpoolFile>& stdout_spool);

// CLI11 check of an input operand: an existing path, or - (standard input).
CLI::Validator existing_path_or_stdin();

// Where a command's report goes: stdout, unless the data itself goes there.
inline std::FILE* report_stream(const std::string& output) { return is_stdio(output) ? stderr : stdout; }

}  // namespace fiblet::cli
