// MRtrix3 .tck header: parsing and the TckHeader accessors.
#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "io/key_value_header.hpp"
#include "tractogram/tck/track_header.hpp"

namespace fiblet {
namespace {

constexpr std::string_view kMagic = "mrtrix tracks";

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
std::string_view trim(std::string_view s) { return detail::trim_header_text(s); }

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

TckHeader read_tck_header(const std::string& path) { return detail::read_track_header(path, kMagic, ".tck"); }

namespace detail {

TckHeader read_track_header(const std::string& path, std::string_view magic, std::string_view what) {
    const KeyValueHeader kv = read_key_value_header(path, magic, Errc::tck_format, what);
    auto fail = [&](const std::string& why) {
        throw Error(Errc::tck_format, path + ": invalid " + std::string(what) + " header: " + why);
    };
    const std::uint64_t file_size = kv.file_size;
    TckHeader h;  // no datatype entry: Float32LE, what MRtrix writes by default
    std::optional<std::uint64_t> offset;
    for (const KeyValueEntry& e : kv.entries) {
        const bool parsed = e.key == "file" || e.key == "datatype";
        if (parsed && e.continued) fail("line " + std::to_string(e.line + 1) + " continues a file/datatype entry");
        if (e.key == "file") {
            offset = parse_file_entry(e.value);
            if (!offset) fail("bad \"file:\" entry \"" + e.value + "\" (expected \". OFFSET\")");
        } else if (e.key == "datatype") {
            const auto t = parse_datatype(e.value);
            if (!t)
                throw Error(Errc::unsupported, path + ": unsupported " + std::string(what) + " datatype \"" + e.value +
                                                   "\" (supported: Float32LE, Float32BE, Float64LE, Float64BE)");
            h.datatype = *t;
        } else {
            h.properties.emplace_back(e.key, e.value);
        }
    }
    if (!offset) fail("missing \"file: . OFFSET\" entry");
    const std::uint64_t header_end = kv.end;
    if (*offset < header_end)
        fail("data offset " + std::to_string(*offset) + " lies inside the header (which ends at byte " +
                       std::to_string(header_end) + ")");
    if (*offset > file_size)
        fail("data offset " + std::to_string(*offset) + " is past the end of the file (" +
                       std::to_string(file_size) + " bytes)");
    h.data_offset = *offset;
    return h;
}

}  // namespace detail
}  // namespace fiblet
