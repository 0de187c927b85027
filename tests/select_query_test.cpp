// Selective decoding against brute force: for many random queries, select()
// returns exactly the runs and points that decoding everything and then
// filtering by the documented rules gives; whichever index it uses (stored
// in the file or computed on load), on files from fiblet and from the
// official encoder.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/fiber_regions.hpp"
#include "fiblet/select.hpp"
#include "select_reference.hpp"
#include "test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

// A chunk's streamlines appended in the TRX layout, checking that they lie
// in order inside the chunk's points, without overlapping.
void append_chunk(const SelectedChunk& c, Streamlines& out) {
    std::uint64_t used = 0, total = 0;
    for (std::size_t i = 0; i < c.size(); ++i) {
        EXPECT_GE(c.first[i], used);
        used = c.first[i] + c.count[i];
        EXPECT_LE(3 * used, c.xyz.size());
        total += c.points_of(i);
        out.xyz.insert(out.xyz.end(), c.xyz_of(i), c.xyz_of(i) + 3 * c.points_of(i));
        out.offsets.push_back(out.offsets.back() + c.points_of(i));
    }
    EXPECT_EQ(total, c.point_count());
}

struct Subject {
    std::string name;
    std::unique_ptr<FftFile> file;
    DecodedFile decoded;
    std::unique_ptr<BlockIndex> stored_or_loaded, computed;
};

// Each test process builds only the subject its parameter names (CTest
// runs every test in its own process).
class SelectQuery : public ::testing::TestWithParam<int> {
protected:
    static void TearDownTestSuite() {
        subjects_.clear();
        dir_.reset();
    }
    void SetUp() override {
        if (!shared_data_available()) GTEST_SKIP() << "shared test data not found";
    }
    const Subject& subject() const {
        if (auto it = subjects_.find(GetParam()); it != subjects_.end()) return *it->second;
        if (!dir_) dir_ = std::make_unique<TempDir>();
        auto s = std::make_unique<Subject>();
        std::string fft;
        CompressOptions o;
        o.threads = 2;
        switch (GetParam()) {
            case 0:  // short fibers from a real scan
                s->name = "fiblet dwi-small64d";
                fft = dir_->file("dwi.fft");
                compress_file(shared_data("dwi-small64d-ifod1.tck"), fft, o);
                break;
            case 1:  // long real bundle
                s->name = "fiblet CST_R";
                fft = dir_->file("cst.fft");
                o.direction_bits = 8;  // the default gives it 16 bits: cases 3 and 4 cover those
                compress_file(shared_data("bundles/CST_R-step0.1.tck"), fft, o);
                break;
            case 2:  // written by another tool, no stored index
                s->name = "official small-sdstream";
                fft = shared_data("reference/small-sdstream.fft");
                break;
            case 3:  // 16-bit directions (packed version 17), default 254 points a block
                s->name = "fiblet 16-bit dwi-small64d";
                fft = dir_->file("dwi16.fft");
                o.direction_bits = 16;
                compress_file(shared_data("dwi-small64d-ifod1.tck"), fft, o);
                break;
            case 5:  // a version-2 index (a box per 8 blocks), as fiblet wrote it before version 3
                s->name = "fiblet dwi-small64d, version-2 index";
                fft = std::string(FIBLET_TESTS_DIR) + "/index-v2/dwi-small64d-ifod1.fft";
                break;
            default:  // 16-bit directions, 400 points a block (2-byte counts in the index)
                s->name = "fiblet 16-bit CST_R, 400 points a block";
                fft = dir_->file("cst16.fft");
                o.direction_bits = 16;
                o.points_per_block = 400;
                compress_file(shared_data("bundles/CST_R-step0.1.tck"), fft, o);
        }
        s->file = std::make_unique<FftFile>(fft);
        s->decoded = decode_everything(*s->file);
        s->stored_or_loaded = std::make_unique<BlockIndex>(BlockIndex::load(*s->file));
        s->computed = std::make_unique<BlockIndex>(BlockIndex::compute(*s->file));
        return *(subjects_[GetParam()] = std::move(s));
    }

