#include "stdio_files.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "fiblet/error.hpp"

namespace fiblet::cli {
namespace {

[[noreturn]] void fail(const std::string& what) {
    throw Error(Errc::io, what + ": " + std::strerror(errno));
}

void copy(int from, int to, const std::string& what) {
    std::vector<char> buf(1 << 20);
    for (;;) {
        const ssize_t n = ::read(from, buf.data(), buf.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) fail(what);
        if (n == 0) return;
        for (ssize_t done = 0; done < n;) {
            const ssize_t w = ::write(to, buf.data() + done, std::size_t(n - done));
            if (w < 0 && errno == EINTR) continue;
            if (w < 0) fail(what);
            done += w;
        }
    }
}

}  // namespace

SpoolFile::SpoolFile(const std::string& suffix) {
    const char* tmp = std::getenv("TMPDIR");
    std::string name = std::string(tmp && *tmp ? tmp : "/tmp") + "/fiblet-stdio-XXXXXX" + suffix;
    const int fd = ::mkstemps(name.data(), int(suffix.size()));
    if (fd < 0) fail("cannot create a temporary file for - in " + name.substr(0, name.rfind('/')));
    pending_.emplace(name);
    ::close(fd);
    path_ = name;
}

SpoolFile::~SpoolFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
}

void SpoolFile::fill_from_stdin() {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    if (!f) fail(path_);
    try {
        copy(STDIN_FILENO, fileno(f), "reading standard input into " + path_);
    } catch (...) {
        std::fclose(f);
        throw;
    }
    if (std::fclose(f) != 0) fail(path_);
}

void SpoolFile::copy_to_stdout() const {
    std::FILE* f = std::fopen(path_.c_str(), "rb");
    if (!f) fail(path_);
    std::fflush(stdout);
    try {
        copy(fileno(f), STDOUT_FILENO, "writing to standard output");
    } catch (...) {
        std::fclose(f);
        throw;
    }
    std::fclose(f);
}

Error named_for_user(const Error& e, const std::optional<SpoolFile>& stdin_spool,
                     const std::optional<SpoolFile>& stdout_spool) {
    std::string message = e.what();
    auto rename = [&](const std::optional<SpoolFile>& spool, const std::string& name) {
        if (!spool) return;
        for (std::size_t at; (at = message.find(spool->path())) != std::string::npos;)
            message.replace(at, spool->path().size(), name);
    };
    rename(stdin_spool, "standard input");
    rename(stdout_spool, "standard output");
    return Error(e.code(), message, e.remedy());
}

CLI::Validator existing_path_or_stdin() {
    return CLI::Validator([](std::string& s) { return is_stdio(s) ? std::string() : CLI::ExistingPath(s); },
                          "PATH or -");
}

std::string readable_path(const std::string& input, const std::string& suffix, std::optional<SpoolFile>& spool) {
    if (!is_stdio(input)) return input;
    spool.emplace(suffix);
    spool->fill_from_stdin();
    return spool->path();
}

std::string writable_path(const std::string& output, const std::string& suffix, std::optional<SpoolFile>& spool) {
    if (!is_stdio(output)) return output;
    spool.emplace(suffix);
    return spool->path();
}

}  // namespace fiblet::cli
