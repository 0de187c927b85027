// Whole fibers out of a file: chunks of whole fibers are read and decoded
// by `threads` threads of the library's pool, a contiguous run of the
// chunk's blocks at a time (reading, counting and decoding all in
// parallel), into one output in fiber order; decode_fibers_into, whose
// caller gives the whole output, in one pool job of parts that each thread
// reads, counts and decodes alone.
#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "container/fiber_spans.hpp"
#include "core/ordered_ends.hpp"
#include "core/thread_count.hpp"
#include "decode/decode_kernels.hpp"
#include "fiblet/parallel.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"

namespace fiblet {

using detail::fibers_end;

namespace {

class ChunkDecoder {
public:
    // decode_file reuses its chunks' outputs: 4096 blocks of 60 points a
    // thread (~3 MB of points) stay in cache (DecodeOptions::chunk_blocks);
    // blocks of other sizes (16-bit: 254 points) as many points.
    static constexpr std::size_t kPointsPerThread = std::size_t{4096} * 60;
    // decode_fibers writes straight into the whole output; only the chunk's
    // blocks are reused (5 MB: 65536 76-byte blocks, fewer larger ones).
    // Bigger chunks join the pool less often: each chunk is two jobs, and a
    // job's end waits for its last run and wakes a worker (docs/parallel.md:
    // 2 threads vs 1 went from 1.4x to 1.7x on the medium file; the whole
    // file as one chunk is slower again, its blocks fall out of cache).
    static constexpr std::size_t kWholeOutputChunkBytes = (std::size_t{1} << 16) * 76;

    ChunkDecoder(const FftFile& file, const DecodeOptions& options, std::size_t min_chunk_bytes = 0)
        : file_(file),
          ctx_(file),
          decoder_(resolve_decoder(options.decoder)),
          threads_(detail::resolve_threads(options.threads)),
          chunk_blocks_(options.chunk_blocks ? options.chunk_blocks : default_chunk_blocks(min_chunk_bytes)) {}

    std::size_t chunk_blocks() const { return chunk_blocks_; }

    std::size_t default_chunk_blocks(std::size_t min_chunk_bytes) const {
        const std::size_t per_thread = std::max<std::size_t>(kPointsPerThread / ctx_.header.points_per_block, 1);
        return std::max(per_thread * threads_, min_chunk_bytes / ctx_.header.block_bytes());
    }

    // End of the chunk of whole fibers starting at `f`: at least one fiber,
    // at most chunk_blocks blocks otherwise.
    std::uint64_t chunk_end(std::uint64_t f, std::uint64_t end) const {
        return fibers_end(file_, f, end, chunk_blocks_);
    }

    // Reads the blocks of fibers [f0, f1) and counts their points (validating
    // every block); returns that count.
    std::uint64_t load(std::uint64_t f0, std::uint64_t f1) {
        f0_ = f0, f1_ = f1;
        const std::uint64_t b0 = file_.block_end(f0);
        blocks_ = file_.block_end(f1) - b0;
        const std::size_t bb = ctx_.header.block_bytes();
        data_.resize(blocks_ * bb);
        // Runs of at least a thousand blocks (below that handing one out
        // costs more than it saves), up to 4 per thread: taken one at a time
        // from the pool, so a thread scheduled late does less of the chunk.
        // Not more: the thread that decodes a run is often not the one that
        // read it, and 8 a thread cost 10 % more CPU (docs/parallel.md).
        runs_ = threads_ == 1 ? 1u : unsigned(std::clamp<std::uint64_t>(blocks_ / 1024, 1, 4 * threads_));
        first_.assign(runs_ + 1, 0);
        points_.assign(runs_ + 1, 0);
        for (unsigned t = 0; t <= runs_; ++t) first_[t] = blocks_ * t / runs_;
        parallel_for(runs_, threads_, [&](std::size_t t) {
            const std::size_t n = first_[t + 1] - first_[t];
            file_.read_blocks(b0 + first_[t], n, data_.data() + first_[t] * bb);
            points_[t + 1] = count_block_points(ctx_, data_.data() + first_[t] * bb, n);
        });
        for (unsigned t = 0; t < runs_; ++t) points_[t + 1] += points_[t];
        return points_[runs_];
    }

