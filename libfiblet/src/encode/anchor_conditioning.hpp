// Internal: where a block starts for fiblet's float decoders and for an
// exact decoder, how far apart the two may walk, and the choice of anchor
// roundings that keeps them close (exact_model.hpp says why they differ).
#pragma once

#include <array>
#include <cstdint>

#include "encode/exact_model.hpp"
#include "fiblet/direction_code.hpp"

namespace fiblet::detail {

// The six unorm16 anchor values of a version-2 block.
struct AnchorWords {
    std::array<std::uint32_t, 3> a0, a1;
};

// A block's start as both decoders compute it from the same anchor words.
struct DecoderStarts {
    AnchorWords words;
    Vec3f a0, a1;  // fiblet's float decoders (normalized)
    Frame frame;
    Vec3d exact0, exact1;  // an exact decoder
    FrameD exact_frame;
    double divergence = 0;  // start_divergence over the block's reach (condition_anchors)
    // Either frame took the C' fallback (formats/fft.md §4), which the
    // original decoder lacks: it would turn the whole block about its axis.
    bool fallback = false;
};
DecoderStarts decoder_starts(const AnchorWords& w);

// An upper bound on how far apart the two decoders' points of a block fall
// (normalized units), `reach` being the longest distance of a point from
// the second anchor: the second anchors' difference plus the frames'
// (Frobenius norm, which bounds the rotation's effect on any vector) times
// the reach.
double start_divergence(const DecoderStarts& s, double reach);

// An upper bound on what the walk itself adds over m steps of `step`
// (normalized): each float step rounds the position by at most 2^-25 per
// coordinate, and each frame product (with the table's rounded frames)
// turns the direction by at most ~5e-7, which the later steps carry.
inline double walk_divergence(std::size_t m, double step) {
    const double k = double(m);
    return k * 1.7320508 * 0x1p-25 + 5e-7 * step * k * k;
}

// The nearest unorm16 rounding of anchors that should be at n0, n1
// (normalized, exact): condition_anchors' first candidate.
AnchorWords nearest_words(Vec3d n0, Vec3d n1);

// The anchor words of a block whose anchors should be at n0, n1, given
// `nearest`, the start of nearest_words(n0, n1) (decoder_starts, with its
// start_divergence over `reach`; decoder_starts4 makes four at once): that
// start — unless the decoders then diverge by more than `threshold` over
// `reach`, which happens where the first segment runs nearly along the
// helper vector C. Then every combination of rounding each value up or
// down is tried (64), and the one with the smallest anchor error plus a
// tenth of the divergence is kept: moving an anchor by less than one
// quantum turns the first axis away from C or changes its float rounding;
// the robust code search (code_search.hpp) then splits what divergence
// remains between the two decoders. A start whose float or exact frame
// would take the C' fallback (which the original decoder lacks,
// formats/fft.md §4) is never kept: the second anchor moves by up to a few
// quanta until the first axis leaves the fallback's cone. Returns the
// chosen words with both decoders' starts and their divergence.
DecoderStarts condition_anchors(Vec3d n0, Vec3d n1, double reach, double threshold, const DecoderStarts& nearest);

// decoder_starts(w[i]) with its start_divergence(.., reach[i]) for i < 4:
// the float and double operations of both, four blocks a vector with
// AVX2 (the same bits: the float frames from SSE lanes, the exact ones
// from double lanes, each rounding as its scalar operation), each block's
// long chain of square roots and divisions in step with the others'.
void decoder_starts4(const AnchorWords w[4], const double reach[4], DecoderStarts out[4]);

}  // namespace fiblet::detail