    // Runs a query with both indexes, reading blocks through the file's
    // mapping with one and with reads with the other, and compares each
    // with brute force.
    void check(const Query& q, const std::string& what) const {
        const Subject& s = subject();
        const ReferenceSelection ref = reference_select(*s.file, s.decoded, q);
        for (const BlockIndex* index : {s.stored_or_loaded.get(), s.computed.get()}) {
            SelectOptions o;
            o.map_file = index == s.stored_or_loaded.get();
            o.chunk_points = 5000;
            Streamlines got;
            std::vector<SelectedRun> runs;
            const SelectionStats stats = select(
                *s.file, *index, q,
                [&](const SelectedChunk& c) {
                    append_chunk(c, got);
                    runs.insert(runs.end(), c.runs.begin(), c.runs.end());
                },
                o);
            expect_same_selection(ref, got, runs, s.name + ": " + what + (o.map_file ? " (mapped)" : " (read)"));
            EXPECT_EQ(stats.runs, runs.size());
            EXPECT_EQ(stats.points, got.point_count());
            std::uint64_t blocks = 0;
            for (const auto& r : runs) blocks += r.block_count;
            EXPECT_EQ(stats.blocks, blocks);
        }
    }

    static inline std::unique_ptr<TempDir> dir_;
    static inline std::map<int, std::unique_ptr<Subject>> subjects_;
};

TEST_P(SelectQuery, EmptyQueryGivesTheWholeFile) {
    const Subject& s = subject();
    std::vector<SelectedRun> runs;
    const Streamlines got = select_streamlines(*s.file, *s.stored_or_loaded, Query{}, &runs);
    EXPECT_EQ(got.xyz, s.decoded.points.xyz);
    EXPECT_EQ(got.offsets, s.decoded.points.offsets);
    EXPECT_EQ(runs.size(), s.file->header().fibers);
}

TEST_P(SelectQuery, FiberSubsetsMatchBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 11);
    const std::uint64_t n = s.file->header().fibers;
    for (int i = 0; i < 12; ++i) {
        Query q;
        const int kind = i % 4;
        if (kind == 0 || kind == 3) {
            for (int r = 0; r < 3; ++r) {
                const auto a = std::uint64_t(gen.uniform(0, float(n + 5)));
                q.fibers.push_back({a, a + std::uint64_t(gen.uniform(0, float(n) / 4))});
            }
        }
        if (kind == 1 || kind == 3) {
            q.min_length_mm = gen.uniform(0, 100);
            if (i % 2) q.max_length_mm = *q.min_length_mm + gen.uniform(0, 80);
        }
        if (kind == 2 || kind == 3) {
            q.random_fraction = gen.uniform(0, 1);
            q.random_seed = std::uint64_t(i) * 7919;
        }
        check(q, "fiber subset " + std::to_string(i));
    }
}

TEST_P(SelectQuery, RandomFractionIsReproducibleAndAboutRight) {
    const Subject& s = subject();
    Query q;
    q.random_fraction = 0.3;
    q.random_seed = 42;
    const auto a = select_runs(*s.file, *s.stored_or_loaded, q);
    const auto b = select_runs(*s.file, *s.computed, q);
    ASSERT_EQ(a.size(), b.size());
    const double n = double(s.file->header().fibers);
    EXPECT_NEAR(double(a.size()) / n, 0.3, 4 * std::sqrt(0.3 * 0.7 / n));
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i].fiber, b[i].fiber);
    q.random_seed = 43;
    const auto c = select_runs(*s.file, *s.stored_or_loaded, q);
    std::size_t same = 0;
    for (std::size_t i = 0; i < std::min(a.size(), c.size()); ++i) same += a[i].fiber == c[i].fiber;
    EXPECT_LT(same, a.size());  // another seed, another subset
}

TEST_P(SelectQuery, FiberRegionsMatchBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 21);
    int nonempty = 0;
    for (int i = 0; i < 16; ++i) {
        Query q;
        const int includes = i % 5 == 4 ? 0 : 1 + i % 3;
        for (int k = 0; k < includes; ++k) q.include.push_back(gen.region());
        for (int k = 0; k < i % 3; ++k) q.exclude.push_back(gen.region());
        const ReferenceSelection ref = reference_select(*s.file, s.decoded, q);
        nonempty += !ref.runs.empty();
        check(q, "fiber regions " + std::to_string(i));
    }
    EXPECT_GT(nonempty, 4);  // the generator makes queries that keep something
}

