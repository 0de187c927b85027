// The read stage of compress_file (compress_stages.hpp): batches of whole
// fibers, parsed by the caller's thread while the worker pool works on the
// batch before.
#include <algorithm>
#include <limits>

#include "compress/compress_stages.hpp"
#include "fiblet/error.hpp"

namespace fiblet::detail {

bool read_fiber_batch(StreamlineSource& reader, FiberBatch& b, std::uint32_t first_fiber) {
    b.count = 0;
    b.first_fiber = first_fiber;
    b.cuts.assign(1, 0);
    std::size_t points = 0, task_points = 0;
    while (points < kBatchPoints) {
        if (b.fibers.size() <= b.count) b.fibers.emplace_back();
        if (std::uint64_t(first_fiber) + b.count == std::numeric_limits<std::uint32_t>::max()) {
            // One more would be fiber 2^32 - 1: fiber IDs are 32-bit.
            std::vector<Vec3f> probe;
            if (!reader.next(probe)) break;
            throw Error(Errc::unsupported, reader.path() + ": more than 2^32 - 1 streamlines (fiber IDs are 32-bit)");
        }
        if (!reader.next(b.fibers[b.count])) break;
        // An empty fiber counts as one point: it still costs per-fiber
        // tables, and 2^24 of them made one batch of 1.8 GB.
        const std::size_t n = std::max<std::size_t>(b.fibers[b.count++].size(), 1);
        points += n, task_points += n;
        if (task_points >= kTaskPoints) b.cuts.push_back(b.count), task_points = 0;
    }
    if (b.cuts.back() != b.count) b.cuts.push_back(b.count);
    return b.count > 0;
}

}  // namespace fiblet::detail
