#include "cli_common.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>

namespace fiblet::cli {

std::string cli_message(const Error& e) {
    switch (e.remedy()) {
        case Remedy::overwrite: return std::string(e.what()) + " (use --force to overwrite)";
        case Remedy::ignore_trailer: return std::string(e.what()) + "; --ignore-trailer reads the blocks without it";
        case Remedy::allow_count_mismatch: return std::string(e.what()) + "; --allow-count-mismatch reads it anyway";
        case Remedy::max_memory: return std::string(e.what()) + "; --max-memory SIZE raises the budget";
        case Remedy::none: break;
    }
    return e.what();
}

int exit_code_for(Errc c) {
    switch (c) {
        case Errc::io: return kIo;
        case Errc::tck_format:
        case Errc::trk_format:
        case Errc::trx_format:
        case Errc::fft_format:
        case Errc::invalid_input:
        case Errc::image_format: return kBadInput;
        case Errc::invalid_argument: return kUsage;
        case Errc::exists: return kExists;
        case Errc::unsupported: return kUnsupported;
        case Errc::checksum: return kChecksum;
        case Errc::interrupted: return 130;
    }
    return kInternal;
}

const std::vector<ExitCodeInfo>& exit_code_table() {
    static const std::vector<ExitCodeInfo> table = {
        {kOk, "success"},
        {kInternal, "internal error (a bug: please report it)"},
        {kUsage, "bad command line or option value"},
        {kIo, "a file cannot be read or written"},
        {kBadInput, "malformed or inconsistent input file (.tck, .fft or image)"},
        {kExists, "the output exists and --force was not given"},
        {kUnsupported, "valid input that fiblet does not support"},
        {kChecksum, "integrity check failed"},
        {kErrorBound, "a measured error (point, Hausdorff, endpoint or length change) exceeds --max-error; "
                      "the report is printed and outputs are kept"},
        {130, "interrupted by SIGINT (128 + signal number for other signals, e.g. 153 for SIGXFSZ); no partial output is left"},
    };
    return table;
}

Progress::Progress(bool quiet) : enabled_(!quiet && ::isatty(STDERR_FILENO)) {}
Progress::~Progress() { done(); }

void Progress::update(const std::string& label, double fraction) {
    if (!enabled_) return;
    const int permille = int(std::lround(std::min(std::max(fraction, 0.0), 1.0) * 1000));
    if (permille == last_permille_ && label == last_label_) return;
    last_permille_ = permille, last_label_ = label;
    fmt::print(stderr, "\r{:<40} {:5.1f}%", label, permille / 10.0);
    std::fflush(stderr);
}

void Progress::done() {
    if (enabled_ && last_permille_ >= 0) fmt::print(stderr, "\r{:<48}\r", "");
    last_permille_ = -1;
}

namespace {
void check_decoded_finite(const float* xyz, std::uint64_t n, const std::string& input, std::uint64_t fiber) {
    // Fast path (vectorizes): no value with every exponent bit set (NaN, Inf).
    std::uint32_t bad = 0;
    for (std::uint64_t i = 0; i < 3 * n; ++i) {
        std::uint32_t b;
        std::memcpy(&b, xyz + i, 4);
        bad |= std::uint32_t((b & 0x7f800000u) == 0x7f800000u);
    }
    if (!bad) return;
    for (std::uint64_t i = 0; i < 3 * n; ++i)
        if (!std::isfinite(xyz[i]))
            throw Error(Errc::invalid_input, input + ": fiber " + std::to_string(fiber) +
                                                 " (0-based) decodes to a non-finite coordinate: the file is damaged or "
                                                 "was not written by a fiblet encoder");
}
}  // namespace

void write_decoded_fiber(TckWriter& writer, const float* xyz, std::uint64_t n, const std::string& input,
                         std::uint64_t fiber) {
    check_decoded_finite(xyz, n, input, fiber);
    writer.write(xyz, std::size_t(n));
}

void write_decoded_fiber(StreamlineSink& sink, const float* xyz, std::uint64_t n, const std::string& input,
                         std::uint64_t fiber) {
    check_decoded_finite(xyz, n, input, fiber);
    sink.write(xyz, std::size_t(n));
}

void write_decoded_chunk(StreamlineSink& sink, const Streamlines& chunk, const std::string& input, std::uint64_t first,
                         bool proven_finite) {
    if (proven_finite) return sink.write_finite_chunk(chunk.xyz.data(), chunk.offsets);
    auto check_each = [&] {
        for (std::size_t i = 0; i < chunk.size(); ++i)
            check_decoded_finite(&chunk.xyz[3 * chunk.offsets[i]], chunk.offsets[i + 1] - chunk.offsets[i], input,
                                 first + i);
    };
    if (!sink.refuses_non_finite()) {
        check_each();
        return sink.write_chunk(chunk.xyz.data(), chunk.offsets);
    }
    // A .tck sink checks every point anyway (one pass over the chunk, not
    // two: ~4 % of a decompress); its refusal names the output, so the
    // chunk is checked again to name the input's fiber.
    try {
        sink.write_chunk(chunk.xyz.data(), chunk.offsets);
    } catch (const Error& e) {
        if (e.code() == Errc::invalid_input) check_each();
        throw;
    }
}

std::string human_bytes(std::uint64_t b) {
    if (b < 10000) return fmt::format("{} B", b);
    if (b < 1'000'000) return fmt::format("{:.1f} kB", b / 1e3);
    if (b < 10'000'000'000ull) return fmt::format("{:.2f} MB", b / 1e6);
    return fmt::format("{:.2f} GB", b / 1e9);
}

std::string micrometres_value(double mm, int decimals) {
    const double um = mm * 1e3;
    const double smallest = std::pow(10.0, -decimals);  // below it, fixed notation would print 0.00
    if (um == 0 || (std::fabs(um) >= smallest && std::fabs(um) < 1e6)) return fmt::format("{:.{}f}", um, decimals);
    return fmt::format("{:.3e}", um);
}

std::string micrometres(double mm, int decimals) { return micrometres_value(mm, decimals) + " µm"; }

// Strings come from files (header properties, names) and may hold any
// bytes: invalid UTF-8 becomes U+FFFD, so the output is always valid JSON.
std::string json_quote(const std::string& s) {
    return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// nlohmann::json prints the shortest text that reads back as the same
// double, and NaN or an infinity as null.
Json& Json::num(const std::string& k, double v) { return raw(k, nlohmann::json(v).dump()); }
// A float's shortest text (24.1133, not its double 24.113300323486328): the
// double nearest to that text prints as it.
Json& Json::num(const std::string& k, float v) {
    return num(k, std::isfinite(v) ? std::strtod(fmt::format("{}", v).c_str(), nullptr) : double(v));
}
Json& Json::integer(const std::string& k, std::uint64_t v) { return raw(k, std::to_string(v)); }
Json& Json::str(const std::string& k, const std::string& v) { return raw(k, json_quote(v)); }
Json& Json::boolean(const std::string& k, bool v) { return raw(k, v ? "true" : "false"); }
Json& Json::raw(const std::string& k, const std::string& r) {
    fields_.emplace_back(k, r);
    return *this;
}

std::string Json::render() const {
    std::string out = "{";
    for (std::size_t i = 0; i < fields_.size(); ++i)
        out += (i ? ", " : "") + json_quote(fields_[i].first) + ": " + fields_[i].second;
    return out + "}";
}

FftFile open_fft_input(const std::string& path, bool ignore_trailer) {
    FftFile file(path, {.ignore_trailer = ignore_trailer});
    if (const std::uint64_t n = file.ignored_trailing_bytes())
        fmt::print(stderr,
                   "fiblet: warning: {}: --ignore-trailer: {} bytes after the last block left unread "
                   "(no checksums, source properties, index or kept fiber ends: the blocks are not verified)\n",
                   path, n);
    return file;
}

void add_ignore_trailer_flag(CLI::App* cmd, bool& flag) {
    cmd->add_flag("--ignore-trailer", flag,
                  "Read only the header, LUT and blocks, not the trailer after them: salvages a file whose "
                  "trailer is damaged (nothing is then verified by checksum)");
}

void make_output_dir(const std::string& dir) {
    std::error_code ec;
    if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
        throw Error(Errc::invalid_argument, dir + ": --output-dir names a file, not a directory");
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error(Errc::io, dir + ": cannot create the --output-dir directory: " + ec.message());
}

void add_threads_option(CLI::App* cmd, unsigned& threads, const std::string& what) {
    CLI::Option* option = cmd->add_option(
        "-j,--threads", threads, what + " threads (default: FIBLET_NTHREADS, else MRTRIX_NTHREADS, else all cores)");
    // Read here rather than by CLI11's envname, so that a bad value names its variable.
    cmd->parse_complete_callback([option, &threads] {
        if (option->count() > 0) return;
        for (const char* name : {"FIBLET_NTHREADS", "MRTRIX_NTHREADS"}) {
            const char* value = std::getenv(name);
            if (!value) continue;
            char* end = nullptr;
            errno = 0;
            const unsigned long long n = std::strtoull(value, &end, 10);
            if (!*value || *end || errno || value[0] == '-' || n > std::numeric_limits<unsigned>::max())
                throw Error(Errc::invalid_argument, std::string(name) + "='" + value +
                                                        "' is not a thread count (a whole number, 0 for all cores)");
            threads = unsigned(n);
            return;
        }
    });
}

void set_decoded_step_size(TckHeader& header, const FftFile& file) {
    const FftHeader& h = file.header();
    if (file.resampling() && !header.get("step_size")) return;
    header.set("step_size", fmt::format("{:.9g}", double(h.step) * double(h.scaling)));
}

void add_fine_index_flag(CLI::App* cmd, bool& fine_index) {
    cmd->add_flag("--fine-index", fine_index,
                  "Write the finer block index (BIDX version 4, a box per block): fewer candidate blocks for "
                  "selections, but about 5x slower to load (e.g. 32 ms against 6 ms); for viewers and "
                  "long-lived sessions (formats/fft-index.md)");
}

}  // namespace fiblet::cli
