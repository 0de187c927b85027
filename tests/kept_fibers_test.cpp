// FiberRegionTest::decode_kept_into across parts and threads: a file of
// several parts (4096 blocks each) decodes to the brute force's fibers
// whatever the threads; a bad block in any part is reported without a
// hang (the parts after it wait for where its points end); a buffer too
// small is refused before anything is written past it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fiber_regions.hpp"
#include "sdstream_file.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

class KeptFibers : public test::SdstreamFile {
protected:
    // A sphere around the file's centre holding about half its points.
    static Query half_sphere(const Streamlines& all) {
        double c[3] = {0, 0, 0};
        for (std::size_t i = 0; i < all.xyz.size(); ++i) c[i % 3] += all.xyz[i];
        const std::size_t n = all.point_count();
        const Vec3f centre{float(c[0] / n), float(c[1] / n), float(c[2] / n)};
        std::vector<float> d2(n);
        for (std::size_t p = 0; p < n; ++p) {
            const float dx = all.xyz[3 * p] - centre.x, dy = all.xyz[3 * p + 1] - centre.y, dz = all.xyz[3 * p + 2] - centre.z;
            d2[p] = dx * dx + dy * dy + dz * dz;
        }
        std::nth_element(d2.begin(), d2.begin() + n / 2, d2.end());
        Query q;
        q.include.push_back(Region::sphere(centre, std::sqrt(d2[n / 2])));
        return q;
    }
};

}  // namespace

TEST_F(KeptFibers, DecodesTheBruteForcesFibersWithAnyThreads) {
    const FftFile file(path_);
    ASSERT_GE(file.header().blocks, 3u * 4096u);  // several parts
    const Streamlines all = decode_fibers(file, 0, file.header().fibers);
    const Query q = half_sphere(all);
    Streamlines expected;
    std::vector<std::uint64_t> expected_fibers;
    for (std::uint64_t f = 0; f < all.size(); ++f) {
        bool in = false;
        for (std::uint64_t p = all.offsets[f]; p < all.offsets[f + 1] && !in; ++p)
            in = q.include[0].contains({all.xyz[3 * p], all.xyz[3 * p + 1], all.xyz[3 * p + 2]});
        if (!in) continue;
        expected_fibers.push_back(f);
        expected.xyz.insert(expected.xyz.end(), &all.xyz[3 * all.offsets[f]], &all.xyz[3 * all.offsets[f + 1]]);
        expected.offsets.push_back(expected.xyz.size() / 3);
    }
    ASSERT_GT(expected_fibers.size(), all.size() / 10);
    ASSERT_LT(expected_fibers.size(), all.size());
    const FiberRegionTest test(file, BlockIndex::load(file), q);
    const std::vector<FiberRange> whole{{0, all.size() - 1}};
    const std::uint64_t room = 3 * std::uint64_t(file.header().blocks) * file.header().points_per_block;
    for (const unsigned threads : {1u, 2u, 3u, 8u}) {
        std::vector<float> xyz(room);
        std::vector<std::uint64_t> offsets, fibers;
        EXPECT_EQ(test.decode_kept_into(whole, xyz, offsets, fibers, threads), expected.point_count());
        EXPECT_EQ(fibers, expected_fibers) << threads;
        EXPECT_EQ(offsets, expected.offsets) << threads;
        EXPECT_EQ(std::memcmp(xyz.data(), expected.xyz.data(), 4 * expected.xyz.size()), 0) << threads;
    }
    // One point short: refused, nothing written past the room given.
    const float sentinel = 7777.0f;
    const std::size_t short_room = expected.xyz.size() - 3;
    std::vector<float> xyz(short_room + 64, sentinel);
    std::vector<std::uint64_t> offsets, fibers;
    EXPECT_EQ(test::error_of([&] {
                  test.decode_kept_into(whole, std::span<float>(xyz.data(), short_room), offsets, fibers, 2);
              }),
              Errc::invalid_argument);
    for (std::size_t i = short_room; i < xyz.size(); ++i) ASSERT_EQ(xyz[i], sentinel);
}

TEST_F(KeptFibers, ABadBlockInAnyPartIsReportedWithoutAHang) {
    const FftFile good(path_);
    const FftHeader& h = good.header();
    const Streamlines all = decode_fibers(good, 0, h.fibers);
    const Query q = half_sphere(all);
    for (const std::uint64_t block : {std::uint64_t{5}, std::uint64_t{h.blocks / 2}, std::uint64_t{h.blocks - 3}}) {
        std::string bytes = test::read_file(path_);
        bytes[h.blocks_offset() + block * h.block_bytes() + kBlockFlagsOffset] = char(0);  // a block of 0 points
        const std::string bad = dir_->file("bad.fft");
        test::write_file(bad, bytes);
        const FftFile file(bad);
        // The good file's index (no read fails before decode_kept_into's);
        // the half sphere and a region over everything.
        Query everything;
        everything.include.push_back(Region::sphere({0, 0, 0}, 1e6f));
        const BlockIndex index = BlockIndex::compute(good);
        const std::vector<FiberRange> whole{{0, h.fibers - 1}};
        std::vector<float> xyz(3 * std::uint64_t(h.blocks) * h.points_per_block);
        std::vector<std::uint64_t> offsets, fibers;
        for (const Query& query : {q, everything})
            for (const unsigned threads : {1u, 2u, 3u})
                EXPECT_TRUE(test::error_of([&] {
                                FiberRegionTest(file, index, query).decode_kept_into(whole, xyz, offsets, fibers, threads);
                            }).has_value())
                << "block " << block << ", threads " << threads;
    }
}
