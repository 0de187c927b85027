// Internal: greedy aiming (search_codes with beam 1) for many full 8-bit
// blocks at once, one block per SIMD lane: 4 (SSE4), 8 (AVX2) or 16
// (AVX-512) blocks per vector, chosen at run time. Each lane performs the
// scalar search's float operations in the same order (the library builds
// with -ffp-contract=off; no fused multiply-add), and the nearest-code
// lookup repeats NearestCodeLut::operator() step by step, so the codes and
// decoded points are the same bits as search_codes' (tests/block_lanes_test.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "encode/code_search.hpp"

namespace fiblet::detail {

// The instruction sets the search has code for, narrowest first.
enum class SimdLevel { scalar, sse4, avx2, avx512 };

const char* simd_level_name(SimdLevel level);
// "avx512", "avx2", "sse4" or "scalar"; nullopt for anything else.
std::optional<SimdLevel> parse_simd_level(std::string_view name);
// Compiled into this build and supported by this CPU.
bool simd_level_supported(SimdLevel level);
std::vector<SimdLevel> supported_simd_levels();
// Throws Error(invalid_argument) unless simd_level_supported(level).
void require_simd_level(SimdLevel level);
// The level the search uses: force_simd_level's, else the environment's
// FIBLET_SIMD, else the widest supported. Throws Error(invalid_argument)
// when FIBLET_SIMD names no level or one this CPU (or build) lacks.
SimdLevel simd_level();
// For tests and benchmarks: use `level` (nullopt: back to the default).
// Throws Error(invalid_argument) for an unsupported level.
void force_simd_level(std::optional<SimdLevel> level);

// `blocks` blocks of `m` codes each but the last, which has `last_m`
// (1 <= last_m <= m: a fiber's last block may be shorter), or, where
// `lengths` is given, lengths[j] codes (1 <= lengths[j] <= m; blocks of
// several fibers), block j's data at a fixed stride (the encoder's layout:
// one fiber's points, ppb per block):
//   start frame frames[j], start point starts[j * stride],
//   targets targets[j * stride + k], decoded points decoded[j * stride + k],
//   codes codes[j * code_stride + k], for k in [0, length(j)).
struct GreedyBatch {
    const Frame* frames;
    const Vec3f* starts;
    const Vec3f* targets;
    Vec3f* decoded;
    std::size_t stride;
    std::uint8_t* codes;
    std::size_t code_stride;
    std::size_t blocks;
    std::size_t m;
    std::size_t last_m;
    const std::uint32_t* lengths = nullptr;

    std::size_t length(std::size_t j) const { return lengths ? lengths[j] : j + 1 == blocks ? last_m : m; }
};

// A search of a batch's blocks in SIMD lanes at one level (greedy_blocks.cpp,
// lookahead_blocks.cpp): returns how many blocks it did, from the first;
// the few left are the scalar search's.
using VectorSearch = std::size_t (*)(const Codebook8&, float, const GreedyBatch&);

// Whether the SIMD lanes can search this batch: the lookup table is usable,
// the block lengths are as described above and the offsets fit 32 bits.
bool lanes_can_take(const Codebook8& cb, const GreedyBatch& batch);

// search_codes(cb, beam 1, ...) for every block of the batch, at simd_level()
// (the scalar GreedyLanes where the lookup table is not usable).
void greedy_blocks(const Codebook8& cb, float step, const GreedyBatch& batch);
// The same at a given level (which must be supported).
void greedy_blocks(const Codebook8& cb, float step, const GreedyBatch& batch, SimdLevel level);

}  // namespace fiblet::detail
