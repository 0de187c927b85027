// Whether a file's blocks can only decode to finite points, from its header
// and direction table alone (docs/decode.md, "Finite points").
#include <algorithm>
#include <cfloat>
#include <cmath>

#include "fiblet/decode.hpp"

namespace fiblet {
namespace {

constexpr double kUnit = 0x1p-24;  // float's unit roundoff

// A bound on the frame's spectral norm: by Gershgorin, its square (the
// largest eigenvalue of the Gram matrix of the columns) is at most the
// largest row sum of the Gram matrix's magnitudes; +inf for a non-finite entry.
double spectral_norm_bound(const Frame& f) {
    double worst = 0;
    for (int i = 0; i < 3; ++i) {
        double row = 0;
        for (int j = 0; j < 3; ++j) {
            const Vec3f a = f.c[i], b = f.c[j];
            if (!(std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z))) return HUGE_VAL;
            row += std::fabs(double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z);
        }
        worst = std::max(worst, row);
    }
    return std::sqrt(worst) * (1 + 4 * kUnit);  // the double sums' own rounding, with room
}

// The largest bound over every code a block may hold (every u16 for 16-bit
// files, whose codes past levels^2 repeat a frame below it).
double direction_table_norm_bound(const FftHeader& h) {
    double worst = 0;
    if (h.direction_bits() == 16) {
        const auto table = make_direction_table16(h);
        for (unsigned k = 0; k < table->levels() * table->levels(); ++k)
            worst = std::max(worst, spectral_norm_bound(table->frame(std::uint16_t(k))));
    } else {
        const DirectionTable table(h.ratio);
        for (unsigned k = 0; k < 256; ++k) worst = std::max(worst, spectral_norm_bound(table.frame(std::uint8_t(k))));
    }
    return worst;
}

}  // namespace

bool decodes_finite(const FftHeader& h) {
    // Anchors are unorm words over their maximum: in [0, 1]. The first
    // frame's three columns are normalized (or the unit x axis).
    double point = 1.0, frame = std::sqrt(3.0) * (1 + 8 * kUnit);
    // Each step composes one table frame: |F L| <= |F| |L|, and the float
    // products' rounding (3-term dot products, any association, as the
    // warp decoder's prefix products) adds at most 10 units relative.
    const double growth = direction_table_norm_bound(h) * (1 + 10 * kUnit);
    const double step = std::fabs(double(h.step));
    for (std::uint32_t k = 2; k < h.points_per_block; ++k) {
        frame *= growth;
        point = (point + step * frame * (1 + kUnit)) * (1 + kUnit);
        if (!(point < FLT_MAX)) return false;  // also NaN: an unvalidated header
    }
    double offset = 0;  // the sum bounds each (and keeps a NaN)
    for (float o : h.offset) offset += std::fabs(double(o));
    const double world = ((point + 0.5) * std::fabs(double(h.scaling)) * (1 + 2 * kUnit) + offset) * (1 + kUnit);
    // The last point's end fraction (fiber_ends.hpp) interpolates two points:
    // at most three times the bound. Room to spare for the bound's own doubles.
    return world * 4 < FLT_MAX;
}

}  // namespace fiblet
