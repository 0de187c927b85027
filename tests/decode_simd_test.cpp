// The SIMD decoders (lanes, warp; portable, AVX2, AVX-512) against the
// scalar reference decoder, on random blocks and on every shared tractogram:
// same point count, nothing written past the output, and
//  - lanes: bit-identical points (so within 1e-4 of the step length);
//  - warp: within the float-rounding bound of docs/decode.md ("Equivalence"),
//    which reassociated sums need: at a 0.05 mm step, 1e-4 x step is 5 nm,
//    1.3 float ulps of a coordinate past 32 mm, and the reference's own
//    sequential sums drift from exact arithmetic by more than that.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

// Every concrete decoder this CPU runs except the reference.
std::vector<std::string> simd_decoders() {
    std::vector<std::string> names = available_decoders();
    names.erase(std::remove(names.begin(), names.end(), "scalar"), names.end());
    return names;
}

struct Deviation {
    double max_mm = 0;   // largest distance between corresponding points
    bool identical = true;
};

Deviation compare_points(const float* a, const float* b, std::size_t points) {
    Deviation d;
    for (std::size_t i = 0; i < points; ++i) {
        const double dx = double(a[3 * i]) - b[3 * i], dy = double(a[3 * i + 1]) - b[3 * i + 1],
                     dz = double(a[3 * i + 2]) - b[3 * i + 2];
        d.max_mm = std::max(d.max_mm, std::sqrt(dx * dx + dy * dy + dz * dz));
        if (std::memcmp(a + 3 * i, b + 3 * i, 12) != 0) d.identical = false;
    }
    return d;
}

// The proven bound on |warp - reference| for point `i` of a block (i >= 1:
// after i - 1 steps), in mm (docs/decode.md, "Equivalence"). u = 2^-24 is the
// float unit roundoff, P the largest normalized coordinate of the block, M
// the largest world coordinate, s the scaling, step the normalized step:
//   s (i u P  +  step (9 i^2 + 6 i) u)  +  4 u ((P + 0.5) s + M)
// (reference's sequential sums; both frames' rounding, 9 u per product in
// Frobenius norm, summed along the block; the warp's tree sums; the final
// add and the world conversion of both).
double warp_bound(const FftHeader& h, int i, double P, double M) {
    const double u = std::ldexp(1.0, -24), s = h.scaling, step = h.step;
    return s * (i * u * P + step * (9.0 * i * i + 6.0 * i) * u) + 4 * u * ((P + 0.5) * s + M);
}

// Largest deviation of `got` from `reference` relative to the warp bound of
// each point (<= 1 passes), block by block.
double worst_vs_warp_bound(const DecodeContext& ctx, const std::vector<std::uint8_t>& blocks, const float* got,
                           const float* reference) {
    const FftHeader& h = ctx.header;
    const std::size_t bb = h.block_bytes(), count = blocks.size() / bb;
    double worst = 0;
    std::size_t at = 0;
    for (std::size_t b = 0; b < count; ++b) {
        const int n = int(BlockView{&blocks[b * bb]}.point_count());
        double P = 0, M = 0;
        for (int k = 0; k < 3 * n; ++k) {
            const double w = reference[3 * at + k];
            M = std::max(M, std::fabs(w));
            P = std::max(P, std::fabs((w + h.offset[k % 3]) / h.scaling + 0.5));
        }
        for (int i = 0; i < n; ++i, ++at) {
            const Deviation d = compare_points(got + 3 * at, reference + 3 * at, 1);
            worst = std::max(worst, d.max_mm / warp_bound(h, std::max(i, 1), P * 1.001, M));
        }
    }
    return worst;
}

FftHeader random_header(std::mt19937& rng, std::uint32_t points_per_block) {
    std::uniform_real_distribution<float> u(0, 1);
    FftHeader h;
    h.points_per_block = points_per_block;
    h.scaling = 10.0f + 290.0f * u(rng);
    h.offset = {200 * u(rng) - 100, 200 * u(rng) - 100, 200 * u(rng) - 100};
    h.ratio = 0.02f + 1.98f * u(rng);
    h.step = (0.05f + 0.95f * u(rng)) / h.scaling;
    return h;
}

