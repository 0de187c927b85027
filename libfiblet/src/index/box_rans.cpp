// The BIDX version-4 box stream (formats/fft-index.md §2): per axis, each
// box's move against the previous box of its fiber as one symbol of 27
// (both sides move by -2..2 cells, "coded whole", "unbounded") in the
// context of that axis's previous symbol; static frequencies stored ahead of
// the words; rANS with 64-bit states and 32-bit words, one state an axis.
#include "index/box_rans.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "core/bytes.hpp"

namespace fiblet::detail {

namespace {

constexpr unsigned kScaleBits = 12;
constexpr std::uint32_t kTotal = 1u << kScaleBits;  // frequencies of a table sum to this
// States live in [kLow, 2^63) and move by 32-bit words: kLow / kTotal = 2^19
// keeps the coder within a fraction of a percent of the entropy (at 2^16
// with 16-bit words it lost about 15 %).
constexpr std::uint64_t kLow = std::uint64_t{1} << 31;
constexpr int kMaxMove = 2;                         // cells a side may move
constexpr unsigned kMoves = (2 * kMaxMove + 1) * (2 * kMaxMove + 1);
constexpr unsigned kWhole = kMoves, kUnbounded = kMoves + 1, kMoveSymbols = kMoves + 2;
// Tables of an axis: 0..26 follow the axis's previous symbol, then a
// fiber's first box, then the extents of boxes coded whole.
constexpr unsigned kFirstContext = kMoveSymbols, kExtentTable = kMoveSymbols + 1;
constexpr unsigned kTablesPerAxis = kMoveSymbols + 2, kTables = 3 * kTablesPerAxis;
constexpr unsigned kExtentSymbols = kMaxBoxExtent + 1;

unsigned alphabet_of(unsigned table) { return table % kTablesPerAxis == kExtentTable ? kExtentSymbols : kMoveSymbols; }
unsigned table_of(unsigned axis, unsigned context) { return axis * kTablesPerAxis + context; }

// One axis of the previous box of the fiber.
struct AxisState {
    std::uint32_t lo = 0, extent = 0;
    unsigned symbol = kUnbounded;  // the last symbol coded on the axis
};

unsigned move_symbol(const AxisState& prev, std::uint32_t lo, std::uint32_t extent) {
    const std::int64_t dlo = std::int64_t(lo) - prev.lo, dhi = std::int64_t(lo + extent) - (prev.lo + prev.extent);
    if (dlo < -kMaxMove || dlo > kMaxMove || dhi < -kMaxMove || dhi > kMaxMove) return kWhole;
    return unsigned((dlo + kMaxMove) * (2 * kMaxMove + 1) + (dhi + kMaxMove));
}

using Counts = std::array<std::uint32_t, kMoveSymbols>;

// Frequencies summing to kTotal, at least 1 for every symbol seen. The
// largest absorbs the rounding: it keeps at least kTotal / 27 - 27 > 1.
Counts normalized(const Counts& c) {
    std::uint64_t total = 0;
    for (std::uint32_t v : c) total += v;
    Counts f{};
    if (total == 0) return f;
    std::uint32_t sum = 0;
    for (std::size_t s = 0; s < c.size(); ++s) {
        if (c[s] != 0) f[s] = std::max<std::uint32_t>(1, std::uint32_t((std::uint64_t(c[s]) * kTotal + total / 2) / total));
        sum += f[s];
    }
    auto& largest = *std::max_element(f.begin(), f.end());
    largest = std::uint32_t(std::int64_t(largest) + std::int64_t(kTotal) - std::int64_t(sum));
    return f;
}

// A coding step: a symbol of a table, or `raw_bits` bits of a value.
struct Step {
    std::uint8_t axis, raw_bits;
    std::uint16_t table, value;
};

// The coding steps of the boxes, in decoding order.
std::vector<Step> steps_of(const std::vector<std::uint64_t>& boxes, const std::vector<bool>& first_of_fiber,
                           std::uint32_t levels) {
    const auto lo_bits = std::uint8_t(level_bits(levels));
    std::vector<Step> steps;
    steps.reserve(boxes.size() * 3 + boxes.size() / 4);
    std::array<AxisState, 3> prev{};
    for (std::size_t b = 0; b < boxes.size(); ++b) {
        const bool first = first_of_fiber[b];
        const std::uint64_t box = boxes[b];
        if (box == kUnboundedCells) {
            steps.push_back({0, 0, std::uint16_t(table_of(0, first ? kFirstContext : prev[0].symbol)), kUnbounded});
            for (AxisState& a : prev) a.symbol = kUnbounded;
            continue;
        }
        for (std::uint8_t k = 0; k < 3; ++k) {
            AxisState& a = prev[k];
            const std::uint32_t lo = cells_lo(box, k), extent = cells_hi(box, k) - lo;
            const unsigned symbol = first || a.symbol == kUnbounded ? kWhole : move_symbol(a, lo, extent);
            steps.push_back({k, 0, std::uint16_t(table_of(k, first ? kFirstContext : a.symbol)), std::uint16_t(symbol)});
            if (symbol == kWhole) {
                steps.push_back({k, 0, std::uint16_t(table_of(k, kExtentTable)), std::uint16_t(extent)});
                steps.push_back({k, lo_bits, 0, std::uint16_t(lo)});
            }
            a = {lo, extent, symbol};
        }
    }
    return steps;
}

// Every table's frequencies (from the steps' counts) and starts; the
// tables written to `out` as (count, then symbol and frequency of each
// symbol seen) per table.
void write_tables(const std::vector<Step>& steps, std::vector<Counts>& freq, std::vector<Counts>& start,
                  std::vector<std::uint8_t>& out) {
    freq.assign(kTables, Counts{}), start.assign(kTables, Counts{});
    for (const Step& s : steps)
        if (s.raw_bits == 0) ++freq[s.table][s.value];
    for (unsigned t = 0; t < kTables; ++t) {
        freq[t] = normalized(freq[t]);
        const auto used = std::count_if(freq[t].begin(), freq[t].end(), [](std::uint32_t f) { return f != 0; });
        out.push_back(std::uint8_t(used));
        std::uint32_t cum = 0;
        for (unsigned s = 0; s < kMoveSymbols; ++s) {
            start[t][s] = cum, cum += freq[t][s];
            if (freq[t][s] == 0) continue;
            out.push_back(std::uint8_t(s));
            put_le(out, std::uint16_t(freq[t][s]));
        }
    }
}

// The rANS words of the steps, appended to `out` in decoding order (rANS
// codes backwards: they come out in reverse), the final states first.
void write_words(const std::vector<Step>& steps, const std::vector<Counts>& freq, const std::vector<Counts>& start,
                 std::vector<std::uint8_t>& out) {
    std::array<std::uint64_t, 3> state{kLow, kLow, kLow};
    std::vector<std::uint32_t> words;
    for (auto it = steps.rbegin(); it != steps.rend(); ++it) {
        const unsigned scale = it->raw_bits ? it->raw_bits : kScaleBits;
        const std::uint32_t f = it->raw_bits ? 1 : freq[it->table][it->value];
        const std::uint32_t from = it->raw_bits ? it->value : start[it->table][it->value];
        std::uint64_t& x = state[it->axis];
        if (x >= ((kLow >> scale) << 32) * f) words.push_back(std::uint32_t(x)), x >>= 32;
        x = ((x / f) << scale) + x % f + from;
    }
    for (unsigned k = 3; k-- > 0;) words.push_back(std::uint32_t(state[k])), words.push_back(std::uint32_t(state[k] >> 32));
    for (auto it = words.rbegin(); it != words.rend(); ++it) put_le(out, *it);
}

}  // namespace

std::vector<std::uint8_t> encode_box_rans(const std::vector<std::uint64_t>& boxes,
                                          const std::vector<bool>& first_of_fiber, std::uint32_t levels) {
    const std::vector<Step> steps = steps_of(boxes, first_of_fiber, levels);
    std::vector<Counts> freq, start;
    std::vector<std::uint8_t> out;
    write_tables(steps, freq, start, out);
    write_words(steps, freq, start, out);
    return out;
}

namespace {

// A table as the decoder uses it: the symbol of each of the kTotal slots.
struct DecodeTable {
    std::array<std::uint8_t, kTotal> symbol;
    std::array<std::uint16_t, kMoveSymbols> freq, start;
};

// The tables of a stream; nullptr for a table it does not store.
struct DecodeTables {
    std::vector<DecodeTable> store;
    std::array<const DecodeTable*, kTables> table{};
};

// Reads the tables; the bytes after them (the words) start at `words`.
// Returns an error message, or nullptr.
const char* read_tables(const std::uint8_t* data, std::size_t size, DecodeTables& out, std::size_t& words) {
    const char* malformed = "its box stream's tables are malformed";
    std::size_t at = 0;
    out.store.reserve(kTables);  // the pointers below stay valid
    for (unsigned t = 0; t < kTables; ++t) {
        if (at >= size) return "its box stream ends in its tables";
        const unsigned used = data[at++];
        if (used == 0) continue;
        if (used > alphabet_of(t) || size - at < 3 * std::size_t(used)) return malformed;
        DecodeTable& d = out.store.emplace_back();
        d.freq.fill(0), d.start.fill(0);
        std::uint32_t cum = 0;
        int last = -1;
        for (unsigned i = 0; i < used; ++i, at += 3) {
            const unsigned s = data[at], f = data[at + 1] | unsigned(data[at + 2]) << 8;
            if (int(s) <= last || s >= alphabet_of(t) || f == 0 || f > kTotal - cum) return malformed;
            d.freq[s] = std::uint16_t(f), d.start[s] = std::uint16_t(cum);
            std::fill_n(d.symbol.begin() + cum, f, std::uint8_t(s));
            cum += f, last = int(s);
        }
        if (cum != kTotal) return malformed;
        out.table[t] = &d;
    }
    words = at;
    return nullptr;
}

// The 32-bit words the three states read, in decoding order; 0 past the end.
struct WordReader {
    const std::uint8_t* bytes;
    std::size_t count, pos = 0;
    std::uint32_t next() {
        const std::size_t i = pos++;
        return i < count ? get_le<std::uint32_t>(bytes + 4 * i) : 0;
    }
};

// One axis: its rANS state, its tables and its previous box. Each axis is
// its own chain of dependent steps; the three run side by side.
class AxisDecoder {
public:
    enum class Outcome { box, unbounded, malformed };

