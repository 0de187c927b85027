// Internal: inputs are regular files, checked by stat() before they are
// opened. open() of a FIFO for reading blocks until a writer comes (a hang,
// not an error), and a format detector that read a pipe would consume the
// bytes its reader needs. Every input is read more than once or by offset;
// the commands that take standard input (`-`) spool it to a file first.
#pragma once

#include <sys/stat.h>

#include <string>

#include "fiblet/error.hpp"

namespace fiblet::detail {

// Whether `path` is something an input may be: a regular file, or (where
// `directory_ok`, a TRX directory) a directory. A path that does not exist
// is left to the open that follows (its errno's text).
inline bool is_regular_input(const std::string& path, bool directory_ok = false) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return true;
    return S_ISREG(st.st_mode) || (directory_ok && S_ISDIR(st.st_mode));
}

// Throws Error{io} (exit 3) for a pipe, a device, a socket or a directory.
inline void require_regular_input(const std::string& path, bool directory_ok = false) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode) || (directory_ok && S_ISDIR(st.st_mode))) return;
    if (S_ISDIR(st.st_mode)) throw Error(Errc::io, path + ": is a directory");
    const char* kind = S_ISFIFO(st.st_mode) ? "a pipe" : S_ISSOCK(st.st_mode) ? "a socket" : "a device";
    throw Error(Errc::io, path + ": not a regular file (" + kind +
                              "): inputs are read more than once or by offset; save it to a file first "
                              "(compress and decompress take - for standard input)");
}

}  // namespace fiblet::detail