// Blocks as an encoder could write them: any anchors (sometimes equal), any
// point count in 1..points_per_block, any direction bytes, zero padding.
std::vector<std::uint8_t> random_blocks(std::mt19937& rng, const FftHeader& h, std::size_t count) {
    const std::uint32_t bb = h.block_bytes();
    std::vector<std::uint8_t> data(count * bb, 0);
    std::uniform_int_distribution<int> byte(0, 255);
    std::uniform_int_distribution<std::uint32_t> points(1, h.points_per_block);
    for (std::size_t b = 0; b < count; ++b) {
        std::uint8_t* block = &data[b * bb];
        for (std::size_t i = 0; i < kBlockDirectionsOffset; ++i) block[i] = std::uint8_t(byte(rng));
        if (byte(rng) < 16) {  // coinciding anchors: the first axis falls back to +x
            block[0] = block[10], block[1] = block[11], block[6] = block[2], block[7] = block[3];
            block[4] = block[8], block[5] = block[9];
        }
        // Mostly full blocks, as in real files.
        const std::uint32_t n = byte(rng) < 192 ? h.points_per_block : points(rng);
        block[kBlockFlagsOffset] = std::uint8_t((block[kBlockFlagsOffset] & 0xc0) | n);
        for (std::uint32_t k = 0; k + 2 < n; ++k) block[kBlockDirectionsOffset + k] = std::uint8_t(byte(rng));
    }
    return data;
}

// Decodes with `name` into a buffer guarded by sentinels, checks that nothing
// beyond the points was written, and returns the points.
std::vector<float> decode_guarded(const DecodeContext& ctx, const std::vector<std::uint8_t>& blocks,
                                  const std::string& name, std::size_t expected_points) {
    constexpr std::size_t kGuard = 64;
    const float sentinel = -12345.678f;
    std::vector<float> out(3 * expected_points + kGuard, sentinel);
    const std::size_t count = blocks.size() / ctx.header.block_bytes();
    EXPECT_EQ(decode_blocks(ctx, blocks.data(), count, out.data(), parse_decoder(name)), expected_points) << name;
    for (std::size_t i = 3 * expected_points; i < out.size(); ++i)
        EXPECT_EQ(out[i], sentinel) << name << " wrote past its output at float " << i;
    out.resize(3 * expected_points);
    return out;
}

// The equivalence each decoder promises. Returns the largest deviation in
// steps, and in `of_bound` the largest fraction of the warp bound used.
double expect_equivalent(const DecodeContext& ctx, const std::vector<std::uint8_t>& blocks, const std::string& name,
                         const float* got, const float* reference, std::size_t points, double* of_bound = nullptr) {
    const Deviation d = compare_points(got, reference, points);
    const double worst = worst_vs_warp_bound(ctx, blocks, got, reference);
    if (name.rfind("lanes", 0) == 0) {
        EXPECT_TRUE(d.identical) << name;
        EXPECT_LE(d.max_mm, 1e-4 * ctx.header.step_mm()) << name;
    } else {
        EXPECT_LE(worst, 1.0) << name;
    }
    if (of_bound) *of_bound = worst;
    return d.max_mm / ctx.header.step_mm();
}

}  // namespace

TEST(DecodeSimd, NamesParseAndResolve) {
    EXPECT_EQ(decoder_name(parse_decoder("scalar")), "scalar");
    EXPECT_EQ(decoder_name(parse_decoder("lanes-portable")), "lanes-portable");
    EXPECT_EQ(decoder_name(parse_decoder("warp-portable")), "warp-portable");
    for (const std::string& name : available_decoders()) EXPECT_EQ(decoder_name(parse_decoder(name)), name);
    const std::string automatic = decoder_name(parse_decoder("auto"));
    EXPECT_EQ(automatic, available_decoders().front());
    for (const char* bad : {"", "fast", "lanes-sse9", "scalar-avx2", "warp-"})
        EXPECT_THROW(parse_decoder(bad), Error) << bad;
}

