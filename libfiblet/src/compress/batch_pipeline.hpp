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
// parity) are in use at any time, whatever the thread count. One thread
// takes the batches' tasks in turn instead (for_each_batch_in_turn).
#pragma once

#include <cstdint>
#include <vector>

#include "compress/compress_stages.hpp"
#include "core/thread_count.hpp"
#include "fiblet/parallel.hpp"

namespace fiblet::detail {

// for_each_batch on one thread: each task runs as soon as its fibers are
// read, while they are in the core's cache, and (unless `after` reads them)
// their buffers take the next fibers; reading a whole batch ahead, as the
// pipeline does, left both megabytes behind. The same batches, tasks and
// slots, so the same results: default compress of the medium tractogram
// 3.5 % faster, -e 0 5 % (one pinned core, median of 5 interleaved).
template <class Slot, class NewSlot, class Task, class InOrder, class After>
void for_each_batch_in_turn(StreamlineSource& reader, std::vector<Slot> (&slots)[2], NewSlot new_slot, Task task,
                            InOrder in_order, After after, bool after_reads_fibers, double& read_seconds) {
    FiberBatch b;
    std::vector<std::vector<Vec3f>> spare;  // buffers of fibers nothing reads any more, the warmest last
    for (int cur = 0;; cur = 1 - cur) {
        begin_fiber_batch(b, b.first_fiber + std::uint32_t(b.count));
        for (std::size_t t = 0;; ++t) {
            {
                const StageClock clock(read_seconds);
                if (!read_fiber_task(reader, b, after_reads_fibers ? nullptr : &spare)) break;
            }
            if (slots[cur].size() <= t) new_slot(slots[cur].emplace_back());
            task(b, t, slots[cur][t]);
            in_order(b, b.cuts[t], b.cuts[t + 1]);
            if (!after_reads_fibers)
                for (std::size_t i = b.cuts[t]; i < b.cuts[t + 1]; ++i) spare.push_back(std::move(b.fibers[i]));
        }
        if (b.count == 0) return;
        after(b, slots[cur]);
    }
}

// task(batch, t, slot) for each task t of every batch of `reader` (from
// where it stands), the slot being slots[batch parity][t] (new ones made
// with new_slot); in_order(batch, first, end) for its fibers in file order,
// on the caller while its tasks run; after(batch, its slots) on the caller
// once they are done, in batch order (reading the batch's fibers only if
// `after_reads_fibers`). The reading's seconds are added to `read_seconds`.
template <class Slot, class NewSlot, class Task, class InOrder, class After>
void for_each_batch(StreamlineSource& reader, unsigned threads, std::vector<Slot> (&slots)[2], NewSlot new_slot,
                    Task task, InOrder in_order, After after, bool after_reads_fibers, double& read_seconds) {
    if (resolve_threads(threads) == 1)
        return for_each_batch_in_turn(reader, slots, new_slot, task, in_order, after, after_reads_fibers, read_seconds);
    FiberBatch batch[2];
    auto read = [&](FiberBatch& b, std::uint32_t first) {
        const StageClock clock(read_seconds);
        return read_fiber_batch(reader, b, first);
    };
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
        in_order(b, 0, b.count);
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