    AxisDecoder(const DecodeTables& tables, unsigned axis, WordReader& words, std::uint32_t levels)
        : tables_(&tables.table[axis * kTablesPerAxis]), words_(words), levels_(levels),
          level_bits_(level_bits(levels)) {
        x_ = std::uint64_t(words.next()) << 32;
        x_ |= words.next();
    }

    // The axis's next box (packed()); `error` set when malformed.
    Outcome next(bool first, const char*& error) {
        const unsigned s = symbol(first ? kFirstContext : prev_.symbol);
        std::int64_t lo, extent;
        if (s == kUnbounded) {
            prev_.symbol = kUnbounded;
            return Outcome::unbounded;
        } else if (s == kWhole) {
            extent = symbol(kExtentTable);
            lo = raw(level_bits_);
        } else if (s < kMoves && !first && prev_.symbol != kUnbounded) {
            lo = std::int64_t(prev_.lo) + std::int64_t(s / (2 * kMaxMove + 1)) - kMaxMove;
            extent = std::int64_t(prev_.lo + prev_.extent) + std::int64_t(s % (2 * kMaxMove + 1)) - kMaxMove - lo;
        } else {
            error = s == kTables ? "its box stream uses a table it does not store"
                                 : "its box stream codes a move without a box before it";
            return Outcome::malformed;
        }
        if (lo < 0 || lo >= std::int64_t(levels_) || extent < 0 || extent > std::int64_t(kMaxBoxExtent)) {
            error = "a box lies off the grid";
            return Outcome::malformed;
        }
        prev_ = {std::uint32_t(lo), std::uint32_t(extent), s};
        return Outcome::box;
    }
    // After an unbounded box on another axis.
    void forget_box() { prev_.symbol = kUnbounded; }
    // The box on this axis into `box`.
    void put(GridBox& box, unsigned axis) const {
        box.lo[axis] = std::uint16_t(prev_.lo), box.extent[axis] = std::uint8_t(prev_.extent);
    }
    bool at_start() const { return x_ == kLow; }  // where the encoder started

private:
    // A symbol of the axis's table `t`; kTables: a table the stream lacks.
    unsigned symbol(unsigned t) {
        const DecodeTable* table = tables_[t];
        if (table == nullptr) return kTables;
        const std::uint32_t slot = x_ & (kTotal - 1);
        const unsigned s = table->symbol[slot];
        x_ = table->freq[s] * (x_ >> kScaleBits) + slot - table->start[s];
        renormalize();
        return s;
    }
    std::uint32_t raw(unsigned bits) {
        const std::uint32_t v = x_ & ((1u << bits) - 1);
        x_ >>= bits;
        renormalize();
        return v;
    }
    // One word at most: a decoded state is at least 2^19 (2^21 after raw bits).
    // A branch, not a select: a symbol takes a few bits of a 32-bit word, so
    // it is well predicted, and the axes' chains do not all wait on the word
    // position as they would through a data dependency.
    void renormalize() {
        if (x_ < kLow) x_ = x_ << 32 | words_.next();
    }

