#include "fiblet/fft_subset.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <utility>

#include "fiblet/block_index.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/streamline_data_chunk.hpp"
#include "container/packed_blocks16.hpp"
#include "container/fft_writer.hpp"
#include "select/block_decoder.hpp"

namespace fiblet {

namespace {

// Gives a copied block its place in the new file: fiber ID, first/last
// flags and (8-bit blocks) index in the fiber; its points stay as they are.
void place_block(const FftHeader& h, std::uint8_t* b, std::uint32_t id, std::uint32_t k, std::uint32_t count) {
    const bool not_first = k > 0, not_last = k + 1 < count;
    if (h.direction_bits() == 16) {
        std::uint8_t* p = b + kBlock16FiberIdOffset;
        p[0] = std::uint8_t(id), p[1] = std::uint8_t(id >> 8), p[2] = std::uint8_t(id >> 16), p[3] = std::uint8_t(id >> 24);
        const auto flags = std::uint16_t((BlockView16{b}.flags() & kFlag16CountMask) | (not_first ? kFlag16NotFirst : 0) |
                                         (not_last ? kFlag16NotLast : 0));
        b[kBlock16FlagsOffset] = std::uint8_t(flags), b[kBlock16FlagsOffset + 1] = std::uint8_t(flags >> 8);
        return;
    }
    b[kBlockFiberIdOffset] = std::uint8_t(id >> 24), b[kBlockFiberIdOffset + 1] = std::uint8_t(id >> 16);
    b[kBlockFiberIdOffset + 2] = std::uint8_t(id >> 8), b[kBlockFiberIdOffset + 3] = std::uint8_t(id);
    b[kBlockFlagsOffset] = std::uint8_t((not_first ? kFlagNotFirst : 0) | (not_last ? kFlagNotLast : 0) |
                                        (b[kBlockFlagsOffset] & kFlagCountMask));
    b[kBlockIndexOffset] = std::uint8_t(k);  // modulo 256, as the format stores it
}

// Version 17's LUT holds point counts: a run's blocks are full but its last,
// which is read for its count.
std::uint32_t run_points(const FftFile& source, const SelectedRun& r) {
    const auto last = source.read_blocks(r.first_block + r.block_count - 1, 1);
    return (r.block_count - 1) * source.header().points_per_block + BlockView16{last.data()}.point_count();
}

// The kept fibers' last-step fractions: a run that stops before its fiber's
// last block ends on a whole step (its last block was a middle one).
TrailerChunk subset_end_fractions(const FftFile& source, const std::vector<SelectedRun>& runs) {
    const FiberEndFractions& src = *source.end_fractions();
    FiberEndFractions kept(runs.size(), kWholeLastStep);
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const SelectedRun& r = runs[i];
        if (r.first_block + r.block_count == source.first_block(r.fiber) + source.block_count(r.fiber))
            kept[i] = src[r.fiber];
    }
    return make_fiber_ends_chunk(kept);
}

// Where each fiber's points start among the file's points (fibers + 1
// entries): a fiber's blocks hold points_per_block points each but the last
// (FftFile checks it), whose count is read.
std::vector<std::uint64_t> fiber_point_starts(const FftFile& source) {
    const FftHeader& h = source.header();
    std::vector<std::uint64_t> starts(h.fibers + 1, 0);
    std::vector<std::uint8_t> last(h.block_bytes());
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        const std::uint32_t count = source.block_count(f);
        std::uint64_t n = 0;
        if (count > 0) {
            source.read_blocks(source.first_block(f) + count - 1, 1, last.data());
            n = std::uint64_t(count - 1) * h.points_per_block + block_flags(h, last.data()).point_count;
        }
        starts[f + 1] = starts[f] + n;
    }
    return starts;
}

// The source's DATA arrays for the runs (formats/fft-data.md): each run gets
// its fiber's per-streamline row and its own points' per-point rows; a
// group lists the runs of its fibers; per-group rows stay as they are.
// run_points[i]: the points of run i.
TrailerChunk subset_streamline_data(const FftFile& source, const std::vector<SelectedRun>& runs,
                                    const std::vector<std::uint32_t>& run_points) {
    const FftHeader& h = source.header();
    const std::vector<StreamlineField>& fields = source.streamline_fields();
    const bool per_point = std::any_of(fields.begin(), fields.end(),
                                       [](const StreamlineField& f) { return f.scope() == FieldScope::point; });
    const std::vector<std::uint64_t> starts = per_point ? fiber_point_starts(source) : std::vector<std::uint64_t>{};
    // (fiber, run) in fiber order: a group's fibers' runs.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> by_fiber;
    std::vector<StreamlineField> kept;
    for (const StreamlineField& f : fields) {
        StreamlineField out{f.name, f.type, f.components, {}};
        const std::size_t row = std::size_t(f.components) * f.value_size();
        auto copy_rows = [&](std::uint64_t first, std::uint64_t count) {
            out.bytes.insert(out.bytes.end(), f.bytes.begin() + std::ptrdiff_t(first * row),
                             f.bytes.begin() + std::ptrdiff_t((first + count) * row));
        };
        switch (*f.scope()) {
            case FieldScope::streamline:
                for (const SelectedRun& r : runs) copy_rows(r.fiber, 1);
                break;
            case FieldScope::point:
                for (std::size_t i = 0; i < runs.size(); ++i) {
                    const std::uint64_t in_fiber = (runs[i].first_block - source.first_block(runs[i].fiber)) * h.points_per_block;
                    copy_rows(starts[runs[i].fiber] + in_fiber, run_points[i]);
                }
                break;
            case FieldScope::group: {
                if (by_fiber.empty()) {
                    for (std::size_t i = 0; i < runs.size(); ++i) by_fiber.emplace_back(runs[i].fiber, std::uint32_t(i));
                    std::sort(by_fiber.begin(), by_fiber.end());
                }
                std::vector<std::uint32_t> members;
                for (std::uint64_t v = 0; v < f.rows(); ++v) {
                    const auto fiber = std::uint64_t(f.at(v, 0));
                    auto at = std::lower_bound(by_fiber.begin(), by_fiber.end(), std::make_pair(fiber, std::uint32_t(0)));
                    for (; at != by_fiber.end() && at->first == fiber; ++at) members.push_back(at->second);
                }
                std::sort(members.begin(), members.end());
                for (const std::uint32_t i : members)
                    for (int b = 0; b < 4; ++b) out.bytes.push_back(std::uint8_t(i >> (8 * b)));
                break;
            }
            case FieldScope::group_data: out.bytes = f.bytes; break;
        }
        kept.push_back(std::move(out));
    }
    return make_streamline_data_chunk(kept);
}

