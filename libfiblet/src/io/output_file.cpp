#include "fiblet/output_file.hpp"

#include <sys/uio.h>

#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>  // renameat2, RENAME_NOREPLACE
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <random>

#include "fiblet/error.hpp"
#include "io/cleanup_signals.hpp"
#include "io/output_target.hpp"

namespace fiblet {
namespace {

// Pending temporaries, removable from a signal handler: fixed slots of
// NUL-terminated paths, published with an atomic flag.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
struct Slot {
    std::atomic<bool> used{false};
    std::atomic<bool> ready{false};
    char path[kPathMax];
};
Slot g_slots[kSlots];

int register_temporary(const std::string& path) {
    if (path.size() >= kPathMax) return -1;
    for (int i = 0; i < kSlots; ++i) {
        bool expected = false;
        if (g_slots[i].used.compare_exchange_strong(expected, true)) {
            std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
            g_slots[i].ready.store(true);
            return i;
        }
    }
    return -1;  // more than kSlots outputs at once: still removed by the destructor
}

void unregister_temporary(int slot) {
    if (slot < 0) return;
    g_slots[slot].ready.store(false);
    g_slots[slot].used.store(false);
}

std::string errno_text() { return std::strerror(errno); }

// Moves `from` to `to` unless `to` exists, atomically: an output that
// appeared while we were writing (another process) is never replaced.
void rename_no_replace(const std::string& from, const std::string& to, const std::string& shown) {
    if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return;
    if (errno == EEXIST) throw Error(Errc::exists, shown + ": output exists", Remedy::overwrite);
    if (errno != EINVAL && errno != ENOSYS)
        throw Error(Errc::io, shown + ": cannot rename temporary into place: " + errno_text());
    // File systems without RENAME_NOREPLACE: link() fails on an existing target too.
    if (::link(from.c_str(), to.c_str()) != 0) {
        if (errno == EEXIST) throw Error(Errc::exists, shown + ": output exists", Remedy::overwrite);
        throw Error(Errc::io, shown + ": cannot move temporary into place: " + errno_text());
    }
    ::unlink(from.c_str());
}

using detail::SignalBlock;

}  // namespace

std::span<const int> fatal_signals() noexcept { return detail::kCleanupSignals; }

void remove_pending_outputs() noexcept {
    for (auto& s : g_slots)
        if (s.ready.load()) ::unlink(s.path);
}

PendingTemporary::PendingTemporary(const std::string& path) {
    const SignalBlock block;
    slot_ = register_temporary(path);
}

PendingTemporary::~PendingTemporary() {
    const SignalBlock block;
    unregister_temporary(slot_);
}

void AtomicOutputFile::check_destination(const std::string& path, bool overwrite) {
    const detail::OutputTarget target = detail::resolve_output_target(path);
    if (!overwrite && target.exists && !target.write_through)
        throw Error(Errc::exists, path + ": output exists", Remedy::overwrite);
}

AtomicOutputFile::AtomicOutputFile(const std::string& path, bool overwrite) : path_(path), overwrite_(overwrite) {
    const detail::OutputTarget target = detail::resolve_output_target(path);
    target_ = target.path;
    if (target.write_through) {
        open_in_place();
    } else {
        if (!overwrite && target.exists) throw Error(Errc::exists, path + ": output exists", Remedy::overwrite);
        create_temporary();
    }
    buffer_.reserve(1u << 20);
}

// A character device (/dev/null): written as it is, never replaced.
void AtomicOutputFile::open_in_place() {
    write_through_ = true;
    fd_ = ::open(target_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0) throw Error(Errc::io, path_ + ": cannot open the output: " + errno_text());
}

void AtomicOutputFile::create_temporary() {
    std::random_device rd;
    {
        // A signal between creating the temporary and registering it would leak it.
        const SignalBlock block;
        for (int attempt = 0; attempt < 16 && fd_ < 0; ++attempt) {
            const std::string suffix = ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(rd() % 1000000);
            tmp_ = detail::temporary_name_for(target_, suffix);
            fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
            if (fd_ < 0 && errno != EEXIST) break;
        }
        if (fd_ >= 0) registry_slot_ = register_temporary(tmp_);
    }
    if (fd_ < 0) throw Error(Errc::io, path_ + ": cannot create output: " + errno_text());
}

AtomicOutputFile::~AtomicOutputFile() {
    if (fd_ >= 0) ::close(fd_);
    if (write_through_) return;
    const SignalBlock block;  // unlink and unregister together
    if (!committed_) ::unlink(tmp_.c_str());
    unregister_temporary(registry_slot_);
}

void AtomicOutputFile::flush_buffer() {
    const char* p = buffer_.data();
    std::size_t left = buffer_.size();
    while (left > 0) {
        const ssize_t n = ::write(fd_, p, left);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw Error(Errc::io, path_ + ": write failed: " + errno_text());
        }
        p += n;
        left -= std::size_t(n);
    }
    buffer_.clear();
}