    // Decodes the loaded chunk into xyz (load()'s number of points) and
    // writes offsets[0 .. f1 - f0] = base + points before each fiber.
    void decode(float* xyz, std::uint64_t* offsets, std::uint64_t base) {
        const std::size_t bb = ctx_.header.block_bytes();
        parallel_for(runs_, threads_, [&](std::size_t t) {
            detail::decode_resolved(ctx_, data_.data() + first_[t] * bb, first_[t + 1] - first_[t],
                                    xyz + 3 * points_[t], decoder_);
        });
        std::size_t b = 0;
        std::uint64_t acc = base;
        offsets[0] = acc;
        for (std::uint64_t f = f0_; f < f1_; ++f) {
            for (std::uint32_t k = file_.block_count(f); k > 0; --k, ++b)
                acc += block_flags(ctx_.header, &data_[b * bb]).point_count;
            offsets[f - f0_ + 1] = acc;
        }
    }

private:
    const FftFile& file_;
    const DecodeContext ctx_;
    const Decoder decoder_;
    const unsigned threads_;
    const std::size_t chunk_blocks_;
    std::uint64_t f0_ = 0, f1_ = 0, blocks_ = 0;
    unsigned runs_ = 1;
    std::vector<std::uint8_t> data_;
    std::vector<std::uint64_t> first_, points_;
};

// decode_fibers_into's parts: 16384 blocks of 60 points (1.2 MB of blocks,
// read and decoded while in cache; as many points of larger blocks). Parts
// of 4096 cost 10 % more on one thread, more than they balance on two
// (docs/parallel.md).
constexpr std::uint64_t kPartPoints = std::uint64_t{16384} * 60;

void check_range(const FftFile& file, std::uint64_t begin, std::uint64_t end) {
    if (begin > end || end > file.header().fibers)
        throw Error(Errc::invalid_argument, file.path() + ": fiber range past the end");
}

}  // namespace

Streamlines decode_fibers(const FftFile& file, std::uint64_t begin, std::uint64_t end, const DecodeOptions& options) {
    check_range(file, begin, end);
    ChunkDecoder chunks(file, options, ChunkDecoder::kWholeOutputChunkBytes);
    Streamlines out;
    out.offsets.resize(end - begin + 1);
    // Reserving the most the blocks can hold maps memory without touching it.
    out.xyz.reserve(3 * (file.block_end(end) - file.block_end(begin)) * file.header().points_per_block);
    for (std::uint64_t f = begin; f < end;) {
        const std::uint64_t e = chunks.chunk_end(f, end);
        const std::uint64_t n = chunks.load(f, e), done = out.xyz.size() / 3;
        out.xyz.resize(3 * (done + n));
        chunks.decode(out.xyz.data() + 3 * done, &out.offsets[f - begin], done);
        f = e;
    }
    return out;
}

std::uint64_t decode_fibers_into(const FftFile& file, std::uint64_t begin, std::uint64_t end, std::span<float> xyz,
                                 std::span<std::uint64_t> offsets, const DecodeOptions& options) {
    check_range(file, begin, end);
    if (offsets.size() < end - begin + 1)
        throw Error(Errc::invalid_argument, "decode_fibers_into: " + std::to_string(end - begin + 1) +
                                                " offsets needed, room for " + std::to_string(offsets.size()));
    // One job of parts of whole fibers, each read, counted and decoded by
    // one thread while its blocks are in cache, after the points of the
    // parts before it (no join per chunk: docs/parallel.md).
    const DecodeContext ctx(file);
    const Decoder decoder = resolve_decoder(options.decoder);
    const std::size_t bb = ctx.header.block_bytes();
    const std::uint64_t part_blocks =
        options.chunk_blocks ? options.chunk_blocks
                             : std::max<std::uint64_t>(kPartPoints / ctx.header.points_per_block, 1);
    std::vector<std::uint64_t> part_first{begin};
    while (part_first.back() < end) part_first.push_back(fibers_end(file, part_first.back(), end, part_blocks));
    const std::size_t parts = part_first.size() - 1;
    detail::OrderedEnds ends(parts);
    offsets[0] = 0;
    // Part p: its blocks read, counted, placed after the parts before it and decoded.
    detail::parallel_parts(ends, detail::resolve_threads(options.threads), [&](std::size_t p) {
        const std::uint64_t f0 = part_first[p], f1 = part_first[p + 1], b0 = file.block_end(f0);
        const std::uint64_t blocks = file.block_end(f1) - b0;
        thread_local std::vector<std::uint8_t> data;
        data.resize(blocks * bb);
        file.read_blocks(b0, blocks, data.data());
        const std::uint64_t points = count_block_points(ctx, data.data(), blocks);
        const std::uint64_t start = ends.publish(p, points);
        if (start == detail::OrderedEnds::kFailed) return;  // a part before failed: its error is the one reported
        if (3 * (start + points) > xyz.size())
            throw Error(Errc::invalid_argument, "decode_fibers_into: " + file.path() + " holds more points than the " +
                                                    std::to_string(xyz.size() / 3) + " the buffer has room for");
        std::uint64_t at = start;
        const std::uint8_t* block = data.data();
        for (std::uint64_t f = f0; f < f1; ++f) {
            for (std::uint32_t k = file.block_count(f); k > 0; --k, block += bb)
                at += block_flags(ctx.header, block).point_count;
            offsets[f - begin + 1] = at;
        }
        detail::decode_resolved(ctx, data.data(), blocks, xyz.data() + 3 * start, decoder);
    });
    return ends.end();
}

namespace {

// The sink stage of a pipelined decode_file: one thread that calls the sink
// on each chunk posted, in order, while the caller decodes the next one.
// One chunk in flight at a time (a bounded queue of one).
class SinkStage {
public:
    explicit SinkStage(const std::function<void(std::uint64_t, const Streamlines&)>& sink)
        : sink_(sink), thread_([this] { run(); }) {}
    ~SinkStage() {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        cv_.notify_all();
        thread_.join();
    }
    // Waits until the chunk posted last is done with (rethrows the sink's exception).
    void wait_idle() {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [&] { return !chunk_ || error_; });
        if (error_) std::rethrow_exception(error_);
    }
    // Hands `chunk` to the sink; it stays untouched until wait_idle returns.
    void post(std::uint64_t first, const Streamlines& chunk) {
        wait_idle();
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            first_ = first, chunk_ = &chunk;
        }
        cv_.notify_all();
    }

private:
    void run() {
        for (;;) {
            std::unique_lock<std::mutex> lock(mutex_);
            cv_.wait(lock, [&] { return chunk_ || stop_; });
            if (!chunk_) return;
            const Streamlines* chunk = chunk_;
            const std::uint64_t first = first_;
            lock.unlock();
            std::exception_ptr error;
            try {
                sink_(first, *chunk);
            } catch (...) {
                error = std::current_exception();
            }
            lock.lock();
            chunk_ = nullptr;
            if (error && !error_) error_ = error;
            lock.unlock();
            cv_.notify_all();
            if (error) return;
        }
    }

