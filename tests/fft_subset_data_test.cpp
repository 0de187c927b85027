// The DATA arrays of a .fft carried into a subset (write_fft_subset, what
// `fiblet extract -o x.fft` writes): per-streamline rows of the kept
// fibers, per-point rows of the kept points, groups listing the kept
// runs, per-group rows as they were. The expected rows come from the
// source TRX as the test built it (its fibers' point counts), not from the
// library's subset code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/select.hpp"
#include "fiblet/trx.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

constexpr std::uint32_t kFibers = 40;

// Fiber f: 5 + 11 f points (up to 434: several 60-point blocks) 0.5 mm
// apart along a circle of radius 50 mm, each fiber shifted.
std::vector<std::vector<Vec3f>> arcs() {
    std::vector<std::vector<Vec3f>> fibers(kFibers);
    for (std::uint32_t f = 0; f < kFibers; ++f)
        for (std::uint32_t k = 0; k < 5 + 11 * f; ++k) {
            const double a = 2 * std::asin(0.25 / 50) * k;
            fibers[f].push_back({float(50 * std::sin(a)), float(50 * (1 - std::cos(a)) + f), 0.3f * float(f)});
        }
    return fibers;
}

StreamlineField uint32_field(const std::string& name, const std::vector<std::uint32_t>& v) {
    StreamlineField f{name, FieldType::uint32, 1, std::vector<std::uint8_t>(v.size() * 4)};
    if (!v.empty()) std::memcpy(f.bytes.data(), v.data(), f.bytes.size());  // memcpy from null is undefined
    return f;
}

std::vector<std::uint32_t> uint32_values(const StreamlineField& f) {
    std::vector<std::uint32_t> v(f.bytes.size() / 4);
    if (!v.empty()) std::memcpy(v.data(), f.bytes.data(), f.bytes.size());  // memcpy from null is undefined
    return v;
}

const StreamlineField& field(const FftFile& file, const std::string& name) {
    for (const StreamlineField& f : file.streamline_fields())
        if (f.name == name) return f;
    throw std::runtime_error("no field " + name);
}

// A TRX whose dps/id is each fiber's index, dpv/at each point's index in
// the file, dpv/rgb three bytes a point, two groups and a dpg row;
// compressed to `fft` (fixed step: no resampling, the same points).
void make_source(const std::string& trx, const std::string& fft, std::vector<std::uint64_t>& starts) {
    const auto fibers = arcs();
    starts.assign(1, 0);
    for (const auto& f : fibers) starts.push_back(starts.back() + f.size());
    const std::uint64_t points = starts.back();
    std::vector<std::uint32_t> ids(kFibers), at(points);
    for (std::uint32_t f = 0; f < kFibers; ++f) ids[f] = f;
    for (std::uint32_t p = 0; p < points; ++p) at[p] = p;
    StreamlineField rgb{"dpv/rgb", FieldType::uint8, 3, std::vector<std::uint8_t>(3 * points)};
    for (std::size_t i = 0; i < rgb.bytes.size(); ++i) rgb.bytes[i] = std::uint8_t(i * 7);
    StreamlineField volume{"dpg/A/volume", FieldType::float32, 1, std::vector<std::uint8_t>(4)};
    const float v = 12.5f;
    std::memcpy(volume.bytes.data(), &v, 4);
    SinkHeader h;
    h.fibers = kFibers, h.points = points;
    h.fields = {uint32_field("dps/id", ids), uint32_field("dpv/at", at), rgb,
                uint32_field("groups/A", {39, 3, 20, 7}), uint32_field("groups/B", {5, 0}), volume};
    {
        TrxWriter w(trx, h, false);
        for (const auto& f : fibers) w.write(&f[0].x, f.size());
        w.finish();
    }
    CompressOptions o;
    o.threads = 1;
    const CompressReport r = compress_file(trx, fft, o);
    ASSERT_FALSE(r.resampled) << "the test's fibers have a fixed step";
    ASSERT_EQ(r.header.points, points);
}

// The source (s.fft) and what `query` keeps of it (sub.fft), in `dir`.
std::vector<SelectedRun> write_subset(const test::TempDir& dir, const Query& query, std::vector<std::uint64_t>& starts) {
    make_source(dir.path() + "/s.trx", dir.path() + "/s.fft", starts);
    const FftFile source(dir.path() + "/s.fft");
    const auto runs = select_runs(source, BlockIndex::load(source), query);
    write_fft_subset(source, runs, dir.path() + "/sub.fft", false);
    return runs;
}

