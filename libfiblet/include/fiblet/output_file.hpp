// fiblet — atomic output files.
//
// Every writer of the library writes to a temporary file next to the
// destination and renames it into place only when the output is complete, so
// a crash, an error or a signal never leaves a half-written file that a
// pipeline could take for a good one.
//
// What the destination may be (decided at construction):
//  - missing or a regular file: the temporary is renamed over it;
//  - a symbolic link: the link is followed and its final target replaced
//    atomically (the link stays); a dangling link is refused;
//  - a character device (/dev/null, /dev/full): written through in place,
//    no temporary, nothing renamed or replaced (--force not needed);
//  - a FIFO, socket, block device or directory: refused (Error{invalid_argument}):
//    the writers seek back to finish a file, which a pipe cannot take;
//  - a file an open FftFile or TckReader of this process reads (the same
//    st_dev/st_ino: the input itself, a symlink or a hard link to it):
//    refused (Error{invalid_argument}), with or without overwrite.
// The temporary's name is shortened to fit NAME_MAX: any legal output name works.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace fiblet {

class AtomicOutputFile {
public:
    // Throws Error{exists} if `path` exists and !overwrite, Error{invalid_argument}
    // for a refused destination (see above), Error{io} if the temporary
    // cannot be created.
    AtomicOutputFile(const std::string& path, bool overwrite);
    ~AtomicOutputFile();  // removes the temporary unless commit() succeeded
    // What the constructor would refuse (see above; an existing output without
    // overwrite), checked now without creating anything: a long command (a
    // compress that scans its input first) fails before its work, not after.
    // The constructor and commit() check again.
    static void check_destination(const std::string& path, bool overwrite);
    AtomicOutputFile(const AtomicOutputFile&) = delete;
    AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

    void write(const void* data, std::size_t size);               // appends
    // Appends `count` pieces (data[i], sizes[i] bytes) in order, handed to
    // the kernel as they are (writev), without copying them first.
    void write_pieces(const void* const* data, const std::size_t* sizes, std::size_t count);
    void write_at(const void* data, std::size_t size, std::uint64_t offset);  // patches
    std::uint64_t size() const { return written_; }
    // Flushes and renames into place: over the destination if `overwrite`,
    // else only if it still does not exist (Error{exists}, atomically).
    void commit();

    const std::string& path() const { return path_; }
    // Empty when the output is written through (a character device).
    const std::string& temporary_path() const { return tmp_; }
    bool writes_through() const { return write_through_; }

private:
    void open_in_place();
    void create_temporary();
    void flush_buffer();
    std::string path_, target_, tmp_;  // as given, with links resolved, the temporary
    int fd_ = -1;
    bool overwrite_ = false, committed_ = false, write_through_ = false;
    std::uint64_t written_ = 0;
    std::string buffer_;
    int registry_slot_ = -1;
};

// Removes every temporary output still pending. Async-signal-safe: a CLI calls
// it from its fatal-signal handler before exiting.
void remove_pending_outputs() noexcept;

// A temporary file of the caller's own (a CLI's spool of standard input or
// output): remove_pending_outputs() removes it too, until this is destroyed.
class PendingTemporary {
public:
    explicit PendingTemporary(const std::string& path);
    ~PendingTemporary();
    PendingTemporary(const PendingTemporary&) = delete;
    PendingTemporary& operator=(const PendingTemporary&) = delete;

private:
    int slot_ = -1;
};

// The signals after which a program should call remove_pending_outputs()
// (every catchable one whose default action ends the process: SIGINT,
// SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXFSZ, SIGXCPU, SIGUSR1, SIGUSR2,
// SIGALRM, SIGVTALRM, SIGPROF). The library blocks them while its registry
// of pending outputs changes, so a handler never sees half an entry.
std::span<const int> fatal_signals() noexcept;

}  // namespace fiblet
