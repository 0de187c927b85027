// fiblet — what the fuzzers run on each input, shared by the libFuzzer
// entry points (fuzz/*_fuzz.cpp) and the regression test that replays the
// inputs that once crashed (tests/fuzz_regression_test.cpp).
//
// Every target feeds the bytes to the library through its public API as a
// file (a memfd, no disk I/O) and checks invariants that must hold for any
// input: only fiblet::Error may be thrown, results do not depend on chunk
// sizes or on the decoder, what compress writes reads back. A broken
// invariant throws HarnessFailure, which libFuzzer reports as a crash.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/select.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::fuzz {

struct HarnessFailure : std::logic_error {
    using std::logic_error::logic_error;
};

inline void check(bool ok, const char* what) {
    if (!ok) throw HarnessFailure(what);
}

// The input as a file: one memfd per process, rewritten for each input.
class MemFile {
public:
    MemFile() : fd_(::memfd_create("fiblet-fuzz", MFD_CLOEXEC)) {
        if (fd_ < 0) throw std::runtime_error("memfd_create failed");
    }
    ~MemFile() { ::close(fd_); }
    std::string set(const std::uint8_t* data, std::size_t size) {
        if (::ftruncate(fd_, 0) != 0) throw std::runtime_error("ftruncate failed");
        for (std::size_t done = 0; done < size;) {
            const ssize_t n = ::pwrite(fd_, data + done, size - done, off_t(done));
            if (n <= 0) throw std::runtime_error("pwrite failed");
            done += std::size_t(n);
        }
        return "/proc/self/fd/" + std::to_string(fd_);
    }

private:
    int fd_;
};

// A private directory for outputs, removed at exit.
inline const std::string& scratch_dir() {
    struct Dir {
        std::string path = (std::filesystem::temp_directory_path() / "fiblet-fuzz-XXXXXX").string();
        Dir() {
            if (!::mkdtemp(path.data())) throw std::runtime_error("mkdtemp failed");
        }
        ~Dir() {
            std::error_code ec;
            std::filesystem::remove_all(path, ec);
        }
    };
    static const Dir dir;
    return dir.path;
}

// ---------------------------------------------------------------- .tck

struct TckOutcome {
    std::optional<Errc> error;
    std::vector<std::uint32_t> sizes;  // points per streamline
    std::uint64_t hash = 0;            // of every coordinate's bits, in order
    bool operator==(const TckOutcome&) const = default;
};

inline TckOutcome read_tck(const std::string& path, TckReadOptions options, bool twice = false) {
    TckOutcome o;
    try {
        TckReader r(path, options);
        std::vector<Vec3f> f;
        for (int pass = 0; pass < (twice ? 2 : 1); ++pass) {
            if (pass == 1) r.rewind();
            o.sizes.clear();
            o.hash = 1469598103934665603ull;
            while (r.next(f)) {
                o.sizes.push_back(std::uint32_t(f.size()));
                for (const Vec3f& p : f)
                    for (float v : {p.x, p.y, p.z}) {
                        std::uint32_t bits;
                        std::memcpy(&bits, &v, 4);
                        o.hash = (o.hash ^ bits) * 1099511628211ull;
                        check(std::isfinite(v), "the reader returned a non-finite coordinate");
                    }
            }
            check(r.streamlines_read() == o.sizes.size(), "streamlines_read() disagrees with next()");
        }
    } catch (const Error& e) {
        o.error = e.code();
        o.sizes.clear();
        o.hash = 0;
    }
    return o;
}

// The .tck reader: the result must not depend on the read size (down to a
// few points per read: 96 bytes, 8 float32 or 4 float64 points), on a
// rewind, or on allow_count_mismatch for valid files.
inline void tck_target(const std::uint8_t* data, std::size_t size) {
    static MemFile input;
    const std::string path = input.set(data, size);
    TckReadOptions small_reads, lenient;
    small_reads.chunk_bytes = 96;
    lenient.allow_count_mismatch = true;
    const TckOutcome whole = read_tck(path, {});
    check(read_tck(path, small_reads, true) == whole, "result depends on the chunk size or rewind");
    if (!whole.error) check(read_tck(path, lenient) == whole, "allow_count_mismatch changed a valid read");
}

// ---------------------------------------------------------------- .trk, TRX

inline double resampled_points_bound(const std::string& path);