// tckedit's -ends_only, -inverse, -skip and -number, alone and mixed with
// the other fiber criteria and a view.
TEST_P(SelectQuery, EndsInverseSkipAndNumberMatchBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 31);
    const std::uint64_t n = s.file->header().fibers;
    int nonempty = 0;
    for (int i = 0; i < 16; ++i) {
        Query q;
        for (int k = 0; k < 1 + i % 2; ++k) q.include.push_back(gen.region());
        if (i % 3 == 1) q.exclude.push_back(gen.region());
        q.ends_only = i % 2 == 0;
        q.inverse = i % 4 >= 2;
        if (i % 5 == 1) q.min_length_mm = gen.uniform(20, 90);
        if (i % 3 == 2) q.skip = std::uint64_t(gen.uniform(0, float(n) / 3));
        if (i % 3 != 0) q.number = std::uint64_t(gen.uniform(0, float(n) / 2));
        if (i == 15) q.include.clear(), q.exclude.clear();  // skip / number / inverse on lengths alone
        if (i == 7) {
            ViewSelection v;
            v.camera.position = {0, -200, 0}, v.camera.target = {0, 0, 0}, v.camera.up = {0, 0, 1};
            q.view = v;
        }
        nonempty += !reference_select(*s.file, s.decoded, q).runs.empty();
        check(q, "ends/inverse/skip/number " + std::to_string(i));
    }
    EXPECT_GE(nonempty, 6);  // random regions rarely hold a fiber's end: half of the queries keep something
}

// FiberRegionTest::decode_kept_into over `candidates` gives the `expected`
// fibers, each with the points of the whole file's decode, and writes
// nothing past the room for the candidates' blocks.
void expect_decoded_kept(const Subject& s, const FiberRegionTest& test, const std::vector<FiberRange>& candidates,
                         const std::vector<std::uint64_t>& expected, unsigned threads, const std::string& what) {
    const Streamlines& all = s.decoded.points;
    std::uint64_t room = 0;
    for (const FiberRange& r : candidates)
        room += (s.file->block_end(r.last + 1) - s.file->first_block(r.first)) * s.file->header().points_per_block;
    const float sentinel = 7777.0f;
    std::vector<float> xyz(3 * room + 8, sentinel);
    std::vector<std::uint64_t> offsets, fibers;
    const std::uint64_t points =
        test.decode_kept_into(candidates, std::span<float>(xyz.data(), 3 * room), offsets, fibers, threads);
    ASSERT_EQ(fibers, expected) << what;
    ASSERT_EQ(offsets.size(), fibers.size() + 1) << what;
    EXPECT_EQ(offsets.back(), points) << what;
    for (std::size_t i = 0; i < fibers.size(); ++i) {
        const std::uint64_t f = fibers[i], n = all.offsets[f + 1] - all.offsets[f];
        ASSERT_EQ(offsets[i + 1] - offsets[i], n) << what << ": fiber " << f;
        EXPECT_EQ(std::memcmp(&xyz[3 * offsets[i]], &all.xyz[3 * all.offsets[f]], 12 * n), 0) << what << ": fiber " << f;
    }
    for (std::size_t i = 3 * room; i < xyz.size(); ++i) ASSERT_EQ(xyz[i], sentinel) << what;
}

