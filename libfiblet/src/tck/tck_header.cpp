// MRtrix3 .tck header: parsing and the TckHeader accessors.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"

namespace fiblet {
namespace {

// A garbage file without newlines or END must not make us read forever.
constexpr std::size_t kMaxHeaderBytes = 16u << 20;
constexpr std::string_view kMagic = "mrtrix tracks";

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; };
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

// Whole string must be a non-negative decimal integer (leading zeros allowed).
std::optional<std::uint64_t> parse_u64(std::string_view s) {
    if (s.empty()) return std::nullopt;
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return v;
}

std::optional<TckDataType> parse_datatype(std::string_view s) {
    // MRtrix parses datatype names case-insensitively.
    if (iequals(s, "Float32LE")) return TckDataType::float32le;
    if (iequals(s, "Float32BE")) return TckDataType::float32be;
    if (iequals(s, "Float64LE")) return TckDataType::float64le;
    if (iequals(s, "Float64BE")) return TckDataType::float64be;
    return std::nullopt;
}

// "file: . OFFSET": the data lives in this file ("."), at byte OFFSET.
std::optional<std::uint64_t> parse_file_entry(std::string_view v) {
    if (v.empty() || v.front() != '.') return std::nullopt;
    v.remove_prefix(1);
    if (v.empty() || !is_space(v.front())) return std::nullopt;
    return parse_u64(trim(v));
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw Error(Errc::tck_format, path + ": invalid .tck header: " + what);
}

struct Fd {
    int fd = -1;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

}  // namespace

const char* tck_datatype_name(TckDataType t) noexcept {
    switch (t) {
        case TckDataType::float32le: return "Float32LE";
        case TckDataType::float32be: return "Float32BE";
        case TckDataType::float64le: return "Float64LE";
        case TckDataType::float64be: return "Float64BE";
    }
    return "unknown";
}

std::optional<std::string> TckHeader::get(const std::string& key) const {
    for (const auto& [k, v] : properties)
        if (k == key) return v;
    return std::nullopt;
}

void TckHeader::set(const std::string& key, const std::string& value) {
    auto first = std::find_if(properties.begin(), properties.end(), [&](const auto& kv) { return kv.first == key; });
    if (first == properties.end()) {
        properties.emplace_back(key, value);
        return;
    }
    first->second = value;
    // Keep the first entry where it was, drop the later duplicates.
    properties.erase(std::remove_if(first + 1, properties.end(), [&](const auto& kv) { return kv.first == key; }),
                     properties.end());
}

void TckHeader::erase(const std::string& key) {
    std::erase_if(properties, [&](const auto& kv) { return kv.first == key; });
}

std::optional<std::uint64_t> TckHeader::count() const {
    const auto v = get("count");
    if (!v) return std::nullopt;
    return parse_u64(trim(*v));
}

std::optional<double> TckHeader::step_size() const {
    const auto v = get("step_size");
    if (!v) return std::nullopt;
    const std::string_view s = trim(*v);
    double d = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), d);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(d) || d <= 0)
        return std::nullopt;
    return d;
}