// Whatever compress accepts, every reader accepts: compress the streamline
// file at `path` (any format; `sizes`: its streamlines' point counts as
// read) and check that its output verifies (verify_fft_file: structure,
// every checksum, the index) and decodes to the same fibers, with the same
// point counts unless resampled, every coordinate finite. A refusal must
// leave no output; where `content_refusals_only`, it must also be about the
// content (invalid_input, unsupported), never the format.
inline void compress_reads_back(const std::string& path, const std::vector<std::uint32_t>& sizes,
                                bool content_refusals_only) {
    const double bound = resampled_points_bound(path);
    if (bound > 200000) return;
    const std::string out = scratch_dir() + "/out.fft";
    CompressReport report;
    try {
        CompressOptions options;
        options.threads = 1;
        options.overwrite = true;
        report = compress_file(path, out, options);
    } catch (const Error& e) {
        if (content_refusals_only)
            check(e.code() == Errc::invalid_input || e.code() == Errc::unsupported, "compress failed on a valid input's format");
        check(!std::filesystem::exists(out), "compress left an output after failing");
        return;
    }
    try {
        verify_fft_file(out);
        const FftFile f(out);
        check(f.header().fibers == sizes.size(), "fiber count changed");
        check(f.checksums() != nullptr, "compress wrote no checksum");
        if (report.resampled)
            check(double(f.header().points) <= std::max(bound, 1e4), "resampled beyond resampled_points_bound (slow)");
        std::uint64_t fiber = 0;
        decode_file(f, [&](std::uint64_t first, const Streamlines& s) {
            check(first == fiber, "decode_file skipped fibers");
            for (std::size_t i = 0; i < s.size(); ++i, ++fiber)
                if (!report.resampled) check(s.offsets[i + 1] - s.offsets[i] == sizes[fiber], "point count changed");
            for (float v : s.xyz) check(std::isfinite(v), "decoded a non-finite coordinate from compress output");
        });
        check(fiber == sizes.size(), "decode_file missed fibers");
    } catch (const Error&) {
        throw HarnessFailure("compress wrote a file its own reader refuses");
    }
    std::filesystem::remove(out);
}

// Any file through open_streamline_source (a .trk, a TRX zip, or whatever
// the bytes are): only fiblet::Error; a second pass after rewind() reads the
// same points; the fields match the streamlines read (rows, names, groups);
// then, for small inputs, compress_reads_back.
inline void streamline_source_target(const std::uint8_t* data, std::size_t size) {
    static MemFile input;
    const std::string path = input.set(data, size);
    std::vector<std::uint32_t> read;
    try {
        const auto source = open_streamline_source(path, {.max_points = 1u << 20});
        std::vector<std::uint32_t> sizes[2];
        std::uint64_t points = 0;
        std::vector<Vec3f> f;
        for (int pass = 0; pass < 2; ++pass) {
            if (pass == 1) source->rewind();
            while (source->next(f)) {
                sizes[pass].push_back(std::uint32_t(f.size()));
                if (pass == 0) points += f.size();
            }
            if (pass == 0)
                for (const StreamlineField& field : source->take_fields())
                    check(check_streamline_field(field, sizes[0].size(), points).empty(),
                          "a field does not match the streamlines read");
        }
        check(sizes[0] == sizes[1], "a second pass read other streamlines");
        if (points > 20000) return;
        read = std::move(sizes[0]);
    } catch (const Error&) {
        // any category: the input is malformed, unsupported or unreadable
        return;
    }
    compress_reads_back(path, read, false);
}

// An upper bound on the points compress may resample a .tck into: its
// polyline length over a fifth of the smallest step it may pick (the
// declared step_size or the median spacing, the centre of a narrow
// histogram bin, the float range's end at most; block_keeping_step goes
// down to a quarter). The median is
// LengthHistogram's: the lower median of every segment, zero-length ones
// included (with seven repeated points among sixteen segments it is the
// shortest non-zero one). A few points far apart can stand for millions of
// resampled ones, which the point limit below does not see.
inline double resampled_points_bound(const std::string& path) {
    const auto source = open_streamline_source(path, {});
    StreamlineSource& r = *source;
    std::vector<Vec3f> f;
    std::vector<double> spacing;
    double length = 0;
    while (r.next(f))
        for (std::size_t k = 1; k < f.size(); ++k) {
            const double dx = double(f[k].x) - f[k - 1].x, dy = double(f[k].y) - f[k - 1].y, dz = double(f[k].z) - f[k - 1].z;
            const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
            length += d;
            spacing.push_back(d);
        }
    if (spacing.empty()) return 0;
    const auto median = spacing.begin() + std::ptrdiff_t((spacing.size() - 1) / 2);  // the first with half at or below
    std::nth_element(spacing.begin(), median, spacing.end());
    // Lengths beyond the float range count as its largest in compress's median.
    const double step = std::min({*median, r.step_size().value_or(INFINITY), double(std::numeric_limits<float>::max())});
    if (!(step > 0)) return 0;  // compress refuses a zero step, or has nothing to resample
    return length / (0.2 * step);
}