// The regions decided by FiberRegionTest::kept_fibers (the index, the
// blocks' anchors, the blocks that may meet a region decoded alone) keep
// what the brute force keeps, with the stored
// and the computed index, on one thread and two, over all fibers and over
// ranges of them; the rule takes kept_fibers on two threads, and on one
// for regions over the whole file, not for a small one.
TEST_P(SelectQuery, FiberRegionTestMatchesBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 41);
    const Streamlines& all = s.decoded.points;
    const std::uint64_t fibers = all.offsets.size() - 1;
    // Two ranges: the first third and the last third.
    const std::vector<FiberRange> thirds{{0, fibers / 3}, {fibers - fibers / 3, fibers - 1}};
    int kept_some = 0;
    for (int i = 0; i < 12; ++i) {
        Query q;
        for (int k = 0; k < 1 + i % 2; ++k) q.include.push_back(gen.region());
        if (i % 3 == 1) q.exclude.push_back(gen.region());
        if (i == 11) q.include.clear();
        const ReferenceSelection ref = reference_select(*s.file, s.decoded, q);
        std::vector<std::uint64_t> expected, expected_in_thirds;
        for (const SelectedRun& r : ref.runs) {
            expected.push_back(r.fiber);
            if (r.fiber <= thirds[0].last || r.fiber >= thirds[1].first) expected_in_thirds.push_back(r.fiber);
        }
        kept_some += !expected.empty();
        for (const BlockIndex* index : {s.stored_or_loaded.get(), s.computed.get()}) {
            const FiberRegionTest test(*s.file, *index, q);
            // The CLI's .fft output: the same runs as select_runs() (a query
            // without regions is select_runs()'s).
            const std::optional<std::vector<SelectedRun>> runs = kept_fiber_runs(*s.file, *index, q, 2);
            ASSERT_EQ(runs.has_value(), !(q.include.empty() && q.exclude.empty())) << s.name << ": query " << i;
            const std::vector<SelectedRun> reference = select_runs(*s.file, *index, q);
            const std::vector<SelectedRun>& got_runs = runs ? *runs : reference;
            ASSERT_EQ(got_runs.size(), reference.size()) << s.name << ": query " << i;
            for (std::size_t r = 0; r < reference.size(); ++r)
                EXPECT_TRUE(got_runs[r].fiber == reference[r].fiber && got_runs[r].first_block == reference[r].first_block &&
                            got_runs[r].block_count == reference[r].block_count && got_runs[r].coarse_blocks == 0)
                    << s.name << ": query " << i << ", run " << r;
            const std::vector<FiberRange> whole{{0, fibers - 1}};
            for (const unsigned threads : {1u, 2u}) {
                EXPECT_EQ(test.kept_fibers(whole, threads), expected) << s.name << ": query " << i << ", " << threads;
                EXPECT_EQ(test.kept_fibers(thirds, threads), expected_in_thirds) << s.name << ": query " << i;
                expect_decoded_kept(s, test, thirds, expected_in_thirds, threads, s.name + ": query " + std::to_string(i));
            }
        }
    }
    EXPECT_GT(kept_some, 4);
    Query everything, tiny;
    everything.include.push_back(Region::sphere({0, 0, 0}, 1e6f));
    tiny.include.push_back(Region::sphere({1e4f, 1e4f, 1e4f}, 1));  // near no block
    EXPECT_TRUE(FiberRegionTest(*s.file, *s.stored_or_loaded, everything).kept_fibers_is_faster(1));
    EXPECT_FALSE(FiberRegionTest(*s.file, *s.stored_or_loaded, tiny).kept_fibers_is_faster(1));
    EXPECT_TRUE(FiberRegionTest(*s.file, *s.stored_or_loaded, tiny).kept_fibers_is_faster(2));
    // kept_fiber_runs: regions alone over fiber ranges (unsorted, past the
    // end: as select() clips them), and no other criterion.
    Query ranged = everything;
    ranged.fibers = {{fibers / 2, fibers + 10}, {0, 1}};
    const auto ranged_runs = kept_fiber_runs(*s.file, *s.stored_or_loaded, ranged, 2);
    ASSERT_TRUE(ranged_runs.has_value());
    EXPECT_EQ(ranged_runs->size(), select_runs(*s.file, *s.stored_or_loaded, ranged).size());
    Query with_length = everything;
    with_length.min_length_mm = 1.0;
    EXPECT_FALSE(kept_fiber_runs(*s.file, *s.stored_or_loaded, with_length, 2).has_value());
    EXPECT_FALSE(kept_fiber_runs(*s.file, *s.stored_or_loaded, tiny, 1).has_value());
    Query bad = everything;
    bad.include.push_back(Region::sphere({0, 0, 0}, -1));
    EXPECT_EQ(error_of([&] { (void)kept_fiber_runs(*s.file, *s.stored_or_loaded, bad, 2); }), Errc::invalid_argument);
    const std::vector<FiberRange> overlapping{{0, 2}, {2, 3}};
    EXPECT_EQ(error_of([&] { (void)FiberRegionTest(*s.file, *s.stored_or_loaded, tiny).kept_fibers(overlapping); }),
              Errc::invalid_argument);
}

TEST_P(SelectQuery, BlockRegionsMatchBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 31);
    for (int i = 0; i < 16; ++i) {
        Query q;
        q.roi_mode = RoiMode::blocks;
        for (int k = 0; k < 1 + i % 3; ++k) q.include.push_back(gen.region());
        if (i % 4 == 3) q.include.clear();
        for (int k = 0; k < i % 2; ++k) q.exclude.push_back(gen.region());
        if (i % 5 == 0) q.random_fraction = 0.5;
        check(q, "block regions " + std::to_string(i));
    }
}

TEST_P(SelectQuery, ViewFrustumAndLevelOfDetailMatchBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 41);
    for (int i = 0; i < 18; ++i) {
        Query q;
        ViewSelection v;
        v.camera = gen.camera();
        v.cull = i % 6 != 5;
        if (i % 3 != 0) {
            v.lod = Viewport{int(gen.uniform(64, 2000)), int(gen.uniform(64, 1200))};
            v.lod_pixels = gen.uniform(0.5f, 40);
        }
        q.view = v;
        if (i % 4 == 1) q.include.push_back(gen.region()), q.roi_mode = RoiMode::blocks;
        if (i % 4 == 2) q.include.push_back(gen.region());
        check(q, "view " + std::to_string(i));
    }
}

