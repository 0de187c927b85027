#include "cli_common.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace fiblet::cli {

int exit_code_for(Errc c) {
    switch (c) {
        case Errc::io: return kIo;
        case Errc::tck_format:
        case Errc::trk_format:
        case Errc::trx_format:
        case Errc::fft_format:
        case Errc::invalid_input: return kBadInput;
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
        {kBadInput, "malformed or inconsistent input file (.tck or .fft)"},
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

namespace {

// Length of the well-formed UTF-8 sequence at s[i] (RFC 3629: shortest form,
// no surrogates, at most U+10FFFF), or 0 if the bytes there are not one.
std::size_t utf8_sequence_length(const std::string& s, std::size_t i) {
    const auto byte = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
    const unsigned b0 = byte(i);
    const auto cont = [&](std::size_t k) { return (byte(k) & 0xC0u) == 0x80u; };
    if (b0 < 0x80) return 1;
    if (b0 >= 0xC2 && b0 <= 0xDF) return cont(i + 1) ? 2 : 0;
    if (b0 >= 0xE0 && b0 <= 0xEF) {
        const unsigned b1 = byte(i + 1);
        const bool ok1 = b0 == 0xE0 ? (b1 >= 0xA0 && b1 <= 0xBF) : b0 == 0xED ? (b1 >= 0x80 && b1 <= 0x9F) : cont(i + 1);
        return ok1 && cont(i + 2) ? 3 : 0;
    }
    if (b0 >= 0xF0 && b0 <= 0xF4) {
        const unsigned b1 = byte(i + 1);
        const bool ok1 = b0 == 0xF0 ? (b1 >= 0x90 && b1 <= 0xBF) : b0 == 0xF4 ? (b1 >= 0x80 && b1 <= 0x8F) : cont(i + 1);
        return ok1 && cont(i + 2) && cont(i + 3) ? 4 : 0;
    }
    return 0;
}

}  // namespace

// Strings come from files (header properties, names) and may hold any
// bytes: invalid UTF-8 becomes U+FFFD, so the output is always valid JSON.
std::string json_quote(const std::string& s) {
    std::string out = "\"";
    for (std::size_t i = 0; i < s.size();) {
        const unsigned char ch = static_cast<unsigned char>(s[i]);
        const std::size_t n = utf8_sequence_length(s, i);
        if (n == 0) {
            out += "\\ufffd";
            ++i;
            continue;
        }
        if (n > 1) {
            out.append(s, i, n);
            i += n;
            continue;
        }
        switch (ch) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            default:
                if (ch < 0x20 || ch == 0x7f) out += fmt::format("\\u{:04x}", ch);
                else out += char(ch);
        }
        ++i;
    }
    return out + "\"";
}

Json& Json::num(const std::string& k, double v) {
    return raw(k, std::isfinite(v) ? fmt::format("{:.9g}", v) : "null");
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

}  // namespace fiblet::cli
