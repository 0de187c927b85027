// Shared helpers of the fiblet subcommands: exit codes, progress, JSON.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/index_format.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::cli {

// Exit codes (documented in docs/tour.md, "Exit codes, in detail", and docs/cli.md).
enum ExitCode : int {
    kOk = 0,
    kInternal = 1,     // a bug: unexpected exception
    kUsage = 2,        // bad command line or option value
    kIo = 3,           // cannot read/write a file
    kBadInput = 4,     // malformed or inconsistent input file
    kExists = 5,       // output exists, --force not given
    kUnsupported = 6,  // valid input fiblet cannot handle
    kChecksum = 7,     // integrity check failed
    kErrorBound = 8,   // a measured error exceeds --max-error (the report is printed, outputs kept)
};
int exit_code_for(Errc c);
// A library error as the CLI says it: the message, and the option that would
// have allowed what failed under its command-line name (Remedy: --force,
// --ignore-trailer, --allow-count-mismatch).
std::string cli_message(const Error& e);
// Every code the CLI returns, with its meaning (for `fiblet help --markdown`).
struct ExitCodeInfo {
    int code;
    const char* meaning;
};
const std::vector<ExitCodeInfo>& exit_code_table();

// --fine-index (compress, extract -o x.fft): the flag that writes the
// block index's version 4 (a box per block) instead of the default version 2.
void add_fine_index_flag(CLI::App* cmd, bool& fine_index);
inline BlockIndexFormat index_format_for(bool fine_index) {
    return fine_index ? BlockIndexFormat::block_boxes : kDefaultBlockIndexFormat;
}

// Progress on stderr, only when stderr is a terminal and not --quiet.
class Progress {
public:
    explicit Progress(bool quiet);
    ~Progress();
    void update(const std::string& label, double fraction);
    void done();

private:
    bool enabled_;
    int last_permille_ = -1;
    std::string last_label_;
};

std::string human_bytes(std::uint64_t bytes);
// A length given in mm, printed in µm with `decimals` decimals from the
// last decimal up to 1 m (every tractogram in millimetres), outside that in
// scientific notation (a file in other units): never a 30-digit number, nor
// 0.00 for an error that is not zero.
std::string micrometres(double mm, int decimals = 2);
// The same number without its unit (for tables whose heading gives it).
std::string micrometres_value(double mm, int decimals = 2);

// Writes one decoded fiber of `n` points. Decoding a valid .fft gives finite
// points, so a NaN or Inf means the input is damaged or hostile: the error
// (Errc::invalid_input) names `input` and the fiber, not the output.
void write_decoded_fiber(TckWriter& writer, const float* xyz, std::uint64_t n, const std::string& input,
                         std::uint64_t fiber);
void write_decoded_fiber(StreamlineSink& sink, const float* xyz, std::uint64_t n, const std::string& input,
                         std::uint64_t fiber);
// The same for every fiber of a decoded chunk whose first is fiber `first`,
// written at once (StreamlineSink::write_chunk: a .tck without a copy);
// without the check when decodes_finite() proved the file's points finite.
void write_decoded_chunk(StreamlineSink& sink, const Streamlines& chunk, const std::string& input, std::uint64_t first,
                         bool proven_finite);

// Minimal JSON object builder (values are numbers, strings, bools or nested
// objects already rendered), keys in insertion order.
class Json {
public:
    Json& num(const std::string& key, double v);
    Json& num(const std::string& key, float v);  // shortest text of the float, not of its double
    Json& integer(const std::string& key, std::uint64_t v);
    Json& str(const std::string& key, const std::string& v);
    Json& boolean(const std::string& key, bool v);
    Json& raw(const std::string& key, const std::string& rendered);
    std::string render() const;

private:
    std::vector<std::pair<std::string, std::string>> fields_;
};
std::string json_quote(const std::string& s);

// Opens a .fft/.fftz input. With `ignore_trailer` (the --ignore-trailer
// flag that add_ignore_trailer_flag() declares) the trailer is left unread,
// and a warning says what that gives up.
FftFile open_fft_input(const std::string& path, bool ignore_trailer);

// Sets the `step_size` a decoded .tck declares: the decoder's step, except
// for resampled input that declared none (raw bundles): its fibers end on a
// fraction of a step (ENDS chunk), and MRtrix takes (points - 1) x step_size
// as a streamline's length where a file declares one (`tckedit -minlength`),
// so the decoded file, like its source, declares none.
void set_decoded_step_size(TckHeader& header, const FftFile& file);
void add_ignore_trailer_flag(CLI::App* cmd, bool& flag);

// --output-dir DIR: created (with its parents) when missing; a file there is a usage error.
void make_output_dir(const std::string& dir);

// -j/--threads N; when not given, from FIBLET_NTHREADS, else from MRtrix3's
// MRTRIX_NTHREADS (0 or unset: all cores). `threads` must outlive the parse.
void add_threads_option(CLI::App* cmd, unsigned& threads, const std::string& what);

// Subcommand registration (one file each).
void add_compress(CLI::App& app);
void add_decompress(CLI::App& app);
void add_stats(CLI::App& app);
void add_info(CLI::App& app);
void add_extract(CLI::App& app);
void add_verify(CLI::App& app);
void add_help(CLI::App& app);
#ifdef FIBLET_WITH_VIEWER
void add_render(CLI::App& app);  // cmd_render.cpp, only with the viewer
void add_view(CLI::App& app);    // cmd_view.cpp, only with the viewer
#endif

}  // namespace fiblet::cli
