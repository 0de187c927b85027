// decodes_finite() against decoding: across the float range of the header's
// scaling, offset and step, wherever it proves a file's points finite, every
// decoder's every coordinate of random blocks and of blocks that walk
// straight from the far corner is finite; and the proof is not vacuous: it
// holds for encoded files, and a header 32 times past its limit overflows.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

float log_uniform(std::mt19937& rng, double lo, double hi) {
    std::uniform_real_distribution<double> e(std::log(lo), std::log(hi));
    return float(std::exp(e(rng)));
}

// Finite header fields, the scaling and offset often near the float maximum
// (where a walk may overflow), the step from tiny to ten times the box.
FftHeader extreme_header(std::mt19937& rng, std::uint8_t version, std::uint32_t points_per_block) {
    std::uniform_real_distribution<float> u(0, 1);
    FftHeader h;
    h.version = version;
    h.points_per_block = points_per_block;
    h.scaling = log_uniform(rng, 1e-3, 3e38);
    if (u(rng) < 0.7f) h.scaling = log_uniform(rng, 1e35, 3e38);
    for (float& o : h.offset) o = (u(rng) < 0.5f ? -1 : 1) * log_uniform(rng, 1e-3, 3e38);
    h.ratio = 0.02f + 1.98f * u(rng);
    h.step = log_uniform(rng, 1e-6, 10);
    return h;
}

// The code nearest straight ahead: a walk that goes as far as a block can.
unsigned straight_code(const FftHeader& h) {
    if (h.direction_bits() == 16) return make_direction_table16(h)->nearest_code({1, 0, 0});
    return DirectionTable(h.ratio).nearest_code({1, 0, 0});
}

// Block `b` of `data`: full, anchors at the far corner (every word at its
// maximum, so the first axis falls back to +x), then `code` or random codes.
void fill_block(std::mt19937& rng, const FftHeader& h, std::uint8_t* block, bool straight, unsigned code) {
    std::uniform_int_distribution<int> byte(0, 255);
    const bool wide = h.direction_bits() == 16;
    const std::size_t anchors = wide ? 18 : 12, flags = wide ? kBlock16FlagsOffset : kBlockFlagsOffset;
    const std::size_t codes = wide ? kBlock16DirectionsOffset : kBlockDirectionsOffset;
    for (std::size_t i = 0; i < anchors; ++i) block[i] = straight ? 0xff : std::uint8_t(byte(rng));
    block[flags] = std::uint8_t(h.points_per_block);
    for (std::uint32_t k = 0; k + 2 < h.points_per_block; ++k) {
        const unsigned c = straight ? code : unsigned(byte(rng) | byte(rng) << 8);
        if (wide)
            block[codes + 2 * k] = std::uint8_t(c), block[codes + 2 * k + 1] = std::uint8_t(c >> 8);
        else
            block[codes + k] = std::uint8_t(c);
    }
}

std::vector<std::uint8_t> probe_blocks(std::mt19937& rng, const FftHeader& h, std::size_t count) {
    std::vector<std::uint8_t> data(count * h.block_bytes(), 0);
    const unsigned code = straight_code(h);
    for (std::size_t b = 0; b < count; ++b) fill_block(rng, h, &data[b * h.block_bytes()], b % 4 == 0, code);
    return data;
}

bool all_finite(const std::vector<float>& v) {
    for (float x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

std::vector<float> decode_with(const DecodeContext& ctx, const std::vector<std::uint8_t>& blocks,
                               const std::string& name = "scalar") {
    const std::size_t count = blocks.size() / ctx.header.block_bytes();
    std::vector<float> xyz(3 * count_block_points(ctx, blocks.data(), count));
    decode_blocks(ctx, blocks.data(), count, xyz.data(), parse_decoder(name));
    return xyz;
}

}  // namespace

TEST(DecodesFinite, ProvenHeadersDecodeFinitePointsWithEveryDecoder) {
    std::mt19937 rng(7);
    std::vector<std::string> decoders = available_decoders();
    decoders.push_back("scalar");
    int proven = 0, overflowed = 0;
    for (int trial = 0; trial < 600; ++trial) {
        const std::uint8_t version =
            trial % 3 == 0 ? kFft16Version : trial % 3 == 1 ? kFft16PackedVersion : kFftVersion;
        const std::uint32_t ppb = version == kFftVersion ? 60 : 126;
        const FftHeader h = extreme_header(rng, version, ppb);
        const DecodeContext ctx(h);  // holds a 16-bit table for decodes_finite too
        const std::vector<std::uint8_t> blocks = probe_blocks(rng, h, 17);
        const bool finite = decodes_finite(h);
        proven += finite;
        for (const std::string& name : decoders) {
            const bool got = all_finite(decode_with(ctx, blocks, name));
            if (finite) {
                EXPECT_TRUE(got) << name << ", trial " << trial << ", scaling " << h.scaling << ", step " << h.step;
            }
            overflowed += !got && name == "scalar";
        }
    }
    // Both sides of the bound were visited.
    EXPECT_GT(proven, 100);
    EXPECT_GT(overflowed, 100);
}

TEST(DecodesFinite, TheBoundIsWithin32TimesOfAnOverflow) {
    std::mt19937 rng(3);
    for (const std::uint8_t version : {kFftVersion, kFft16Version}) {
        FftHeader h;
        h.version = version;
        h.points_per_block = version == kFftVersion ? 60 : 254;
        h.ratio = 0.3f;
        h.step = 0.01f;
        h.offset = {0, 0, 0};
        // The largest scaling proven (to 0.1 %), by bisection in log scale.
        double lo = 1, hi = 3e38;
        while (hi / lo > 1.001) {
            h.scaling = float(std::sqrt(lo * hi));
            (decodes_finite(h) ? lo : hi) = h.scaling;
        }
        h.scaling = float(lo);
        ASSERT_TRUE(decodes_finite(h));
        std::vector<std::uint8_t> straight(h.block_bytes(), 0);
        fill_block(rng, h, straight.data(), true, straight_code(h));
        EXPECT_TRUE(all_finite(decode_with(DecodeContext(h), straight)));
        h.scaling = float(32 * lo);
        EXPECT_FALSE(decodes_finite(h));
        EXPECT_FALSE(all_finite(decode_with(DecodeContext(h), straight))) << "version " << int(version);
    }
}

TEST(DecodesFinite, NonFiniteHeaderFieldsAreNotProven) {
    FftHeader h;
    h.scaling = 100, h.step = 0.001f, h.ratio = 0.3f;
    ASSERT_TRUE(decodes_finite(h));
    for (float bad : {std::nanf(""), INFINITY}) {
        for (int field = 0; field < 4; ++field) {
            FftHeader g = h;
            float* target[] = {&g.scaling, &g.step, &g.ratio, &g.offset[1]};
            *target[field] = bad;
            EXPECT_FALSE(decodes_finite(g)) << "field " << field << " = " << bad;
        }
    }
}

TEST(DecodesFinite, EncodedFilesAreProven) {
    test::TempDir dir;
    test::write_helix_tck(dir.file("h.tck"), 20, 300);
    for (unsigned bits : {8u, 16u}) {
        CompressOptions o;
        o.direction_bits = bits;
        const std::string out = dir.file("h" + std::to_string(bits) + ".fft");
        compress_file(dir.file("h.tck"), out, o);
        EXPECT_TRUE(decodes_finite(FftFile(out).header())) << bits << " bits";
    }
}