TEST_P(SelectQuery, FrustumCullingNeverDropsABlockWithAPointInside) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 51);
    for (int i = 0; i < 10; ++i) {
        Query q;
        q.view = ViewSelection{gen.camera(), true, std::nullopt, kDefaultLodPixels};
        const Frustum f = frustum_from_camera(q.view->camera);
        std::vector<std::uint8_t> kept(s.file->header().blocks, 0);
        for (const auto& r : select_runs(*s.file, *s.stored_or_loaded, q))
            for (std::uint64_t b = r.first_block; b < r.first_block + r.block_count; ++b) kept[b] = 1;
        for (std::size_t b = 0; b < s.decoded.blocks.size(); ++b) {
            const DecodedBlock& blk = s.decoded.blocks[b];
            for (std::uint32_t k = 0; k < blk.points; ++k) {
                const Vec3f p = point_at(s.decoded, blk.first_point + k);
                bool in = true;
                for (const Plane& pl : f.planes) in = in && pl.n.x * p.x + pl.n.y * p.y + pl.n.z * p.z + pl.d >= 0;
                if (in) {
                    ASSERT_TRUE(kept[b]) << "block " << b << " has a point in the frustum";
                    break;
                }
            }
        }
    }
}

TEST_P(SelectQuery, MixedQueriesMatchBruteForce) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 61);
    for (int i = 0; i < 12; ++i) {
        Query q;
        if (i % 2) q.random_fraction = gen.uniform(0.2f, 1), q.random_seed = std::uint64_t(i);
        if (i % 3 == 0) q.min_length_mm = gen.uniform(0, 80);
        q.include.push_back(gen.region());
        if (i % 4 == 0) q.exclude.push_back(gen.region());
        q.roi_mode = i % 2 ? RoiMode::blocks : RoiMode::fibers;
        if (i % 3 != 2) {
            ViewSelection v{gen.camera(), true, std::nullopt, kDefaultLodPixels};
            if (i % 2 == 0) v.lod = Viewport{800, 600}, v.lod_pixels = gen.uniform(1, 30);
            q.view = v;
        }
        check(q, "mixed " + std::to_string(i));
    }
}

TEST_P(SelectQuery, ChunkedOutputEqualsTheWholeOutput) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 71);
    Query q;
    q.view = ViewSelection{gen.camera(), true, Viewport{640, 480}, 6};
    std::vector<SelectedRun> runs;
    const Streamlines whole = select_streamlines(*s.file, *s.stored_or_loaded, q, &runs);
    Streamlines joined;
    std::vector<SelectedRun> joined_runs;
    std::size_t chunks = 0;
    SelectOptions o;
    o.chunk_points = 500;
    select(
        *s.file, *s.stored_or_loaded, q,
        [&](const SelectedChunk& c) {
            ++chunks;
            ASSERT_EQ(c.first.size(), c.runs.size());
            append_chunk(c, joined);
            joined_runs.insert(joined_runs.end(), c.runs.begin(), c.runs.end());
        },
        o);
    EXPECT_EQ(joined.xyz, whole.xyz);
    EXPECT_EQ(joined.offsets, whole.offsets);
    EXPECT_EQ(joined_runs.size(), runs.size());
    if (whole.point_count() > 2000) {
        EXPECT_GT(chunks, 1u);
    }
}