TEST(DecodeSimd, RandomBlocksMatchTheReference) {
    std::mt19937 rng(2024);
    // Block sizes around the warp (32 lanes: 33 and 34 points) and SIMD widths.
    for (std::uint32_t ppb : {60u, 63u, 2u, 3u, 9u, 17u, 33u, 34u, 47u}) {
        for (std::size_t count : {std::size_t(1), std::size_t(7), std::size_t(16), std::size_t(45), std::size_t(700)}) {
            const FftHeader h = random_header(rng, ppb);
            const DecodeContext ctx(h);
            const std::vector<std::uint8_t> blocks = random_blocks(rng, h, count);
            const std::size_t points = count_block_points(ctx, blocks.data(), count);
            std::vector<float> reference(3 * points);
            ASSERT_EQ(decode_blocks_scalar(ctx, blocks.data(), count, reference.data()), points);
            for (const std::string& name : simd_decoders()) {
                const std::vector<float> got = decode_guarded(ctx, blocks, name, points);
                expect_equivalent(ctx, blocks, name, got.data(), reference.data(), points);
            }
        }
    }
}

namespace {

// 16-bit blocks (BlockView16) as an encoder could write them: any unorm24
// anchors (sometimes equal), any point count, any first/last flags and u16
// codes (for version 17 mostly below 181^2, some beyond: the table maps every u16).
std::vector<std::uint8_t> random_blocks16(std::mt19937& rng, const FftHeader& h, std::size_t count) {
    const std::uint32_t bb = h.block_bytes();
    std::vector<std::uint8_t> data(count * bb, 0);
    std::uniform_int_distribution<int> byte(0, 255);
    std::uniform_int_distribution<std::uint32_t> points(1, h.points_per_block), code(0, 65535),
        valid(0, h.code_levels() * h.code_levels() - 1);
    for (std::size_t b = 0; b < count; ++b) {
        std::uint8_t* block = &data[b * bb];
        for (std::size_t i = 0; i < kBlock16FlagsOffset; ++i) block[i] = std::uint8_t(byte(rng));
        if (byte(rng) < 16) std::memcpy(block + 9, block, 9);  // coinciding anchors: the first axis falls back to +x
        const std::uint32_t n = byte(rng) < 192 ? h.points_per_block : points(rng);
        const std::uint16_t flags = std::uint16_t(n | (byte(rng) & 0xc0) << 8);
        block[kBlock16FlagsOffset] = std::uint8_t(flags), block[kBlock16FlagsOffset + 1] = std::uint8_t(flags >> 8);
        for (std::uint32_t k = 0; k + 2 < n; ++k) {
            const std::uint32_t c = byte(rng) < 4 ? code(rng) : valid(rng);
            block[kBlock16DirectionsOffset + 2 * k] = std::uint8_t(c), block[kBlock16DirectionsOffset + 2 * k + 1] = std::uint8_t(c >> 8);
        }
    }
    return data;
}

}  // namespace

// Every SIMD decoder of 16-bit blocks (lanes; warp runs as lanes) gives the
// scalar16 reference's points bit for bit, for versions 16 and 17 (whose
// first axis comes from the anchors' integers).
TEST(DecodeSimd, RandomBlocks16MatchTheReference) {
    std::mt19937 rng(16);
    for (const std::uint8_t version : {kFft16Version, kFft16PackedVersion}) {
        for (std::uint32_t ppb : {254u, 126u, 2u, 3u, 17u, 33u}) {
            for (std::size_t count : {std::size_t(1), std::size_t(15), std::size_t(16), std::size_t(300)}) {
                FftHeader h = random_header(rng, ppb);
                h.version = version;
                const DecodeContext ctx(h);
                const std::vector<std::uint8_t> blocks = random_blocks16(rng, h, count);
                const std::size_t points = count_block_points(ctx, blocks.data(), count);
                std::vector<float> reference(3 * points);
                ASSERT_EQ(decode_blocks_scalar16(ctx, blocks.data(), count, reference.data()), points);
                for (const std::string& name : simd_decoders()) {
                    const std::vector<float> got = decode_guarded(ctx, blocks, name, points);
                    EXPECT_TRUE(compare_points(got.data(), reference.data(), points).identical)
                        << name << ", version " << int(version) << ", " << ppb << " points a block, " << count << " blocks";
                }
            }
        }
    }
}