    const std::function<void(std::uint64_t, const Streamlines&)>& sink_;
    std::mutex mutex_;
    std::condition_variable cv_;
    const Streamlines* chunk_ = nullptr;
    std::uint64_t first_ = 0;
    bool stop_ = false;
    std::exception_ptr error_;
    std::thread thread_;  // last: starts once the rest is set up
};

}  // namespace

void decode_file(const FftFile& file, const std::function<void(std::uint64_t, const Streamlines&)>& sink,
                 const DecodeOptions& options) {
    // The sink's thread is one of the threads asked for: writing a .tck is
    // the kernel's page copies, as long as decoding on a core of its own,
    // and a second decoder beside them only took the sink's core away.
    DecodeOptions decoding = options;
    if (options.overlap_sink) decoding.threads = std::max(1u, detail::resolve_threads(options.threads) - 1);
    ChunkDecoder chunks(file, decoding);
    const std::uint64_t fibers = file.header().fibers;
    // Two chunks: one decoded while the sink (on its own thread, with
    // overlap_sink) has the other.
    Streamlines chunk[2];
    const int buffers = options.overlap_sink ? 2 : 1;
    // Room for a usual chunk up front: growing would copy it.
    for (int k = 0; k < buffers; ++k)
        chunk[k].xyz.reserve(3 * std::min<std::uint64_t>(chunks.chunk_blocks(), file.header().blocks) *
                             file.header().points_per_block);
    std::optional<SinkStage> stage;
    if (options.overlap_sink) stage.emplace(sink);
    std::uint64_t points = 0;
    int k = 0;
    for (std::uint64_t f = 0; f < fibers;) {
        const std::uint64_t e = chunks.chunk_end(f, fibers);
        const std::uint64_t n = chunks.load(f, e);
        points += n;
        Streamlines& c = chunk[k];
        c.xyz.resize(3 * n);
        c.offsets.resize(e - f + 1);
        chunks.decode(c.xyz.data(), c.offsets.data(), 0);
        if (stage) stage->post(f, c);
        else sink(f, c);
        k = (k + 1) % buffers;
        f = e;
    }
    if (stage) stage->wait_idle();
    // A whole-file reader reports the header's count: it must be what it wrote.
    if (points != file.header().points)
        throw Error(Errc::fft_format, file.path() + ": not a valid .fft file: the blocks hold " + std::to_string(points) +
                                          " points, the header says " + std::to_string(file.header().points));
}

}  // namespace fiblet