    const DecodeTable* const* tables_;
    WordReader& words_;
    std::uint32_t levels_;
    unsigned level_bits_;
    std::uint64_t x_;
    AxisState prev_;
};

}  // namespace

DecodedBoxes decode_box_rans(const std::uint8_t* data, std::size_t size, const std::vector<bool>& first_of_fiber,
                             std::uint32_t levels) {
    DecodedBoxes out;
    DecodeTables tables;
    std::size_t at = 0;
    if (const char* e = read_tables(data, size, tables, at)) return out.error = e, out;
    if ((size - at) % 4 != 0 || size - at < 24) return out.error = "its box stream's words are malformed", out;
    WordReader words{data + at, (size - at) / 4};
    AxisDecoder x(tables, 0, words, levels), y(tables, 1, words, levels), z(tables, 2, words, levels);
    out.boxes.reserve(first_of_fiber.size());
    const char* error = nullptr;
    using Outcome = AxisDecoder::Outcome;
    for (std::size_t b = 0; b < first_of_fiber.size(); ++b) {
        const bool first = first_of_fiber[b];
        const Outcome ox = x.next(first, error);
        if (ox == Outcome::unbounded) {
            y.forget_box(), z.forget_box();
            out.boxes.push_back(kUnboundedCells);
            continue;
        }
        if (ox == Outcome::malformed || y.next(first, error) != Outcome::box || z.next(first, error) != Outcome::box)
            return out.error = error ? error : "its box stream codes an unbounded box after an axis", out;
        GridBox box;
        x.put(box, 0), y.put(box, 1), z.put(box, 2);
        out.boxes.push_back(pack_cells(box));
    }
    if (words.pos > words.count) out.error = "its box stream is shorter than its boxes";
    else if (words.pos != words.count || !x.at_start() || !y.at_start() || !z.at_start())
        out.error = "its box stream does not end with its boxes";
    return out;
}

}  // namespace fiblet::detail