// The new file's fiber table: each run's blocks as one fiber.
std::vector<FiberLutEntry> plan_runs(FftHeader& h, const FftFile& source, const std::vector<SelectedRun>& runs,
                                     const std::string& path) {
    return detail::plan_fiber_table(h, runs.size(), [&](std::size_t i) {
        const SelectedRun& r = runs[i];
        if (r.coarse_blocks > 0)
            throw Error(Errc::invalid_argument, "a level of detail (coarse blocks) cannot be stored in a .fft file");
        if (r.fiber >= source.header().fibers || r.block_count == 0 || r.block_count > 0xffff ||
            r.first_block < source.first_block(r.fiber) ||
            r.first_block + r.block_count > source.first_block(r.fiber) + source.block_count(r.fiber))
            throw Error(Errc::invalid_argument, "run " + std::to_string(i) + " is not a block range of its fiber");
        return detail::FiberBlocks{r.block_count, h.packed() ? run_points(source, r) : 0};
    }, path);
}

// copy_run's buffers, reused from run to run.
struct CopyScratch {
    std::vector<std::uint8_t> raw, packed;
    std::vector<std::uint32_t> packed_sizes;
    std::vector<float> xyz;
};

// Run i's blocks, read, renamed as fiber i and written; the block index
// gets their decoded points, h and `points` their point counts.
void copy_run(const FftFile& source, const DecodeContext& ctx, const SelectedRun& r, std::uint32_t i, FftHeader& h,
              detail::FftWriter& out, IndexBuilder& index, std::uint32_t& points, CopyScratch& scratch) {
    const std::uint32_t bb = h.block_bytes();
    auto& [raw, packed, packed_sizes, xyz] = scratch;
    raw.resize(std::size_t(r.block_count) * bb);
    source.read_blocks(r.first_block, r.block_count, raw.data());
    xyz.resize(3 * count_block_points(ctx, raw.data(), r.block_count));
    detail::decode_selected_blocks(ctx, raw.data(), r.block_count, xyz.data());
    const float* p = xyz.data();
    for (std::uint32_t k = 0; k < r.block_count; ++k) {
        std::uint8_t* b = &raw[std::size_t(k) * bb];
        const std::uint32_t n = block_flags(h, b).point_count;
        place_block(h, b, i, k, r.block_count);
        index.add_block(p, n, k + 1 == r.block_count);
        p += 3 * n;
        h.points += n;
        points += n;
    }
    if (!h.packed()) return out.write_blocks(raw);
    packed.clear();
    packed_sizes.clear();
    detail::pack_blocks16(h, raw, packed, &packed_sizes);
    out.write_packed_blocks(packed, packed_sizes);
}

}  // namespace

SubsetReport write_fft_subset(const FftFile& source, const std::vector<SelectedRun>& runs, const std::string& path,
                              bool overwrite, BlockIndexFormat index_format) {
    if (runs.size() > std::numeric_limits<std::uint32_t>::max())
        throw Error(Errc::unsupported, path + ": more than 2^32 - 1 fibers (fiber IDs are 32-bit)");
    FftHeader h = source.header();
    h.fibers = runs.size();
    h.points = 0;  // counted as the blocks are copied
    const std::vector<FiberLutEntry> lut = plan_runs(h, source, runs, path);
    detail::FftWriter out(path, overwrite, std::nullopt, h, lut);
    const DecodeContext ctx(source);
    IndexBuilder index(h, index_format);
    std::vector<std::uint32_t> run_points(runs.size(), 0);
    CopyScratch scratch;
    for (std::size_t i = 0; i < runs.size(); ++i)
        copy_run(source, ctx, runs[i], std::uint32_t(i), h, out, index, run_points[i], scratch);
    std::vector<TrailerChunk> chunks;
    for (const auto tag : {kPropertiesTag, kResampledTag})
        if (const TrailerChunk* c = source.find_chunk(tag)) chunks.push_back(*c);
    if (source.end_fractions()) chunks.push_back(subset_end_fractions(source, runs));
    if (!source.streamline_fields().empty()) chunks.push_back(subset_streamline_data(source, runs, run_points));
    if (auto bidx = index.finish()) chunks.push_back(std::move(*bidx));
    const SubsetReport report{h.fibers, h.blocks, h.points, out.finish(h, std::move(chunks))};
    out.commit();
    return report;
}

}  // namespace fiblet
