// The version-4 box stream (formats/fft-index.md §2): any boxes on any grid
// come back exactly (moves, boxes coded whole, unbounded ones, every grid
// size), and damaged streams are refused or decode to boxes on the grid,
// never read out of bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "index/box_rans.hpp"

using namespace fiblet;
using namespace fiblet::detail;

namespace {

struct Boxes {
    std::vector<std::optional<GridBox>> boxes;
    std::vector<bool> first;
};

// Fibers of random walks on a grid of `levels` cells: boxes that touch the
// previous one (moves of -2..2 cells, as consecutive blocks make), jumps
// past that (coded whole), and now and then an unbounded box.
Boxes random_boxes(std::uint32_t levels, std::size_t blocks, std::uint32_t seed) {
    std::mt19937 rng(seed);
    auto uniform = [&](std::uint32_t n) { return std::uint32_t(rng() % n); };
    Boxes out;
    GridBox box;
    for (std::size_t b = 0; b < blocks; ++b) {
        const bool first = b == 0 || uniform(12) == 0;
        out.first.push_back(first);
        if (uniform(50) == 0) {
            out.boxes.push_back(std::nullopt);
            continue;
        }
        for (int a = 0; a < 3; ++a) {
            const bool jump = first || uniform(20) == 0;
            const auto lo = std::int64_t(jump ? uniform(levels) : std::uint32_t(box.lo[a] + uniform(5)) - 2);
            const auto extent = std::int64_t(jump ? uniform(16) : box.extent[a] + std::int64_t(uniform(5)) - 2);
            box.lo[a] = std::uint16_t(std::clamp<std::int64_t>(lo, 0, levels - 1));
            box.extent[a] = std::uint8_t(std::clamp<std::int64_t>(extent, 0, kMaxBoxExtent));
        }
        out.boxes.push_back(box);
    }
    return out;
}

std::vector<std::uint64_t> packed(const Boxes& b) {
    std::vector<std::uint64_t> out;
    for (const auto& box : b.boxes) out.push_back(box ? pack_cells(*box) : kUnboundedCells);
    return out;
}

std::vector<std::uint8_t> encoded(const Boxes& b, std::uint32_t levels) {
    return encode_box_rans(packed(b), b.first, levels);
}

TEST(BoxRans, RandomBoxesComeBackExactlyOnEveryGridSize) {
    for (const std::uint32_t levels : {1u, 2u, 3u, 30u, 31u, 32u, 700u, kMaxGridLevels}) {
        for (const std::size_t blocks : {std::size_t{1}, std::size_t{7}, std::size_t{5000}}) {
            const Boxes in = random_boxes(levels, blocks, levels * 7 + std::uint32_t(blocks));
            const std::vector<std::uint8_t> stream = encoded(in, levels);
            const DecodedBoxes out = decode_box_rans(stream.data(), stream.size(), in.first, levels);
            ASSERT_EQ(out.error, "") << levels << " levels, " << blocks << " blocks";
            EXPECT_EQ(out.boxes, packed(in)) << levels << " levels, " << blocks << " blocks";
        }
    }
}

TEST(BoxRans, NoBlocksAndOnlyUnboundedBlocksRoundTrip) {
    for (const std::size_t blocks : {std::size_t{0}, std::size_t{3}}) {
        const Boxes in{std::vector<std::optional<GridBox>>(blocks), std::vector<bool>(blocks, true)};
        const std::vector<std::uint8_t> stream = encoded(in, 30);
        const DecodedBoxes out = decode_box_rans(stream.data(), stream.size(), in.first, 30);
        ASSERT_EQ(out.error, "");
        EXPECT_EQ(out.boxes, packed(in));
    }
}

TEST(BoxRans, MovesCostNoMoreThanTheirEntropy) {
    // One fiber whose boxes move by -2..2 cells on each side, mostly not at
    // all (as consecutive blocks move): with a table per previous move, the
    // words stay within 2 % of the moves' order-0 entropy (what a table per
    // axis would reach).
    std::mt19937 rng(3);
    const double p[5] = {0.05, 0.15, 0.6, 0.15, 0.05};  // of moves -2..2
    std::discrete_distribution<int> move(p, p + 5);
    Boxes in;
    GridBox box{{500, 500, 500}, {7, 7, 7}};
    std::array<std::array<double, 25>, 3> count{};  // of the moves coded, per axis
    for (int b = 0; b < 30000; ++b) {
        for (int a = 0; a < 3; ++a) {
            int dlo = move(rng) - 2, dhi = move(rng) - 2;
            const int extent = box.extent[a] + dhi - dlo;
            if (extent < 0 || extent > int(kMaxBoxExtent)) dlo = dhi = 0;
            box.lo[a] = std::uint16_t(box.lo[a] + dlo), box.extent[a] = std::uint8_t(box.extent[a] + dhi - dlo);
            if (b > 0) ++count[a][(dlo + 2) * 5 + dhi + 2];
        }
        in.boxes.push_back(box);
        in.first.push_back(b == 0);
    }
    double entropy = 0;  // bits
    for (const auto& axis : count) {
        double n = 0;
        for (const double c : axis) n += c;
        for (const double c : axis)
            if (c > 0) entropy -= c * std::log2(c / n);
    }
    const std::vector<std::uint8_t> stream = encoded(in, kMaxGridLevels);
    EXPECT_EQ(decode_box_rans(stream.data(), stream.size(), in.first, kMaxGridLevels).boxes, packed(in));
    // The words after the tables (87 of them: a count, then 3 bytes a
    // symbol), less the 3 final states of 8 bytes.
    std::size_t at = 0;
    for (int t = 0; t < 87; ++t) at += 1 + 3 * std::size_t(stream.at(at));
    ASSERT_LE(at + 24, stream.size());
    EXPECT_LT(8.0 * double(stream.size() - at - 24), 1.02 * entropy);
}

TEST(BoxRans, TruncatedExtendedOrForeignStreamsAreRefused) {
    const Boxes in = random_boxes(30, 3000, 11);
    const std::vector<std::uint8_t> stream = encoded(in, 30);
    auto error = [&](const std::vector<std::uint8_t>& s, const std::vector<bool>& first) {
        return decode_box_rans(s.data(), s.size(), first, 30).error;
    };
    EXPECT_EQ(error(stream, in.first), "");
    for (const std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{2}, stream.size() / 2, stream.size() - 2,
                                  stream.size() - 1}) {
        const std::vector<std::uint8_t> s(stream.begin(), stream.begin() + std::ptrdiff_t(cut));
        EXPECT_NE(error(s, in.first), "") << "cut at " << cut;
    }
    auto longer = stream;
    longer.insert(longer.end(), {0x12, 0x34});
    EXPECT_NE(error(longer, in.first), "");
    // The same stream read with other fiber starts (another file's LUT).
    auto other = in.first;
    other[1] = !other[1];
    EXPECT_NE(error(stream, other), "");
    EXPECT_NE(error(stream, std::vector<bool>(in.first.size() + 1, false)), "");
}

TEST(BoxRans, DamagedBytesAreRefusedOrDecodeToBoxesOnTheGrid) {
    const Boxes in = random_boxes(30, 2000, 5);
    const std::vector<std::uint8_t> stream = encoded(in, 30);
    std::mt19937 rng(17);
    int refused = 0;
    for (int i = 0; i < 300; ++i) {
        auto s = stream;
        s[rng() % s.size()] ^= std::uint8_t(1u << (rng() % 8));
        const DecodedBoxes out = decode_box_rans(s.data(), s.size(), in.first, 30);
        if (!out.error.empty()) {
            ++refused;
            continue;
        }
        ASSERT_EQ(out.boxes.size(), in.boxes.size());
        for (const std::uint64_t v : out.boxes) {
            if (v == kUnboundedCells) continue;
            for (int a = 0; a < 3; ++a) ASSERT_LT(cells_lo(v, a), 30u);
        }
    }
    // The final states must come back to where the encoder started them:
    // nearly every damaged word breaks that (a damaged table the boxes never
    // use does not).
    EXPECT_GT(refused, 200);
}

}  // namespace
