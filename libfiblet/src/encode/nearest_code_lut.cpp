#include "encode/nearest_code_lut.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

namespace fiblet::detail {

namespace {

// Neighbours' and Rivals' columns: a code and its direction appended, and
// the lanes past `count` closed (direction 0, pad +inf).
template <class Columns>
void add_column(Columns& r, const DirectionTable& table, unsigned code) {
    const Vec3f& d = table.direction(std::uint8_t(code));
    r.x[r.count] = d.x, r.y[r.count] = d.y, r.z[r.count] = d.z, r.pad[r.count] = 0.0f;
    r.code[r.count++] = std::uint8_t(code);
}
template <class Columns>
void close_columns(Columns& r) {
    for (unsigned i = r.count; i < std::size(r.x); ++i) r.x[i] = r.y[i] = r.z[i] = 0.0f, r.pad[i] = INFINITY, r.code[i] = 0;
}

// f(c) for the codes one level up or down on one grid axis from `code`
// (fewer at the grid's edges), in grid order: Rivals' codes.
template <class F>
void for_each_rival(unsigned code, F&& f) {
    const int h0 = int(code >> 4), l0 = int(code & 15);
    for (const auto& [h, l] : {std::pair{h0 - 1, l0}, {h0, l0 - 1}, {h0, l0 + 1}, {h0 + 1, l0}})
        if (h >= 0 && h <= 15 && l >= 0 && l <= 15) f(unsigned(h << 4 | l));
}

}  // namespace

std::uint8_t NearestCodeLut::rival(std::uint8_t code, Vec3f d) const {
    const Rivals& r = rivals_[code];
    unsigned best = 0;
    float best_dot = r.x[0] * d.x + r.y[0] * d.y + r.z[0] * d.z;
    for (unsigned i = 1; i < r.count; ++i)
        if (const float v = r.x[i] * d.x + r.y[i] * d.y + r.z[i] * d.z; v > best_dot) best = i, best_dot = v;
    return r.code[best];
}

NearestCodeLut::NearestCodeLut(const DirectionTable& table) {
    const float ratio = table.ratio();
    rows_.resize(256);
    for (unsigned c = 0; c < 256; ++c) rows_[c] = row_frame(table.frame(std::uint8_t(c)));
    neighbours_.resize(256);
    for (unsigned c = 0; c < 256; ++c) {
        Neighbours& nb = neighbours_[c];
        nb.count = 0;
        nb.before = 0;
        const int h0 = int(c >> 4), l0 = int(c & 15);
        for (int h = std::max(h0 - 1, 0); h <= std::min(h0 + 1, 15); ++h)
            for (int l = std::max(l0 - 1, 0); l <= std::min(l0 + 1, 15); ++l) {
                const auto code = unsigned(h << 4 | l);
                if (code == c) {
                    nb.before = nb.count;
                    continue;
                }
                add_column(nb, table, code);
            }
        close_columns(nb);
    }
    rivals_.resize(256);
    for (unsigned c = 0; c < 256; ++c) {
        Rivals& r = rivals_[c];
        r.count = 0;
        for_each_rival(c, [&](unsigned code) { add_column(r, table, code); });
        close_columns(r);
    }
    auto aim_word = [&](unsigned code, Vec3f d) {
        return std::uint16_t(code | unsigned(rival(std::uint8_t(code), d)) << 8);
    };
    const unsigned zero_code = table.nearest_code({0, 0, 0}), back_code = table.nearest_code({-1, 0, 0});
    zero_word_ = aim_word(zero_code, {0, 0, 0});
    back_word_ = aim_word(back_code, {-1, 0, 0});
    if (!(ratio < 1.0f)) return;  // the cap reaches the half sphere's rim: no gnomonic view of it
    const double rim_x = 1.0 - double(ratio);
    const double tan_rim = std::sqrt(std::max(1.0 - rim_x * rim_x, 0.0)) / rim_x;
    if (!(tan_rim > 0.0) || !std::isfinite(tan_rim)) return;
    rim_tan_ = float(tan_rim);
    rim_tan2_ = rim_tan_ * rim_tan_;
    cell_scale_ = float(kGrid) / (2.0f * rim_tan_);
    cells_.resize(std::size_t(kGrid) * kGrid);
    const double cell = 2.0 * double(rim_tan_) / kGrid;
    // Each cell starts from its neighbour's code and climbs over the 3x3
    // code neighbourhood (the nearest code changes by at most a level or
    // two between adjacent cells); each row starts with the full search.
    auto closeness = [&](unsigned code, Vec3f d) { return dot(table.direction(std::uint8_t(code)), d); };
    for (int iy = 0; iy < kGrid; ++iy) {
        unsigned code = 0;
        for (int iz = 0; iz < kGrid; ++iz) {
            double u = -double(rim_tan_) + (iy + 0.5) * cell, v = -double(rim_tan_) + (iz + 0.5) * cell;
            const double l = std::sqrt(u * u + v * v);
            if (l > double(rim_tan_)) u *= double(rim_tan_) / l, v *= double(rim_tan_) / l;
            const Vec3f d{1.0f, float(u), float(v)};  // any length: only the angle matters
            if (iz == 0) {
                code = table.nearest_code(d);
            } else {
                for (bool moved = true; moved;) {
                    moved = false;
                    const int h0 = int(code >> 4), l0 = int(code & 15);
                    float best = closeness(code, d);
                    for (int h = std::max(h0 - 1, 0); h <= std::min(h0 + 1, 15); ++h)
                        for (int k = std::max(l0 - 1, 0); k <= std::min(l0 + 1, 15); ++k) {
                            const unsigned c = unsigned(h << 4 | k);
                            if (const float val = closeness(c, d); val > best) best = val, code = c, moved = true;
                        }
                }
            }
            cells_[std::size_t(iy) * kGrid + std::size_t(iz)] = aim_word(code, d);
        }
    }
}

}  // namespace fiblet::detail
