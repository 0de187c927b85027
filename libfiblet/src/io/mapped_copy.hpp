// Internal: reads of a memory mapping of a file that another process may
// truncate meanwhile. Reading a mapped page past the end of a shrunk file
// raises SIGBUS, which would end the process with no message and no
// cleanup; inside these functions the fault is caught and the read fails
// instead, so the caller throws a clear error. Jumping out of the signal
// handler is safe only because nothing else runs under the guard: plain
// copies or a hash update, no locks taken, no destructors skipped. So the
// mapping must be read through these functions alone, never decoded in place.
#pragma once

#include <cstddef>
#include <span>

#include "fiblet/checksum.hpp"

namespace fiblet::detail {

struct MappedCopy {
    const void* from;  // in the mapping
    void* to;
    std::size_t bytes;
};

// Makes every copy; false when one of them faulted (the file shrank under
// the mapping), the destinations then holding unspecified bytes. The first
// call installs a process-wide SIGBUS handler; faults outside these copies
// go on to the handler installed before it (by default: the process ends,
// as it would have without fiblet).
bool copy_from_mapping(std::span<const MappedCopy> copies);

// hash.update(from, bytes) in place, under the same guard; false when it
// faulted (the hash then holds an unspecified state).
bool hash_from_mapping(const void* from, std::size_t bytes, Xxh64Stream& hash);

}  // namespace fiblet::detail
