// The read stage of compress_file (compress_stages.hpp): batches of whole
// fibers, parsed by the caller's thread while the worker pool works on the
// batch before.
#include <algorithm>
#include <limits>

#include "compress/compress_stages.hpp"
#include "fiblet/error.hpp"

namespace fiblet::detail {

void begin_fiber_batch(FiberBatch& b, std::uint32_t first_fiber) {
    b.count = 0;
    b.first_fiber = first_fiber;
    b.cuts.assign(1, 0);
    b.points = 0;
    b.complete = false;
}

bool read_fiber_task(StreamlineSource& reader, FiberBatch& b, std::vector<std::vector<Vec3f>>* spare) {
    if (b.complete) return false;
    std::size_t task_points = 0;
    while (b.points < kBatchPoints) {
        if (b.fibers.size() <= b.count) b.fibers.emplace_back();
        if (spare && !spare->empty()) {
            b.fibers[b.count] = std::move(spare->back());
            spare->pop_back();
        }
        if (std::uint64_t(b.first_fiber) + b.count == std::numeric_limits<std::uint32_t>::max()) {
            // One more would be fiber 2^32 - 1: fiber IDs are 32-bit.
            std::vector<Vec3f> probe;
            if (!reader.next(probe)) break;
            throw Error(Errc::unsupported, reader.path() + ": more than 2^32 - 1 streamlines (fiber IDs are 32-bit)");
        }
        if (!reader.next(b.fibers[b.count])) break;
        // An empty fiber counts as one point: it still costs per-fiber
        // tables, and 2^24 of them made one batch of 1.8 GB.
        const std::size_t n = std::max<std::size_t>(b.fibers[b.count++].size(), 1);
        b.points += n, task_points += n;
        if (task_points >= kTaskPoints) {
            b.cuts.push_back(b.count);
            return true;
        }
    }
    b.complete = true;
    if (b.cuts.back() == b.count) return false;
    b.cuts.push_back(b.count);
    return true;
}

bool read_fiber_batch(StreamlineSource& reader, FiberBatch& b, std::uint32_t first_fiber) {
    begin_fiber_batch(b, first_fiber);
    while (read_fiber_task(reader, b)) {
    }
    return b.count > 0;
}

}  // namespace fiblet::detail
