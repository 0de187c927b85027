// MRtrix3 key-value text headers (.tck, .mif): read in growing blocks from
// a file descriptor, so that a binary file without newlines fails fast and in
// bounded memory.
#include "io/key_value_header.hpp"
#include "io/regular_input.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>

namespace fiblet::detail {
namespace {

// A garbage file without newlines or END must not make us read forever.
constexpr std::size_t kMaxHeaderBytes = 16u << 20;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

[[noreturn]] void fail(const std::string& path, Errc code, std::string_view what, const std::string& why) {
    throw Error(code, path + ": invalid " + std::string(what) + " header: " + why);
}

struct Fd {
    int fd = -1;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

// The file's lines, read on demand in blocks that double in size.
class LineReader {
public:
    LineReader(const std::string& path, int fd) : path_(path), fd_(fd) {}

    // Reads until `n` bytes are buffered or the file ends.
    void fill(std::size_t n) {
        while (buf_.size() < n && read_more()) {
        }
    }
    const std::string& buffer() const { return buf_; }
    // Next line (without its newline); nullopt at end of file. `fail` is
    // called when no newline comes within the size limit.
    template <class Fail>
    std::optional<std::string_view> next(const Fail& fail) {
        for (;;) {
            const std::size_t nl = buf_.find('\n', line_start_);
            if (nl != std::string::npos) {
                std::string_view line(buf_.data() + line_start_, nl - line_start_);
                line_start_ = nl + 1;
                return line;
            }
            if (buf_.size() > kMaxHeaderBytes) fail("no END line within the first 16 MiB");
            if (!read_more()) {
                if (line_start_ >= buf_.size()) return std::nullopt;
                std::string_view line(buf_.data() + line_start_, buf_.size() - line_start_);
                line_start_ = buf_.size();
                return line;
            }
        }
    }
    std::size_t consumed() const { return line_start_; }

private:
    bool read_more() {
        if (eof_) return false;
        // Small reads first (headers are a few kB), doubling for long ones.
        const std::size_t block = std::max<std::size_t>(4096, buf_.size());
        const std::size_t old = buf_.size();
        buf_.resize(old + block);
        ssize_t n;
        do {
            n = ::read(fd_, buf_.data() + old, block);
        } while (n < 0 && errno == EINTR);
        if (n < 0) throw Error(Errc::io, path_ + ": read failed: " + std::strerror(errno));
        buf_.resize(old + std::size_t(n));
        if (n == 0) eof_ = true;
        return n > 0;
    }

    const std::string& path_;
    int fd_;
    std::string buf_;  // bytes read so far (at most kMaxHeaderBytes + one block)
    std::size_t line_start_ = 0;
    bool eof_ = false;
};

}  // namespace

std::string_view trim_header_text(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

std::vector<std::string> KeyValueHeader::all(std::string_view key) const {
    std::vector<std::string> v;
    for (const KeyValueEntry& e : entries)
        if (e.key == key) v.push_back(e.value);
    return v;
}

std::string KeyValueHeader::one(std::string_view key) const {
    for (const KeyValueEntry& e : entries)
        if (e.key == key) return e.value;
    return {};
}

KeyValueHeader read_key_value_header(const std::string& path, std::string_view magic, Errc code,
                                     std::string_view what) {
    auto bad = [&](const std::string& why) { fail(path, code, what, why); };
    Fd f;
    detail::require_regular_input(path);
    f.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (f.fd < 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(f.fd, &st) != 0) throw Error(Errc::io, path + ": cannot stat: " + std::strerror(errno));
    KeyValueHeader h;
    h.file_size = std::uint64_t(st.st_size);

    LineReader in(path, f.fd);
    // The magic is checked on its bytes before looking for a newline, so binary files fail fast.
    const std::string first_line = "first line is not \"" + std::string(magic) + "\"";
    in.fill(magic.size());
    if (in.buffer().compare(0, magic.size(), magic) != 0) bad(first_line);
    const auto first = in.next(bad);
    if (!first || trim_header_text(*first) != magic) bad(first_line);

    std::string malformed;  // first malformed line, reported once END is found
    std::size_t line_no = 1;
    while (const auto raw = in.next(bad)) {
        ++line_no;
        const std::string_view line = trim_header_text(*raw);
        if (line == "END") {
            if (!malformed.empty()) bad(malformed);
            h.end = in.consumed();
            return h;
        }
        const std::size_t colon = line.find(':');
        if (colon == std::string_view::npos) {
            if (line.empty()) continue;
            if (h.entries.empty()) {
                if (malformed.empty())
                    malformed = "line " + std::to_string(line_no) + " is neither \"key: value\" nor END";
                continue;
            }
            KeyValueEntry& last = h.entries.back();
            last.value += '\n';
            last.value += line;
            last.continued = true;
            continue;
        }
        h.entries.push_back({std::string(trim_header_text(line.substr(0, colon))),
                             std::string(trim_header_text(line.substr(colon + 1))), line_no, false});
    }
    fail(path, code, what, "missing END line");
}

}  // namespace fiblet::detail