void AtomicOutputFile::write(const void* data, std::size_t size) {
    if (buffer_.size() + size > buffer_.capacity()) flush_buffer();
    if (size >= buffer_.capacity()) {  // straight to the file: a copy would double a large trailer
        write_pieces(&data, &size, 1);
        return;
    }
    buffer_.append(static_cast<const char*>(data), size);
    written_ += size;
}

void AtomicOutputFile::write_pieces(const void* const* data, const std::size_t* sizes, std::size_t count) {
    flush_buffer();
    constexpr std::size_t kMaxPieces = 1024;  // IOV_MAX on Linux
    iovec iov[kMaxPieces];
    for (std::size_t at = 0; at < count;) {
        const std::size_t n = std::min(kMaxPieces, count - at);
        for (std::size_t i = 0; i < n; ++i) iov[i] = {const_cast<void*>(data[at + i]), sizes[at + i]};
        iovec* v = iov;
        std::size_t left = n;
        while (left > 0) {
            const ssize_t w = ::writev(fd_, v, int(left));
            if (w < 0) {
                if (errno == EINTR) continue;
                throw Error(Errc::io, path_ + ": write failed: " + errno_text());
            }
            written_ += std::uint64_t(w);
            // Skip what was written (a short write may stop inside a piece).
            std::size_t done = std::size_t(w);
            while (left > 0 && done >= v->iov_len) done -= v->iov_len, ++v, --left;
            if (left > 0) v->iov_base = static_cast<char*>(v->iov_base) + done, v->iov_len -= done;
        }
        at += n;
    }
}

void AtomicOutputFile::write_at(const void* data, std::size_t size, std::uint64_t offset) {
    flush_buffer();
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::pwrite(fd_, p, size, off_t(offset));
        if (n < 0) {
            if (errno == EINTR) continue;
            throw Error(Errc::io, path_ + ": write failed: " + errno_text());
        }
        p += n, size -= std::size_t(n), offset += std::uint64_t(n);
    }
}

void AtomicOutputFile::commit() {
    flush_buffer();
    // No fsync: the rename makes the output atomic for the process (error,
    // crash, signal); like zstd or gzip, durability across power loss is
    // left to the file system (an fsync costs more than encoding here).
    if (::close(fd_) != 0) {
        fd_ = -1;
        throw Error(Errc::io, path_ + ": close failed: " + errno_text());
    }
    fd_ = -1;
    if (write_through_) return void(committed_ = true);
    // What the name points at may have changed while we wrote (a link, a device, an input).
    detail::recheck_output_target({target_, false, true}, path_);
    const SignalBlock block;  // the rename and the registry agree on what exists
    if (overwrite_) {
        if (::rename(tmp_.c_str(), target_.c_str()) != 0)
            throw Error(Errc::io, path_ + ": cannot rename temporary into place: " + errno_text());
    } else {
        rename_no_replace(tmp_, target_, path_);
    }
    committed_ = true;
    unregister_temporary(registry_slot_);
    registry_slot_ = -1;
}

}  // namespace fiblet
