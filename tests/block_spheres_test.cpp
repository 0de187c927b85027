// detail::block_spheres (the view spheres a selection computes for every
// candidate block, four at a time with AVX2) against block_bounding_sphere,
// one block at a time, and against the sphere's definition in long double.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "fiblet/fft_format.hpp"
#include "fiblet/view.hpp"
#include "index/block_spheres.hpp"
#include "scoped_simd_loops.hpp"

namespace fiblet {
namespace {

// Headers of every scale: sub-millimetre files, brain-sized ones, and one
// whose blocks reach past the float range (the radius saturates).
std::vector<FftHeader> headers() {
    std::vector<FftHeader> out;
    for (const float scaling : {0.25f, 180.0f, 3.5e3f, 3e37f}) {
        FftHeader h;
        h.scaling = scaling;
        h.offset = {-0.4f * scaling, 13.0f, -0.5f * scaling};
        h.step = 0.1f / scaling * 60;
        out.push_back(h);
    }
    return out;
}

// Random 76-byte blocks: every anchor byte random, some anchors at 0 and
// at 65535, point counts 0 to 63 (the 6-bit field: past the layout's 60 too).
std::vector<std::vector<std::uint8_t>> random_blocks(std::size_t n, std::mt19937& rng) {
    std::vector<std::vector<std::uint8_t>> blocks(n, std::vector<std::uint8_t>(fft_block_bytes(kDefaultPointsPerBlock)));
    std::uniform_int_distribution<int> byte(0, 255);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::uint8_t& b : blocks[i]) b = std::uint8_t(byte(rng));
        if (i % 7 == 0) std::memset(blocks[i].data(), i % 14 ? 0xff : 0x00, 12);
        blocks[i][kBlockFlagsOffset] = std::uint8_t((blocks[i][kBlockFlagsOffset] & ~kFlagCountMask) | (i * 5 % 64));
    }
    return blocks;
}

TEST(BlockSpheres, EqualBlockBoundingSphereBitForBit) {
    std::mt19937 rng(11);
    for (const FftHeader& h : headers())
        for (std::size_t n = 0; n <= 37; n += (n < 9 ? 1 : 7)) {  // every remainder of four, and longer runs
            const auto blocks = random_blocks(n, rng);
            std::vector<const std::uint8_t*> pointers;
            for (const auto& b : blocks) pointers.push_back(b.data());
            for (const bool avx2 : {true, false}) {
                SCOPED_TRACE(testing::Message() << "scaling " << h.scaling << " n " << n << " avx2 " << avx2);
                const test::ScopedSimdLoops loops(avx2);
                std::vector<Sphere> spheres(n);
                detail::block_spheres(h, pointers.data(), n, spheres.data());
                for (std::size_t i = 0; i < n; ++i) {
                    const Sphere one = block_bounding_sphere(h, pointers[i]);
                    EXPECT_EQ(std::memcmp(&spheres[i], &one, sizeof(Sphere)), 0) << "block " << i;
                }
            }
        }
}

// The definition, independently: centred on the first anchor, a radius
// that reaches the second anchor plus a step for every point after it
// (float-rounded up), saturated at the largest float.
TEST(BlockSpheres, HoldTheirBlockWhateverTheScale) {
    std::mt19937 rng(12);
    for (const FftHeader& h : headers()) {
        const auto blocks = random_blocks(64, rng);
        std::vector<const std::uint8_t*> pointers;
        for (const auto& b : blocks) pointers.push_back(b.data());
        std::vector<Sphere> spheres(blocks.size());
        detail::block_spheres(h, pointers.data(), blocks.size(), spheres.data());
        for (std::size_t i = 0; i < blocks.size(); ++i) {
            const BlockView v{pointers[i]};
            const auto a = v.anchors_normalized();
            long double world[6];
            for (int k = 0; k < 6; ++k)
                world[k] = ((long double)a[k] - 0.5L) * h.scaling - h.offset[std::size_t(k % 3)];
            // The float to_world rounds (v - 0.5) * scaling and then the offset's subtraction.
            const double rounding = 1e-6 * (double(h.scaling) + std::fabs(double(h.offset[0])));
            EXPECT_NEAR(double(spheres[i].center.x), double(world[0]), rounding) << "block " << i;
            const std::uint32_t n = v.point_count();
            if (n < 2) {
                EXPECT_EQ(spheres[i].radius, 0.0f);
                continue;
            }
            const long double reach = std::sqrt((world[3] - world[0]) * (world[3] - world[0]) +
                                                (world[4] - world[1]) * (world[4] - world[1]) +
                                                (world[5] - world[2]) * (world[5] - world[2])) +
                                      (long double)(n - 2) * h.step * h.scaling;
            if (reach >= (long double)std::numeric_limits<float>::max())
                EXPECT_EQ(spheres[i].radius, std::numeric_limits<float>::max());
            else
                EXPECT_GE((long double)spheres[i].radius, reach * (1 - 1e-6L)) << "block " << i;
        }
    }
}

}  // namespace
}  // namespace fiblet
