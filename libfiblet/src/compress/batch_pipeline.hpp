// Internal: the loop the compress passes share (compress_scan.cpp,
// compress_encode.cpp), over batches of whole fibers read by the caller.
//
// Batch k's tasks run on the worker pool while the caller does batch k's
// in-order work and reads batch k + 1; batch k + 1's job starts before the
// caller waits for batch k, so a thread done with k's tasks goes on to
// k + 1's (the caller too, ParallelJob::wait's `meanwhile`) instead of
// idling at every batch's end while the other finishes k's last task.
// Then `after` (batch k's results, in order) runs on the caller while the
// pool works on k + 1. Two batches and two sets of slots (one per batch
// parity) are in use at any time, whatever the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "compress/compress_stages.hpp"
#include "fiblet/parallel.hpp"

namespace fiblet::detail {

// task(batch, t, slot) for each task t of every batch of `reader` (from
// where it stands), the slot being slots[batch parity][t] (new ones made
// with new_slot); in_order(batch) on the caller while its tasks run;
// after(batch, its slots) on the caller once they are done, in batch order.
// The reading's seconds are added to `read_seconds`.
template <class Slot, class NewSlot, class Task, class InOrder, class After>
void for_each_batch(StreamlineSource& reader, unsigned threads, std::vector<Slot> (&slots)[2], NewSlot new_slot,
                    Task task, InOrder in_order, After after, double& read_seconds) {
    auto read = [&](FiberBatch& b, std::uint32_t first) {
        const StageClock clock(read_seconds);
        return read_fiber_batch(reader, b, first);
    };
    FiberBatch batch[2];
    ParallelJob job[2];  // after batch and slots: destroyed (waited for) first
    auto start = [&](int k) {
        while (slots[k].size() < batch[k].tasks()) new_slot(slots[k].emplace_back());
        job[k] = ParallelJob(batch[k].tasks(), threads, [&, k](std::size_t t) { task(batch[k], t, slots[k][t]); });
    };
    int cur = 0;
    if (!read(batch[cur], 0)) return;
    start(cur);
    for (;;) {
        const FiberBatch& b = batch[cur];
        in_order(b);
        // The other batch's job is done and its slots were used by `after`.
        const bool more = read(batch[1 - cur], std::uint32_t(b.first_fiber + b.count));
        if (more) start(1 - cur);
        job[cur].wait(more ? &job[1 - cur] : nullptr);
        after(b, slots[cur]);
        if (!more) return;
        cur = 1 - cur;
    }
}

}  // namespace fiblet::detail