TEST(FftSubsetData, WholeFibersKeepTheirRows) {
    test::TempDir dir;
    std::vector<std::uint64_t> starts;
    Query q;
    q.fibers = {{3, 3}, {5, 5}, {20, 20}};
    std::vector<SelectedRun> runs;
    ASSERT_NO_FATAL_FAILURE(runs = write_subset(dir, q, starts));
    ASSERT_EQ(runs.size(), 3u);
    const FftFile source(dir.path() + "/s.fft");
    const FftFile sub(dir.path() + "/sub.fft");
    EXPECT_EQ(uint32_values(field(sub, "dps/id")), (std::vector<std::uint32_t>{3, 5, 20}));
    std::vector<std::uint32_t> at;
    std::vector<std::uint8_t> rgb;
    const StreamlineField& source_rgb = field(source, "dpv/rgb");
    for (const std::uint64_t f : {3u, 5u, 20u})
        for (std::uint64_t p = starts[f]; p < starts[f + 1]; ++p) {
            at.push_back(std::uint32_t(p));
            rgb.insert(rgb.end(), source_rgb.bytes.begin() + std::ptrdiff_t(3 * p), source_rgb.bytes.begin() + std::ptrdiff_t(3 * p + 3));
        }
    EXPECT_EQ(uint32_values(field(sub, "dpv/at")), at);
    EXPECT_EQ(field(sub, "dpv/rgb").bytes, rgb);
    EXPECT_EQ(field(sub, "dpv/rgb").type, FieldType::uint8);
    EXPECT_EQ(uint32_values(field(sub, "groups/A")), (std::vector<std::uint32_t>{0, 2}));  // fibers 3 and 20
    EXPECT_EQ(uint32_values(field(sub, "groups/B")), (std::vector<std::uint32_t>{1}));     // fiber 5
    EXPECT_EQ(field(sub, "dpg/A/volume").bytes, field(source, "dpg/A/volume").bytes);
}

// Blocks mode: a box keeps pieces of fibers, a fiber in several pieces;
// each piece's per-point rows are those of its points in the source.
TEST(FftSubsetData, PiecesOfFibersKeepTheirPointsRows) {
    test::TempDir dir;
    std::vector<std::uint64_t> starts;
    Query q;
    q.roi_mode = RoiMode::blocks;
    q.include = {Region::box_between({40, -1, -1}, {70, 100, 100}), Region::box_between({-60, -1, -1}, {-30, 200, 100})};
    std::vector<SelectedRun> runs;
    ASSERT_NO_FATAL_FAILURE(runs = write_subset(dir, q, starts));
    ASSERT_GT(runs.size(), 10u);
    const FftFile source(dir.path() + "/s.fft");
    const FftFile sub(dir.path() + "/sub.fft");
    const Streamlines got = decode_fibers(sub, 0, sub.header().fibers);
    const Streamlines all = decode_fibers(source, 0, source.header().fibers);
    const auto ids = uint32_values(field(sub, "dps/id"));
    const auto at = uint32_values(field(sub, "dpv/at"));
    ASSERT_EQ(ids.size(), got.size());
    ASSERT_EQ(at.size(), got.point_count());
    std::size_t pieces_after_the_start = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        const std::uint64_t first = at[got.offsets[i]], f = ids[i];
        ASSERT_LT(f, kFibers);
        pieces_after_the_start += first > starts[f];
        for (std::uint64_t k = got.offsets[i]; k < got.offsets[i + 1]; ++k) {
            // Consecutive points of the piece's own fiber, decoded where the source decodes them.
            const std::uint64_t p = first + (k - got.offsets[i]);
            ASSERT_EQ(at[k], p) << "piece " << i;
            ASSERT_GE(p, starts[f]);
            ASSERT_LT(p, starts[f + 1]);
            for (int c = 0; c < 3; ++c) ASSERT_EQ(got.xyz[3 * k + c], all.xyz[3 * p + c]) << "piece " << i << " point " << k;
        }
    }
    EXPECT_GT(pieces_after_the_start, 5u);  // the test sees pieces that start inside their fiber
    EXPECT_GT(got.size(), std::set<std::uint32_t>(ids.begin(), ids.end()).size());  // and fibers in two pieces
    // Each group lists every piece of its fibers, and nothing else.
    for (const auto& [name, fibers] : {std::pair{"groups/A", std::vector<std::uint32_t>{3, 7, 20, 39}},
                                       std::pair{"groups/B", std::vector<std::uint32_t>{0, 5}}}) {
        std::vector<std::uint32_t> expected;
        for (std::uint32_t i = 0; i < ids.size(); ++i)
            if (std::find(fibers.begin(), fibers.end(), ids[i]) != fibers.end()) expected.push_back(i);
        EXPECT_EQ(uint32_values(field(sub, name)), expected) << name;
    }
}

}  // namespace
}  // namespace fiblet