TEST_P(SelectQuery, SubsetFileDecodesToTheSelection) {
    const Subject& s = subject();
    QueryGenerator gen(s.decoded, 81);
    TempDir dir;
    for (int i = 0; i < 4; ++i) {
        Query q;
        q.include.push_back(gen.region());
        q.roi_mode = i % 2 ? RoiMode::blocks : RoiMode::fibers;
        if (i == 3) q.view = ViewSelection{gen.camera(), true, std::nullopt, kDefaultLodPixels};
        std::vector<SelectedRun> runs;
        const Streamlines expected = select_streamlines(*s.file, *s.stored_or_loaded, q, &runs);
        const std::string out = dir.file("subset" + std::to_string(i) + ".fft");
        const SubsetReport rep = write_fft_subset(*s.file, select_runs(*s.file, *s.stored_or_loaded, q), out, false);
        EXPECT_EQ(rep.fibers, runs.size());
        const FftFile subset(out);  // validates header, LUT, trailer and checksums
        EXPECT_TRUE(subset.verifies_checksums());
        EXPECT_EQ(subset.header().points, expected.point_count());
        EXPECT_EQ(subset.properties(), s.file->properties());
        const DecodedFile d = decode_everything(subset);
        EXPECT_EQ(d.points.xyz, expected.xyz);
        EXPECT_EQ(d.points.offsets, expected.offsets);
        // Its blocks carry their new fiber IDs and flags.
        for (std::size_t b = 0; b < d.blocks.size(); ++b) {
            const auto raw = subset.read_blocks(b, 1);
            const bool wide = subset.header().direction_bits() == 16;
            EXPECT_EQ(wide ? BlockView16{raw.data()}.fiber_id() : BlockView{raw.data()}.fiber_id(), d.blocks[b].fiber);
            const BlockFlags flags = block_flags(subset.header(), raw.data());
            EXPECT_EQ(flags.last, d.blocks[b].last_of_fiber);
            EXPECT_EQ(flags.first, b == subset.first_block(d.blocks[b].fiber));
        }
        // A subset of the official encoder's file gets fiblet's index.
        const BlockIndex index = BlockIndex::load(subset);
        EXPECT_EQ(index.source(), BlockIndex::Source::chunk);
        const Query everything;
        EXPECT_EQ(select_streamlines(subset, index, everything).xyz, expected.xyz);
    }
}

INSTANTIATE_TEST_SUITE_P(Files, SelectQuery, ::testing::Values(0, 1, 2, 3, 4, 5));

TEST(SelectQueryErrors, BadQueriesAreRejectedBeforeReading) {
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const FftFile file(shared_data("reference/small-sdstream.fft"));
    const BlockIndex index = BlockIndex::load(file);
    auto rejects = [&](const Query& q) {
        try {
            select_runs(file, index, q);
        } catch (const Error& e) {
            return e.code() == Errc::invalid_argument;
        }
        return false;
    };
    Query q;
    q.random_fraction = 1.5;
    EXPECT_TRUE(rejects(q));
    q = {};
    q.min_length_mm = 50, q.max_length_mm = 10;
    EXPECT_TRUE(rejects(q));
    q = {};
    q.include.push_back(Region::sphere({0, 0, 0}, -1));
    EXPECT_TRUE(rejects(q));
    q = {};
    q.exclude.push_back(Region::box_between({1, 0, 0}, {0, 1, 1}));
    EXPECT_TRUE(rejects(q));
    q = {};
    q.fibers.push_back({10, 5});
    EXPECT_TRUE(rejects(q));
    q = {};
    q.view = ViewSelection{};
    q.view->camera.target = q.view->camera.position;
    EXPECT_TRUE(rejects(q));
    q.view = ViewSelection{};
    q.view->camera.up = {0, 0, 1};  // parallel to the default view direction
    EXPECT_TRUE(rejects(q));
    q.view = ViewSelection{};
    q.view->camera.near_mm = 0;
    EXPECT_TRUE(rejects(q));
    q.view = ViewSelection{};
    q.view->lod = Viewport{0, 10};
    EXPECT_TRUE(rejects(q));
    q = {};
    for (int i = 0; i < 65; ++i) q.include.push_back(Region::sphere({0, 0, 0}, 1));
    EXPECT_TRUE(rejects(q));
    q.roi_mode = RoiMode::blocks;  // no per-fiber mask in blocks mode
    EXPECT_FALSE(rejects(q));
    q.ends_only = true;  // ends-only and inverse decide whole fibers
    EXPECT_TRUE(rejects(q));
    q.ends_only = false, q.inverse = true;
    EXPECT_TRUE(rejects(q));
}

TEST(SelectQueryErrors, LevelOfDetailCannotBeWrittenAsFft) {
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const FftFile file(shared_data("reference/small-sdstream.fft"));
    const BlockIndex index = BlockIndex::load(file);
    Query q;
    q.view = ViewSelection{};
    q.view->camera.position = {0, 0, 3000};
    q.view->camera.far_mm = 5000;
    q.view->lod = Viewport{100, 100};
    const auto runs = select_runs(file, index, q);
    ASSERT_FALSE(runs.empty());
    ASSERT_GT(runs.front().coarse_blocks, 0u);
    TempDir dir;
    EXPECT_THROW(write_fft_subset(file, runs, dir.file("x.fft"), false), Error);
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.fft")));
}

}  // namespace
