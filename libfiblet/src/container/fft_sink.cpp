// The two ways of writing a .fft: plain, and the seekable zstd container
// (formats/fftz.md).
#include "container/fft_sink.hpp"

#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <thread>
#include <vector>

#include "fiblet/error.hpp"
#include "fiblet/fftz_format.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/parallel.hpp"

namespace fiblet::detail {

namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
}

class PlainSink final : public FftSink {
public:
    PlainSink(const std::string& path, bool overwrite) : out_(path, overwrite) {}
    void begin(std::span<const std::uint8_t> header, std::span<const std::uint8_t> lut) override {
        out_.write(header.data(), header.size());
        out_.write(lut.data(), lut.size());
    }
    void write_blocks(std::span<const std::uint8_t> blocks) override { out_.write(blocks.data(), blocks.size()); }
    std::uint64_t logical_size() const override { return out_.size(); }
    void finish(std::span<const std::uint8_t> trailer, std::span<const std::uint8_t> header) override {
        out_.write(trailer.data(), trailer.size());
        out_.write_at(header.data(), header.size(), 0);
    }
    std::uint64_t stored_size() const override { return out_.size(); }
    void commit() override { out_.commit(); }

private:
    AtomicOutputFile out_;
};

// A zstd frame holding `bytes` as one raw (stored) block: its content can be
// rewritten in place later, which the header needs (its error fields are
// known only at the end).
std::vector<std::uint8_t> raw_zstd_frame(std::span<const std::uint8_t> bytes) {
    if (bytes.size() >= (1u << 17)) throw Error(Errc::invalid_argument, "raw zstd block too large");
    std::vector<std::uint8_t> f;
    put_u32(f, 0xFD2FB528);  // zstd frame magic
    f.push_back(0xA0);       // descriptor: 4-byte content size, single segment, no checksum
    put_u32(f, std::uint32_t(bytes.size()));
    const std::uint32_t block_header = 1u | (0u << 1) | std::uint32_t(bytes.size()) << 3;  // last, raw, size
    for (int i = 0; i < 3; ++i) f.push_back(std::uint8_t(block_header >> (8 * i)));
    f.insert(f.end(), bytes.begin(), bytes.end());
    return f;
}