// The whole compression of small valid .tck inputs, and a decode of what it
// wrote (compress_reads_back).
inline void compress_target(const std::uint8_t* data, std::size_t size) {
    static MemFile input;
    const std::string path = input.set(data, size);
    const TckOutcome whole = read_tck(path, {});
    std::uint64_t points = 0;
    for (auto n : whole.sizes) points += n;
    if (whole.error || points > 20000) return;
    compress_reads_back(path, whole.sizes, true);
}

// ---------------------------------------------------------------- .fft

// Everything decoded, or the error category.
struct FftOutcome {
    std::optional<Errc> error;
    Streamlines s;
};

inline bool same_points(const std::vector<float>& a, const std::vector<float>& b, float tolerance) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::isnan(a[i]) || std::isnan(b[i])) {
            if (std::isnan(a[i]) != std::isnan(b[i])) return false;
        } else if (!(std::fabs(a[i] - b[i]) <= tolerance) && a[i] != b[i]) {
            return false;
        }
    }
    return true;
}

inline FftOutcome decode_whole(const FftFile& f, const DecodeOptions& options) {
    FftOutcome o;
    try {
        decode_file(f, [&](std::uint64_t first, const Streamlines& chunk) {
            check(first == o.s.size(), "decode_file skipped fibers");
            const std::uint64_t base = o.s.point_count();
            o.s.xyz.insert(o.s.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
            for (std::size_t i = 1; i < chunk.offsets.size(); ++i) o.s.offsets.push_back(base + chunk.offsets[i]);
        }, options);
        check(o.s.size() == f.header().fibers, "decode_file missed fibers");
    } catch (const Error& e) {
        o.error = e.code();
        o.s = {};
    }
    return o;
}

// The scalar reference decoder of the file's kind (8- or 16-bit codes).
inline std::size_t scalar_reference(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                    float* xyz) {
    return ctx.header.direction_bits() == 16 ? decode_blocks_scalar16(ctx, blocks, count, xyz)
                                             : decode_blocks_scalar(ctx, blocks, count, xyz);
}

// The scalar reference over all blocks at once, then the fibers' last-step
// fractions (ENDS chunk), fiber offsets from the LUT.
inline FftOutcome decode_reference(const FftFile& f) {
    FftOutcome o;
    try {
        const FftHeader& h = f.header();
        const std::vector<std::uint8_t> blocks = f.read_blocks(0, h.blocks);
        const DecodeContext ctx(h);
        const std::size_t n = count_block_points(ctx, blocks.data(), h.blocks);
        o.s.xyz.resize(3 * n);
        check(scalar_reference(ctx, blocks.data(), h.blocks, o.s.xyz.data()) == n, "scalar decoder count");
        if (f.end_fractions()) apply_fiber_ends(h, *f.end_fractions(), blocks.data(), h.blocks, o.s.xyz.data());
        std::uint64_t acc = 0, b = 0;
        for (std::uint64_t fiber = 0; fiber < h.fibers; ++fiber) {
            for (std::uint32_t k = 0; k < f.block_count(fiber); ++k, ++b)
                acc += block_flags(h, &blocks[b * h.block_bytes()]).point_count;
            o.s.offsets.push_back(acc);
        }
        // A whole file must hold the header's point count (decode_file checks it too).
        if (acc != h.points) throw Error(Errc::fft_format, "point count differs from the header's");
    } catch (const Error& e) {
        o.error = e.code();
        o.s = {};
    }
    return o;
}

// Twice the float-rounding bound of the warp decoder (docs/decode.md,
// "Equivalence") for the longest block and the largest coordinates of the
// file: s (i u P + step (9 i^2 + 6 i) u) + 4 u ((P + 0.5) s + M).
inline float warp_tolerance(const FftHeader& h, const std::vector<float>& xyz) {
    double P = 0, M = 0;
    for (std::size_t k = 0; k < xyz.size(); ++k) {
        M = std::max(M, double(std::fabs(xyz[k])));
        P = std::max(P, std::fabs((double(xyz[k]) + h.offset[k % 3]) / h.scaling + 0.5));
    }
    const double u = std::ldexp(1.0, -24), s = h.scaling, i = h.points_per_block;
    return float(2 * (s * (i * u * P + h.step * (9 * i * i + 6 * i) * u) + 4 * u * ((P + 0.5) * s + M)));
}

// Selective decoding on an opened file: the block index (the BIDX chunk,
// parsed from untrusted bytes, or computed) and queries. A query without
// criteria gives every fiber with points whole; a region query gives fibers of the file.
inline void select_target(const FftFile& f, const Streamlines& all) {
    std::optional<BlockIndex> index;
    try {
        index.emplace(BlockIndex::load(f));
    } catch (const Error& e) {
        check(e.code() == Errc::fft_format || e.code() == Errc::checksum, "BlockIndex::load: unexpected category");
        return;
    }
    check(index->blocks() == f.header().blocks && index->fibers() == f.header().fibers, "index size");
    std::vector<SelectedRun> runs;
    const Streamlines everything = select_streamlines(f, *index, Query{}, &runs);
    // Selection outputs runs of blocks: fibers without points (a file from
    // another writer may hold some) are not in it.
    std::vector<std::uint64_t> non_empty{0};
    for (std::size_t i = 0; i + 1 < all.offsets.size(); ++i)
        if (all.offsets[i + 1] > all.offsets[i]) non_empty.push_back(all.offsets[i + 1]);
    check(everything.offsets == non_empty, "an empty query changed the fibers");
    check(same_points(everything.xyz, all.xyz, 0), "an empty query changed the points");
    if (all.point_count() == 0) return;
    // A sphere around the first point: every fiber kept must hold a point inside it.
    Query q;
    const Vec3f c{all.xyz[0], all.xyz[1], all.xyz[2]};
    q.include.push_back(Region::sphere(c, 0.5f * f.header().scaling * 0.1f + 1e-3f));
    runs.clear();
    const Streamlines near = select_streamlines(f, *index, q, &runs);
    check(runs.size() == near.size(), "runs and streamlines differ");
    for (std::size_t i = 0; i < runs.size(); ++i) {
        check(runs[i].fiber < all.size(), "a run of a fiber past the end");
        bool inside = false;
        for (std::uint64_t k = near.offsets[i]; k < near.offsets[i + 1] && !inside; ++k)
            inside = q.include[0].contains({near.xyz[3 * k], near.xyz[3 * k + 1], near.xyz[3 * k + 2]});
        check(inside, "a fiber kept by a region query has no point inside the region");
    }
    // A camera looking at the first point from a little away: the first
    // block is kept exactly when its view sphere meets the frustum (the
    // frustum walk narrows the block's box to where its first point can be),
    // where the index is the writer's (checksums verified) or computed.
    if (index->source() != BlockIndex::Source::decoded && !f.verifies_checksums()) return;
    const float away = 20 * f.header().step * f.header().scaling;
    Query view;
    view.view = ViewSelection{};
    Camera& camera = view.view->camera;
    camera.target = c, camera.position = {c.x + away, c.y + 0.5f * away, c.z + away};
    camera.near_mm = 0.5f * away, camera.far_mm = 4 * away, camera.fov_y_deg = 10, camera.aspect = 1;
    Sphere first;
    std::vector<SelectedRun> seen;
    try {
        first = block_bounding_sphere(f.header(), f.read_blocks(0, 1).data());
        seen = select_runs(f, *index, view);
    } catch (const Error& e) {
        check(e.code() == Errc::invalid_argument || e.code() == Errc::fft_format || e.code() == Errc::checksum,
              "a view query failed with an unexpected category");
        return;
    }
    const bool kept = !seen.empty() && seen[0].first_block == 0;
    check(kept == sphere_intersects_frustum(frustum_from_camera(camera), first.center, first.radius),
          "a view query disagrees with the first block's sphere");
}

// The .fft reader and every decoder: open (checksums verified or not),
// decode in small chunks with every decoder and compare with the scalar
// reference, decode sub-ranges, verify.
inline void fft_target(const std::uint8_t* data, std::size_t size) {
    static MemFile input;
    const std::string path = input.set(data, size);
    // Opened with checksums verified; when they fail, again without, and
    // when the trailer itself is damaged, without it: so that damaged blocks
    // still reach the decoders.
    bool verified_open = false;
    std::uint64_t logical_size = size;  // a .fftz holds a larger .fft
    const FftOpenOptions modes[] = {{}, {.verify_checksums = false}, {.verify_checksums = false, .ignore_trailer = true}};
    for (const FftOpenOptions& mode : modes) {
        const bool verify = mode.verify_checksums;
        std::optional<FftFile> file;
        try {
            file.emplace(path, mode);
        } catch (const Error& e) {
            if (e.code() == Errc::checksum && !mode.ignore_trailer) continue;
            break;  // malformed: the same without verification
        }
        check(!mode.ignore_trailer || !file->has_trailer(), "ignore_trailer read a trailer");
        // Bytes after the blocks make a file fiblet-written: it never opens without its checksums.
        check(mode.ignore_trailer || file->logical_size() == file->header().file_bytes() || file->checksums(),
              "a file with a trailer opened without a CSUM chunk");
        verified_open |= verify;
        logical_size = file->logical_size();
        const FftFile& f = *file;
        const FftHeader& h = f.header();
        check(h.file_bytes() <= f.logical_size(), "opened a file shorter than its header says");
        check(f.block_end(h.fibers) == h.blocks, "LUT does not cover the blocks");
        if (const auto step = f.resampled_step_mm()) check(std::isfinite(*step) && *step > 0, "unvalidated RSMP step");
        const FftOutcome ref = decode_reference(f);
        DecodeOptions small_chunks;
        small_chunks.chunk_blocks = 3;
        const FftOutcome chunked = decode_whole(f, small_chunks);
        // Both fail or both succeed (the category may differ: a chunked read
        // can meet a checksum mismatch before a malformed block further on).
        check(chunked.error.has_value() == ref.error.has_value(), "decode_file and the reference disagree");
        if (ref.error) {
            if (verify && *ref.error == Errc::checksum) continue;  // decode the damaged blocks unverified
            break;
        }
        check(chunked.s.offsets == ref.s.offsets, "decode_file offsets differ from the reference");
        check(same_points(chunked.s.xyz, ref.s.xyz, 0), "decode_file points differ from the reference");
        // Every decoder this CPU runs (SIMD kinds and levels), with one
        // thread and with several: the same fibers; lanes bit-identical,
        // warp within a few float roundings of the file's scale.
        for (const std::string& name : available_decoders()) {
            for (unsigned threads : {1u, 3u}) {
                DecodeOptions o;
                o.decoder = parse_decoder(name);
                o.threads = threads;
                o.chunk_blocks = 5;
                const FftOutcome got = decode_whole(f, o);
                check(!got.error, "a decoder failed where the reference succeeded");
                check(got.s.offsets == ref.s.offsets, "a decoder's offsets differ from the reference");
                const bool exact = name.rfind("warp", 0) != 0 || h.direction_bits() == 16;  // 16-bit: scalar only
                check(same_points(got.s.xyz, ref.s.xyz, exact ? 0.0f : warp_tolerance(h, ref.s.xyz)),
                      "a decoder's points differ from the reference");
            }
        }
        select_target(f, ref.s);
        // A sub-range decodes to the same slice.
        const std::uint64_t b = h.fibers / 3, e = h.fibers - h.fibers / 4;
        const Streamlines part = decode_fibers(f, b, e);
        check(part.size() == e - b, "decode_fibers range size");
        const std::uint64_t p0 = ref.s.offsets[b];
        for (std::uint64_t i = 0; i <= e - b; ++i)
            check(part.offsets[i] == ref.s.offsets[b + i] - p0, "decode_fibers offsets differ");
        check(same_points(part.xyz, std::vector<float>(ref.s.xyz.begin() + 3 * p0,
                                                       ref.s.xyz.begin() + 3 * ref.s.offsets[e]),
                          0),
              "decode_fibers points differ");
        break;  // decoded: nothing more to see without verification
    }
    if (!verified_open) return;
    try {
        const VerifyReport r = verify_fft_file(path);
        check(r.bytes_read <= logical_size, "verify read more than the file");
    } catch (const Error& e) {
        check(e.code() != Errc::invalid_argument && e.code() != Errc::interrupted, "verify: unexpected category");
    }
}

// ---------------------------------------------------------------- raw blocks

// Input: 13 bytes of file parameters, then blocks.
//   byte 0      bit 7: 16-bit codes (version 16), else 8-bit (version 2);
//               points per block: 2 + (byte & 127) % 62 (8-bit), 2 + (byte & 127) (16-bit)
//   bytes 1-2   ratio: (u16 + 1) / 32768, in (0, 2]
//   bytes 3-4   step: u16 / 65536 normalized units, in [0, 1)
//   bytes 5-6   scaling: 2^(u16 / 65536 * 40 - 20) mm, 1e-6 .. 1e6
//   bytes 7-12  offset: three i16, in units of scaling / 1000
inline constexpr std::size_t kBlocksInputHeader = 13;

inline FftHeader blocks_input_header(const std::uint8_t* p) {
    auto u16 = [&](int i) { return std::uint16_t(p[i] | p[i + 1] << 8); };
    FftHeader h;
    h.version = p[0] & 0x80 ? kFft16Version : kFftVersion;
    h.points_per_block = 2 + (h.version == kFft16Version ? p[0] & 0x7f : (p[0] & 0x7f) % 62);
    h.ratio = float(u16(1) + 1) / 32768.0f;
    h.step = float(u16(3)) / 65536.0f;
    h.scaling = float(std::exp2(double(u16(5)) / 65536.0 * 40.0 - 20.0));
    for (int a = 0; a < 3; ++a) h.offset[a] = float(std::int16_t(u16(7 + 2 * a))) * h.scaling / 1000.0f;
    return h;
}

inline void blocks_target(const std::uint8_t* data, std::size_t size) {
    if (size < kBlocksInputHeader) return;
    const FftHeader h = blocks_input_header(data);
    const std::size_t bb = h.block_bytes(), count = (size - kBlocksInputHeader) / bb;
    std::vector<std::uint8_t> blocks(data + kBlocksInputHeader, data + kBlocksInputHeader + count * bb);
    // A point count outside 1..pointsPerBlock must be rejected; then make it valid.
    const DecodeContext ctx(h);
    const bool wide = h.direction_bits() == 16;
    bool counts_valid = true;
    for (std::size_t b = 0; b < count; ++b) {
        std::uint8_t* flags = &blocks[b * bb + (wide ? kBlock16FlagsOffset : kBlockFlagsOffset)];
        const std::uint32_t n = block_flags(h, &blocks[b * bb]).point_count, fixed = 1 + n % h.points_per_block;
        counts_valid &= n >= 1 && n <= h.points_per_block;
        if (n >= 1 && n <= h.points_per_block) continue;
        if (wide) {  // u16, little-endian: flags in the top two bits, the count below
            const std::uint16_t v = std::uint16_t(((flags[0] | flags[1] << 8) & ~kFlag16CountMask) | fixed);
            flags[0] = std::uint8_t(v), flags[1] = std::uint8_t(v >> 8);
        } else {
            flags[0] = std::uint8_t((flags[0] & ~kFlagCountMask) | fixed);
        }
        check(block_flags(h, &blocks[b * bb]).point_count == fixed, "harness: point count not repaired");
    }
    if (!counts_valid) {
        bool rejected = false;
        try {
            count_block_points(ctx, data + kBlocksInputHeader, count);
        } catch (const Error& e) {
            rejected = e.code() == Errc::fft_format;
        }
        check(rejected, "count_block_points accepted an invalid point count");
    }
    const std::size_t n = count_block_points(ctx, blocks.data(), count);
    std::vector<float> ref(3 * n), one(3 * n);
    check(scalar_reference(ctx, blocks.data(), count, ref.data()) == n, "scalar decoder point count");
    for (float v : ref) check(std::isfinite(v), "the scalar decoder produced a non-finite coordinate");
    // Blocks decode independently: one at a time gives the same points.
    for (std::size_t b = 0, at = 0; b < count; ++b)
        at += 3 * scalar_reference(ctx, blocks.data() + b * bb, 1, one.data() + at);
    check(same_points(one, ref, 0), "a block decoded alone differs");
    for (const std::string& name : available_decoders()) {
        const Decoder d = parse_decoder(name);
        const bool exact = name.rfind("warp", 0) != 0 || wide;  // 16-bit: scalar only
        for (unsigned threads : {1u, 2u}) {
            std::vector<float> got(3 * n + 3, 12345.0f);  // one sentinel point past the end
            check(decode_blocks(ctx, blocks.data(), count, got.data(), d, threads) == n, "decoder point count");
            check(got[3 * n] == 12345.0f && got[3 * n + 2] == 12345.0f, "a decoder wrote past the points");
            got.resize(3 * n);
            check(same_points(got, ref, exact ? 0.0f : warp_tolerance(h, ref)), "a decoder differs from the reference");
        }
    }
}

}  // namespace fiblet::fuzz
