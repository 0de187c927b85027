// fiblet — atomic output files.
//
// Every writer of the library writes to a temporary file next to the
// destination and renames it into place only when the output is complete, so
// a crash, an error or a signal never leaves a half-written file that a
// pipeline could take for a good one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace fiblet {

class AtomicOutputFile {
public:
    // Throws Error{exists} if `path` exists and !overwrite, Error{io} if the
    // temporary cannot be created.
    AtomicOutputFile(const std::string& path, bool overwrite);
    ~AtomicOutputFile();  // removes the temporary unless commit() succeeded
    AtomicOutputFile(const AtomicOutputFile&) = delete;
    AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

    void write(const void* data, std::size_t size);               // appends
    void write_at(const void* data, std::size_t size, std::uint64_t offset);  // patches
    std::uint64_t size() const { return written_; }
    // Flushes and renames into place: over the destination if `overwrite`,
    // else only if it still does not exist (Error{exists}, atomically).
    void commit();

    const std::string& path() const { return path_; }
    const std::string& temporary_path() const { return tmp_; }

private:
    void flush_buffer();
    std::string path_, tmp_;
    int fd_ = -1;
    bool overwrite_ = false, committed_ = false;
    std::uint64_t written_ = 0;
    std::string buffer_;
    int registry_slot_ = -1;
};

// Removes every temporary output still pending. Async-signal-safe: a CLI calls
// it from its SIGINT/SIGTERM/SIGHUP handler before exiting.
void remove_pending_outputs() noexcept;

// Installs SIGINT/SIGTERM/SIGHUP handlers that remove pending outputs and
// exit with 128+signal (the shell convention).
void install_signal_cleanup();

}  // namespace fiblet
