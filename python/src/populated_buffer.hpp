// Memory for large decoded arrays, mapped with its pages faulted in up front
// (MAP_POPULATE). Touching fresh memory page by page is what dominates a
// large load otherwise: on the 2-core VMs we measure on, a 552 MB
// std::vector costs ~2x more to fill than this buffer (see docs/ecosystem.md).
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <new>
#include <utility>

namespace fiblet::python {

// How the pages of a buffer come to be: faulted in up front by one thread
// (populate), or on first touch by whichever threads write them, in 2 MB
// transparent huge pages where the kernel allows (huge: 512x fewer faults,
// taken by the decoding threads in parallel; scripts/bench_python.sh
// measures both with FIBLET_PY_BUFFER=populate|huge).
enum class PageMode { populate, huge };

class PopulatedBuffer {
public:
    PopulatedBuffer() = default;
    explicit PopulatedBuffer(std::size_t bytes, PageMode mode = PageMode::populate) : bytes_(bytes) {
        if (bytes_ == 0) return;
        const int populate = mode == PageMode::populate ? MAP_POPULATE : 0;
        void* p = ::mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | populate, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
        if (mode == PageMode::huge) ::madvise(p, bytes_, MADV_HUGEPAGE);  // advice only: ignored where unsupported
#endif
        data_ = p;
    }
    ~PopulatedBuffer() {
        if (data_) ::munmap(data_, bytes_);
    }
    PopulatedBuffer(PopulatedBuffer&& o) noexcept
        : data_(std::exchange(o.data_, nullptr)), bytes_(std::exchange(o.bytes_, 0)) {}
    PopulatedBuffer& operator=(PopulatedBuffer&& o) noexcept {
        std::swap(data_, o.data_), std::swap(bytes_, o.bytes_);
        return *this;
    }
    PopulatedBuffer(const PopulatedBuffer&) = delete;
    PopulatedBuffer& operator=(const PopulatedBuffer&) = delete;

    template <typename T>
    T* as() const { return static_cast<T*>(data_); }
    // Keeps the first `bytes` (whole pages) and gives the rest back.
    void shrink(std::size_t bytes) {
        const auto page = std::size_t(::sysconf(_SC_PAGESIZE));
        const std::size_t keep = (bytes + page - 1) / page * page;
        if (!data_ || keep >= bytes_) return;
        ::munmap(static_cast<char*>(data_) + keep, bytes_ - keep);
        bytes_ = keep;
        if (keep == 0) data_ = nullptr;
    }
    std::size_t bytes() const { return bytes_; }

private:
    void* data_ = nullptr;
    std::size_t bytes_ = 0;
};

}  // namespace fiblet::python
