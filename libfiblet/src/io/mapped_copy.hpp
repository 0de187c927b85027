// Internal: copies out of a memory mapping of a file that another process
// may truncate meanwhile. Reading a mapped page past the end of a shrunk
// file raises SIGBUS, which would end the process with no message and no
// cleanup; inside copy_from_mapping the fault is caught and the copy fails
// instead, so the caller throws a clear error. Jumping out of the signal
// handler is safe only because nothing else runs under the guard: plain
// copies, no locks taken, no destructors skipped. So the mapping must be
// read through this function alone, never decoded in place.
#pragma once

#include <cstddef>
#include <span>

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

}  // namespace fiblet::detail