TEST(DecodeSimd, InvalidPointCountsAreRejectedByEveryDecoder) {
    std::mt19937 rng(5);
    const FftHeader h = random_header(rng, 60);
    const DecodeContext ctx(h);
    for (std::uint8_t bad : {std::uint8_t(0), std::uint8_t(61), std::uint8_t(63)}) {
        std::vector<std::uint8_t> blocks = random_blocks(rng, h, 40);
        blocks[17 * h.block_bytes() + kBlockFlagsOffset] = bad;
        std::vector<float> out(3 * 60 * 40);
        for (const std::string& name : available_decoders()) {
            try {
                decode_blocks(ctx, blocks.data(), 40, out.data(), parse_decoder(name));
                ADD_FAILURE() << name << " accepted a block of " << int(bad) << " points";
            } catch (const Error& e) {
                EXPECT_EQ(e.code(), Errc::fft_format);
            }
        }
    }
}

namespace {

// Decodes every block of a file with each decoder and compares with the
// reference; the default decoder through decode_fibers must give the
// reference's points bit for bit.
void expect_file_matches_reference(const std::string& path) {
    const FftFile file(path);
    const FftHeader& h = file.header();
    const DecodeContext ctx(h);
    const std::vector<std::uint8_t> blocks = file.read_blocks(0, h.blocks);
    const std::size_t points = count_block_points(ctx, blocks.data(), h.blocks);
    ASSERT_EQ(points, h.points) << path;
    std::vector<float> reference(3 * points);
    const bool wide = h.direction_bits() == 16;
    if (wide) decode_blocks_scalar16(ctx, blocks.data(), h.blocks, reference.data());
    else decode_blocks_scalar(ctx, blocks.data(), h.blocks, reference.data());
    for (const std::string& name : simd_decoders()) {
        const std::vector<float> got = decode_guarded(ctx, blocks, name, points);
        if (wide) {  // every SIMD decoder of 16-bit blocks is the lanes one
            EXPECT_TRUE(compare_points(got.data(), reference.data(), points).identical) << path << ", " << name;
            continue;
        }
        double of_bound = 0;
        const double steps = expect_equivalent(ctx, blocks, name, got.data(), reference.data(), points, &of_bound);
        std::printf("  %-28s %-16s max deviation %.3g x step, %.2f of the bound\n",
                    std::filesystem::path(path).filename().c_str(), name.c_str(), steps, of_bound);
    }
    // decode_fibers also places the fibers' ends (ENDS chunk): the reference then does too.
    if (file.end_fractions()) apply_fiber_ends(h, *file.end_fractions(), blocks.data(), h.blocks, reference.data());
    const Streamlines all = decode_fibers(file, 0, h.fibers);
    ASSERT_EQ(all.point_count(), points);
    EXPECT_EQ(std::memcmp(all.xyz.data(), reference.data(), 12 * points), 0) << path;
}

}  // namespace

TEST(DecodeSimd, ReferenceFftFilesMatchTheReferenceDecoder) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    for (const char* name : {"reference/small-ifod1.fft", "reference/small-sdstream.fft"})
        expect_file_matches_reference(test::shared_data(name));
}

TEST(DecodeSimd, SharedTractogramsMatchTheReferenceDecoder) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    std::vector<std::filesystem::path> inputs;
    for (const char* sub : {"", "bundles"})
        for (const auto& entry : std::filesystem::directory_iterator(test::shared_data_dir() + "/" + sub))
            if (entry.path().extension() == ".tck") inputs.push_back(entry.path());
    inputs.push_back(test::shared_data("conformance/standard.tck"));
    inputs.push_back(test::shared_data("conformance/simple.tck"));
    std::sort(inputs.begin(), inputs.end());
    ASSERT_GE(inputs.size(), 15u);
    for (const auto& tck : inputs) {
        const std::string fft = dir.file(tck.stem().string() + ".fft");
        // The SIMD decoders are the 8-bit layout's; the default would give
        // the smooth files 16-bit codes (encode/direction_bits.hpp).
        CompressOptions o;
        o.direction_bits = 8;
        compress_file(tck.string(), fft, o);
        expect_file_matches_reference(fft);
    }
    // And 16-bit files (version 17) of a smooth and of a folded tractogram.
    for (const char* name : {"small-ifod1-step0.05.tck", "conformance/standard.tck"}) {
        const std::string fft = dir.file("wide.fft");
        CompressOptions o;
        o.direction_bits = 16;
        o.overwrite = true;
        compress_file(test::shared_data(name), fft, o);
        ASSERT_EQ(FftFile(fft).header().direction_bits(), 16u);
        expect_file_matches_reference(fft);
    }
}