TckHeader read_tck_header(const std::string& path) {
    Fd f;
    f.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (f.fd < 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(f.fd, &st) != 0) throw Error(Errc::io, path + ": cannot stat: " + std::strerror(errno));
    const std::uint64_t file_size = std::uint64_t(st.st_size);

    std::string buf;        // bytes read so far (at most kMaxHeaderBytes + one block)
    std::size_t line_start = 0;
    bool eof = false;
    // Reads another block; returns false at end of file.
    auto read_more = [&]() {
        if (eof) return false;
        // Small reads first (headers are a few kB), doubling for long ones.
        const std::size_t block = std::max<std::size_t>(4096, buf.size());
        const std::size_t old = buf.size();
        buf.resize(old + block);
        ssize_t n;
        do {
            n = ::read(f.fd, buf.data() + old, block);
        } while (n < 0 && errno == EINTR);
        if (n < 0) throw Error(Errc::io, path + ": read failed: " + std::strerror(errno));
        buf.resize(old + std::size_t(n));
        if (n == 0) eof = true;
        return n > 0;
    };
    // Next line (without its newline) and the offset just past it; nullopt at end of file.
    auto next_line = [&]() -> std::optional<std::string_view> {
        for (;;) {
            const std::size_t nl = buf.find('\n', line_start);
            if (nl != std::string::npos) {
                std::string_view line(buf.data() + line_start, nl - line_start);
                line_start = nl + 1;
                return line;
            }
            if (buf.size() > kMaxHeaderBytes)
                fail(path, "no END line within the first " + std::to_string(kMaxHeaderBytes >> 20) +
                               " MiB (not a .tck file?)");
            if (!read_more()) {
                if (line_start >= buf.size()) return std::nullopt;
                std::string_view line(buf.data() + line_start, buf.size() - line_start);
                line_start = buf.size();
                return line;
            }
        }
    };

    // Check the magic before looking for a newline, so binary files fail fast.
    while (buf.size() < kMagic.size() && read_more()) {
    }
    if (buf.compare(0, kMagic.size(), kMagic) != 0) fail(path, "first line is not \"mrtrix tracks\"");
    const auto first = next_line();
    if (!first || trim(*first) != kMagic) fail(path, "first line is not \"mrtrix tracks\"");

    TckHeader h;  // no datatype entry: Float32LE, what MRtrix writes by default
    std::optional<std::uint64_t> offset;
    bool found_end = false;
    std::string malformed;  // first malformed line, if any
    // Where a continuation line goes: the last key's entry in `properties`, or a parsed field.
    enum class Last { none, property, parsed } last = Last::none;
    std::size_t line_no = 1;
    while (const auto raw = next_line()) {
        ++line_no;
        const std::string_view line = trim(*raw);
        if (line == "END") {
            found_end = true;
            break;
        }
        const std::size_t colon = line.find(':');
        if (colon == std::string_view::npos) {
            if (line.empty()) continue;
            // A line without ':' continues the previous value (as MRtrix and nibabel read it).
            // Errors here are reported only if END is found: data bytes after a header
            // without END would otherwise hide that simpler diagnosis.
            if (last != Last::property) {
                if (malformed.empty())
                    malformed = "line " + std::to_string(line_no) +
                                (last == Last::none ? " is neither \"key: value\" nor END"
                                                    : " continues a file/datatype entry");
                continue;
            }
            h.properties.back().second += '\n';
            h.properties.back().second += line;
            continue;
        }
        const std::string_view key = trim(line.substr(0, colon));
        const std::string_view value = trim(line.substr(colon + 1));
        if (key == "file") {
            offset = parse_file_entry(value);
            if (!offset) fail(path, "bad \"file:\" entry \"" + std::string(value) + "\" (expected \". OFFSET\")");
            last = Last::parsed;
        } else if (key == "datatype") {
            const auto t = parse_datatype(value);
            if (!t)
                throw Error(Errc::unsupported, path + ": unsupported .tck datatype \"" + std::string(value) +
                                                   "\" (supported: Float32LE, Float32BE, Float64LE, Float64BE)");
            h.datatype = *t;
            last = Last::parsed;
        } else {
            h.properties.emplace_back(std::string(key), std::string(value));
            last = Last::property;
        }
    }
    if (!found_end) fail(path, "missing END line");
    if (!malformed.empty()) fail(path, malformed);
    if (!offset) fail(path, "missing \"file: . OFFSET\" entry");
    const std::uint64_t header_end = line_start;
    if (*offset < header_end)
        fail(path, "data offset " + std::to_string(*offset) + " lies inside the header (which ends at byte " +
                       std::to_string(header_end) + ")");
    if (*offset > file_size)
        fail(path, "data offset " + std::to_string(*offset) + " is past the end of the file (" +
                       std::to_string(file_size) + " bytes)");
    h.data_offset = *offset;
    return h;
}

}  // namespace fiblet