std::vector<std::uint8_t> compress_frame(std::span<const std::uint8_t> bytes, int level) {
    struct Ctx {
        ZSTD_CCtx* c = ZSTD_createCCtx();
        ~Ctx() { ZSTD_freeCCtx(c); }
    } ctx;
    if (!ctx.c) throw Error(Errc::io, "zstd: out of memory");
    ZSTD_CCtx_setParameter(ctx.c, ZSTD_c_compressionLevel, level);
    ZSTD_CCtx_setParameter(ctx.c, ZSTD_c_checksumFlag, 1);  // each frame checks its content
    ZSTD_CCtx_setParameter(ctx.c, ZSTD_c_contentSizeFlag, 1);
    std::vector<std::uint8_t> out(ZSTD_compressBound(bytes.size()));
    const std::size_t n = ZSTD_compress2(ctx.c, out.data(), out.size(), bytes.data(), bytes.size());
    if (ZSTD_isError(n)) throw Error(Errc::io, std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
}

class FftzSink final : public FftSink {
public:
    FftzSink(const std::string& path, bool overwrite, const ZstdOptions& o, unsigned bits, std::uint32_t block_bytes,
             unsigned threads)
        : out_(path, overwrite), options_(o), bits_(bits), block_bytes_(block_bytes), threads_(std::max(1u, threads)) {
        if (o.group_blocks < 1 || std::uint64_t(o.group_blocks) * block_bytes > (1u << 30))
            throw Error(Errc::invalid_argument, "zstd group must hold 1 block and at most 1 GiB");
        if (o.level < ZSTD_minCLevel() || o.level > ZSTD_maxCLevel())
            throw Error(Errc::invalid_argument, "zstd level must be in [" + std::to_string(ZSTD_minCLevel()) + ", " +
                                                    std::to_string(ZSTD_maxCLevel()) + "]");
    }

    void begin(std::span<const std::uint8_t> header, std::span<const std::uint8_t> lut) override {
        std::vector<std::uint8_t> d;
        put_u32(d, kZstdSkippableMagic);
        put_u32(d, std::uint32_t(kFftzDescriptorBytes));
        d.insert(d.end(), std::begin(kFftzMagic), std::end(kFftzMagic));
        d.push_back(kFftzVersion);
        d.push_back(std::uint8_t(options_.transpose ? FftzLayout::transposed : FftzLayout::plain));
        d.push_back(0), d.push_back(0);
        put_u32(d, options_.group_blocks);
        put_u32(d, 0);
        frame(d, 0);
        const auto head = raw_zstd_frame(header);
        header_at_ = out_.size() + (head.size() - header.size());
        header_bytes_ = header.size();
        frame(head, header.size());
        frame(compress_frame(lut, options_.level), lut.size());
        logical_ = header.size() + lut.size();
    }

    void write_blocks(std::span<const std::uint8_t> blocks) override {
        pending_.insert(pending_.end(), blocks.begin(), blocks.end());
        logical_ += blocks.size();
        const std::size_t group = std::size_t(options_.group_blocks) * block_bytes_;
        if (pending_.size() >= group * threads_) flush_groups(false);
    }

    std::uint64_t logical_size() const override { return logical_; }

    void finish(std::span<const std::uint8_t> trailer, std::span<const std::uint8_t> header) override {
        flush_groups(true);
        if (!trailer.empty()) frame(compress_frame(trailer, options_.level), trailer.size());
        // Seek table (zstd seekable format): entries without checksums.
        std::vector<std::uint8_t> t;
        put_u32(t, kZstdSeekTableMagic);
        put_u32(t, std::uint32_t(8 * entries_.size() + 9));
        for (const auto& [c, d] : entries_) put_u32(t, c), put_u32(t, d);
        put_u32(t, std::uint32_t(entries_.size()));
        t.push_back(0);  // descriptor: no checksums
        put_u32(t, kZstdSeekableFooterMagic);
        out_.write(t.data(), t.size());
        if (header.size() != header_bytes_) throw Error(Errc::invalid_argument, "the .fft header changed size");
        out_.write_at(header.data(), header.size(), header_at_);
    }

    std::uint64_t stored_size() const override { return out_.size(); }
    void commit() override { out_.commit(); }

private:
    void frame(const std::vector<std::uint8_t>& bytes, std::uint64_t decompressed) {
        if (entries_.size() >= 0x8000000u) throw Error(Errc::unsupported, "more than 2^27 zstd frames");
        out_.write(bytes.data(), bytes.size());
        entries_.emplace_back(std::uint32_t(bytes.size()), std::uint32_t(decompressed));
    }

    // Compresses the whole groups of pending blocks (and, at the end, the
    // last partial one) on up to threads_ threads, and writes them in order.
    void flush_groups(bool last) {
        const std::size_t group = std::size_t(options_.group_blocks) * block_bytes_;
        std::vector<std::span<const std::uint8_t>> jobs;
        std::size_t at = 0;
        while (pending_.size() - at >= group || (last && at < pending_.size())) {
            const std::size_t n = std::min(group, pending_.size() - at);
            jobs.emplace_back(pending_.data() + at, n);
            at += n;
        }
        std::vector<std::vector<std::uint8_t>> done(jobs.size());
        // One frame at a time from the library's pool.
        parallel_for(jobs.size(), threads_, [&](std::size_t j) {
            const auto fields = options_.transpose ? transpose_block_group(jobs[j], bits_, block_bytes_)
                                                   : std::vector<std::uint8_t>(jobs[j].begin(), jobs[j].end());
            done[j] = compress_frame(fields, options_.level);
        });
        for (std::size_t j = 0; j < jobs.size(); ++j) frame(done[j], jobs[j].size());
        pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(at));
    }

    AtomicOutputFile out_;
    ZstdOptions options_;
    unsigned bits_;
    std::uint32_t block_bytes_;
    unsigned threads_;
    std::vector<std::uint8_t> pending_;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> entries_;  // (compressed, decompressed) per frame
    std::uint64_t header_at_ = 0, header_bytes_ = 0, logical_ = 0;
};

}  // namespace

std::unique_ptr<FftSink> open_fft_sink(const std::string& path, bool overwrite, const std::optional<ZstdOptions>& zstd,
                                       unsigned direction_bits, std::uint32_t block_bytes, unsigned threads) {
    if (!zstd) return std::make_unique<PlainSink>(path, overwrite);
    return std::make_unique<FftzSink>(path, overwrite, *zstd, direction_bits, block_bytes, threads);
}

}  // namespace fiblet::detail
