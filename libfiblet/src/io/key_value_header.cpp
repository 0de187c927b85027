#include "io/key_value_header.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace fiblet::detail {
namespace {

// A binary file without newlines or END must not make us read forever.
constexpr std::uint64_t kMaxHeaderBytes = 16u << 20;

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::strchr(" \t\r\v\f", s.front())) s.remove_prefix(1);
    while (!s.empty() && std::strchr(" \t\r\v\f", s.back())) s.remove_suffix(1);
    return s;
}

}  // namespace

std::vector<std::string> KeyValueHeader::all(std::string_view key) const {
    std::vector<std::string> v;
    for (const auto& [k, value] : entries)
        if (k == key) v.push_back(value);
    return v;
}

std::string KeyValueHeader::one(std::string_view key) const {
    const auto v = all(key);
    return v.empty() ? std::string() : v.front();
}

KeyValueHeader read_key_value_header(const std::string& path, std::string_view magic, Errc code,
                                     std::string_view what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    auto fail = [&](const std::string& why) {
        throw Error(code, path + ": invalid " + std::string(what) + " header: " + why);
    };
    KeyValueHeader h;
    in.seekg(0, std::ios::end);
    h.file_size = std::uint64_t(in.tellg());
    in.seekg(0);

    // The magic is checked on its bytes first, so that binary files fail fast.
    std::string first(magic.size(), '\0');
    if (!in.read(first.data(), std::streamsize(first.size())) || first != magic)
        fail("first line is not \"" + std::string(magic) + "\"");
    std::string line;
    std::getline(in, line);
    if (!trim(line).empty()) fail("first line is not \"" + std::string(magic) + "\"");
    std::size_t line_no = 1;
    while (std::getline(in, line)) {
        ++line_no;
        if (std::uint64_t(in.tellg()) > kMaxHeaderBytes) fail("no END line within the first 16 MiB");
        const std::string_view t = trim(line);
        if (t == "END") {
            h.end = std::uint64_t(in.tellg());
            return h;
        }
        const std::size_t colon = t.find(':');
        if (colon == std::string_view::npos) {
            if (t.empty()) continue;
            if (h.entries.empty()) fail("line " + std::to_string(line_no) + " is neither \"key: value\" nor END");
            h.entries.back().second += '\n';
            h.entries.back().second += t;
            continue;
        }
        h.entries.emplace_back(std::string(trim(t.substr(0, colon))), std::string(trim(t.substr(colon + 1))));
    }
    if (in.bad()) throw Error(Errc::io, path + ": read failed: " + std::strerror(errno));
    fail("missing END line");
}

}  // namespace fiblet::detail
