#include "io/output_target.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "fiblet/error.hpp"
#include "io/open_inputs.hpp"

namespace fiblet::detail {
namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
    throw Error(Errc::invalid_argument, path + ": " + why);
}

const char* refused_kind(mode_t mode) {
    if (S_ISDIR(mode)) return "is a directory";
    if (S_ISFIFO(mode))
        return "is a FIFO (named pipe): fiblet seeks back to finish its outputs, write a regular file instead";
    if (S_ISSOCK(mode)) return "is a socket: write a regular file instead";
    if (S_ISBLK(mode)) return "is a block device: fiblet does not write onto disks, write a regular file instead";
    return nullptr;
}

// The final target of a symbolic link (all links in the chain followed).
std::string follow_link(const std::string& path) {
    std::unique_ptr<char, decltype(&std::free)> real(::realpath(path.c_str(), nullptr), &std::free);
    if (real) return real.get();
    if (errno == ENOENT) refuse(path, "is a symbolic link to a missing file: name the file itself");
    throw Error(Errc::io, path + ": cannot follow the symbolic link: " + std::strerror(errno));
}

}  // namespace

OutputTarget resolve_output_target(const std::string& path) {
    OutputTarget t{path, false, false};
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) {
        if (errno == ENOENT) return t;
        throw Error(Errc::io, path + ": cannot examine the output: " + std::strerror(errno));
    }
    if (S_ISLNK(st.st_mode)) {
        if (::stat(path.c_str(), &st) != 0) {
            if (errno == ENOENT) refuse(path, "is a symbolic link to a missing file: name the file itself");
            throw Error(Errc::io, path + ": cannot examine the output: " + std::strerror(errno));
        }
        // A regular file gets replaced: by its own name, so the link stays.
        // Anything else (/dev/stdout -> a terminal or a pipe) is opened or
        // refused through the link, which /proc's links need (pipe:[N] is no path).
        if (S_ISREG(st.st_mode)) t.path = follow_link(path);
    }
    t.exists = true;
    if (const char* why = refused_kind(st.st_mode)) refuse(path, why);
    refuse_open_input(st.st_dev, st.st_ino, path);
    t.write_through = S_ISCHR(st.st_mode);
    return t;
}

void recheck_output_target(const OutputTarget& target, const std::string& shown_name) {
    struct stat st {};
    if (::lstat(target.path.c_str(), &st) != 0) return;  // gone or never there: the rename creates it
    if (S_ISLNK(st.st_mode)) refuse(shown_name, "became a symbolic link while it was written: not replaced");
    if (const char* why = refused_kind(st.st_mode)) refuse(shown_name, why);
    if (S_ISCHR(st.st_mode)) refuse(shown_name, "became a device while it was written: not replaced");
    refuse_open_input(st.st_dev, st.st_ino, shown_name);
}

std::string temporary_name_for(const std::string& path, const std::string& suffix) {
    const std::size_t slash = path.rfind('/');
    const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
    const std::string prefix = slash == std::string::npos ? "" : path.substr(0, slash + 1);
    std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
    const long limit = ::pathconf(dir.c_str(), _PC_NAME_MAX);
    const std::size_t name_max = limit > 0 ? std::size_t(limit) : NAME_MAX;
    // Shortened by bytes: the name is only read by people and cleanup globs
    // (*.tmp-*); uniqueness comes from the suffix (pid, random, O_EXCL).
    if (name.size() + suffix.size() > name_max) name.resize(name_max > suffix.size() ? name_max - suffix.size() : 0);
    return prefix + name + suffix;
}

}  // namespace fiblet::detail
