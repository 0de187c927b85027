// Internal: a precomputed lookup for the nearest 8-bit direction code, the
// encoder's hot path (DirectionTable::nearest_code costs a normalization,
// the cap mapping, the formula and nine dot products per point).
//
// The table covers the gnomonic coordinates (y/x, z/x) of the local
// direction, i.e. its intersection with the plane x = 1, on a G x G grid
// over the square around the cap's rim, storing the nearest code of each
// cell centre (and its rival, aim()): one division per lookup, no square
// root. Directions outside the cap (or behind the half sphere) are pushed
// radially onto the rim, where their nearest code lies. A cell is 1/256 of
// the cap's width, about 1/10 of the code spacing, so a lookup returns the
// nearest code except within a hair of a tie (where both codes are equally
// good; the encoder's closed loop makes up for either). Only for caps
// narrower than a half sphere (ratio < 1); otherwise callers use
// nearest_code.
#pragma once

#include <cstdint>
#include <vector>

#include "encode/row_frame.hpp"
#include "core/vec_math.hpp"
#include "fiblet/direction_code.hpp"

namespace fiblet::detail {

class NearestCodeLut {
public:
    static constexpr int kGrid = 256;

    explicit NearestCodeLut(const DirectionTable& table);
    bool usable() const { return !cells_.empty(); }
    // The code's local frame as rows (row_frame.hpp), for the code searches.
    const RowFrame& rows(std::uint8_t code) const { return rows_[code]; }
    // The codes of the 3x3 around a code (itself left out), in grid order
    // (level h, then level l, ascending), with their directions as columns
    // for evaluating them four at a time; lanes past `count` have direction
    // 0 and pad = +inf (so pad + anything finite is +inf), the others pad = 0.
    struct Neighbours {
        alignas(16) float x[8], y[8], z[8], pad[8];
        std::uint8_t code[8];
        unsigned count;
        unsigned before;  // how many of them precede the code itself in grid order
    };
    const Neighbours& neighbours(std::uint8_t code) const { return neighbours_[code]; }
    // The retry lookahead's rivals of a code (LookaheadRivals::four): its
    // four nearest codes, one level up or down on one grid axis (fewer at
    // the grid's edges), in grid order, as Neighbours' columns. The diagonal codes of the 3x3 are a
    // level farther on both axes; trying them as well made the default's
    // compress 13 % slower for a 0.3 % smaller mean error (docs/encode.md).
    struct Rivals {
        alignas(16) float x[4], y[4], z[4], pad[4];
        std::uint8_t code[4];
        unsigned count;
    };
    const Rivals& rivals(std::uint8_t code) const { return rivals_[code]; }
    // A code aimed at and its rival, the lookahead's alternative in the
    // first search and the length tails (LookaheadRivals::aim): of the
    // code's four Rivals, the one nearest in angle to the aim (at the cell's
    // centre: the table holds both), the first in grid order on a tie. One
    // rival from the aim's own cell instead of the four, whose directions
    // cost gathers at every point, took the default's compress of the
    // medium tractogram from 3.51 to 2.87 s (one core) for a 1.5 % larger
    // mean error (docs/encode.md).
    struct Aim {
        std::uint8_t code, rival;
    };
    Aim aim(Vec3f local) const {
        const std::uint16_t w = word(local);
        return {std::uint8_t(w & 0xff), std::uint8_t(w >> 8)};
    }
    // The rival of `code` for an aim in direction `d` (any length): what
    // the table holds at its cells' centres, and where there is no table
    // (caps of a half sphere), what aims use.
    std::uint8_t rival(std::uint8_t code, Vec3f d) const;
    // What aim() reads, for the SIMD searches that repeat its operations
    // lane by lane (code_lanes-inl.hpp); cells: kGrid * kGrid words, each
    // its code | rival << 8 (as are zero_word and back_word).
    struct Gnomonic {
        const std::uint16_t* cells;
        float rim_tan, rim_tan2, cell_scale;
        std::uint16_t zero_word, back_word;
    };
    Gnomonic gnomonic() const { return {cells_.data(), rim_tan_, rim_tan2_, cell_scale_, zero_word_, back_word_}; }

    std::uint8_t operator()(Vec3f local) const { return std::uint8_t(word(local) & 0xff); }

private:
    std::uint16_t word(Vec3f local) const {
        const float x = local.x, y = local.y, z = local.z;
        const float lateral2 = y * y + z * z;
        float u, v;
        if (x > 0.0f && lateral2 <= rim_tan2_ * (x * x)) {
            const float inv = 1.0f / x;
            u = y * inv, v = z * inv;
        } else {  // outside the cap: the nearest code is on the rim, in the lateral direction
            if (!(lateral2 > 0.0f)) return x < 0.0f ? back_word_ : zero_word_;
            const float s = rim_tan_ / std::sqrt(lateral2);
            u = y * s, v = z * s;
        }
        return cells_[std::size_t(cell(u)) * kGrid + std::size_t(cell(v))];
    }
    int cell(float u) const {
        const int i = int((u + rim_tan_) * cell_scale_);
        return i < 0 ? 0 : (i >= kGrid ? kGrid - 1 : i);
    }
    std::vector<std::uint16_t> cells_;
    std::vector<RowFrame> rows_;
    std::vector<Neighbours> neighbours_;
    std::vector<Rivals> rivals_;
    float rim_tan_ = 1, rim_tan2_ = 1, cell_scale_ = 1;
    std::uint16_t zero_word_ = 0, back_word_ = 0;
};

}  // namespace fiblet::detail
