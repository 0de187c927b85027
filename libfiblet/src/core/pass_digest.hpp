// Internal: a digest of the bytes a multi-pass reader reads on each pass,
// compared between passes to catch a file edited while it is read (XXH3-64
// through libxxhash's run-time dispatch: 33 GB/s on one core of an AVX2
// AMD EPYC VM, against 13 GB/s for its inline SSE2 code and 14 for XXH64).
// Never stored: files keep XXH64 (checksum.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

namespace fiblet::detail {

class PassDigest {
public:
    PassDigest();
    ~PassDigest();
    PassDigest(const PassDigest&) = delete;
    PassDigest& operator=(const PassDigest&) = delete;
    void reset();
    void update(const void* data, std::size_t size);
    std::uint64_t digest() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace fiblet::detail
