// The BIDX version-3 box stream: an LZMA-style binary range coder (11-bit
// probabilities, adapted by 1/32 of the error) over the symbols of
// formats/fft-index.md §7 (read only: version 4 replaced it).
#include "index/box_stream.hpp"

namespace fiblet::detail {

namespace {

constexpr unsigned kProbBits = 11, kAdaptShift = 5;
constexpr std::uint16_t kHalf = 1u << (kProbBits - 1);
constexpr std::uint32_t kTop = 1u << 24;

void adapt(std::uint16_t& p, unsigned b) {
    if (b) p = std::uint16_t(p - (p >> kAdaptShift));
    else p = std::uint16_t(p + (((1u << kProbBits) - p) >> kAdaptShift));
}

std::int64_t unzigzag(std::uint32_t z) { return z & 1 ? -std::int64_t(z / 2) - 1 : std::int64_t(z / 2); }
std::uint32_t sign_of(std::int64_t d) { return d < 0 ? 0 : (d == 0 ? 1 : 2); }

}  // namespace

BoxModel::BoxModel(std::uint32_t levels)
    : bounded_(kHalf), levels_(levels), level_bits_(detail::level_bits(levels)) {
    for (Axis& a : axes_) {
        for (auto& t : a.extent_steps) t.fill(kHalf);
        for (auto& t : a.delta_steps) t.fill(kHalf);
    }
}

namespace {

class BoxStreamDecoder : BoxModel {
public:
    BoxStreamDecoder(const std::uint8_t* data, std::size_t size, std::uint32_t levels)
        : BoxModel(levels), data_(data), size_(size) {
        for (int i = 0; i < 5; ++i) code_ = code_ << 8 | next();
    }

    // The next box; false (with `error` set) when it is off the grid.
    bool next_box(std::optional<GridBox>& box, bool first_of_fiber, std::string& error) {
        if (first_of_fiber)
            for (Axis& a : axes_) a.sign = 3;
        box.reset();
        if (!bit(bounded_)) return true;
        GridBox b;
        for (int k = 0; k < 3; ++k) {
            Axis& a = axes_[k];
            const std::uint32_t e = unary(a.extent_context(), kMaxBoxExtent);
            const std::uint32_t z = first_of_fiber ? kEscape : unary(a.delta_context(e), kEscape);
            const std::int64_t lo = z == kEscape ? std::int64_t(direct(level_bits_)) : std::int64_t(a.lo) + unzigzag(z);
            if (lo < 0 || lo >= std::int64_t(levels_)) {
                error = "a box lies off the grid";
                return false;
            }
            a.sign = z == kEscape ? 3 : sign_of(lo - std::int64_t(a.lo));
            a.lo = std::uint32_t(lo), a.extent = e;
            b.lo[k] = std::uint16_t(a.lo), b.extent[k] = std::uint8_t(e);
        }
        box = b;
        return true;
    }
    // Bytes read, including those past the end (read as 0).
    std::uint64_t consumed() const { return pos_; }

private:
    std::uint8_t next() { return pos_ < size_ ? data_[pos_++] : (++pos_, 0); }
    void normalize() {
        while (range_ < kTop) range_ <<= 8, code_ = code_ << 8 | next();
    }
    unsigned bit(std::uint16_t& p) {
        const std::uint32_t bound = (range_ >> kProbBits) * p;
        unsigned b;
        if (code_ < bound) range_ = bound, b = 0;
        else code_ -= bound, range_ -= bound, b = 1;
        adapt(p, b);
        normalize();
        return b;
    }
    std::uint32_t unary(std::uint16_t* p, std::uint32_t max) {
        std::uint32_t v = 0;
        while (v < max && bit(p[v])) ++v;
        return v;
    }
    std::uint32_t direct(unsigned bits) {
        std::uint32_t v = 0;
        for (unsigned i = 0; i < bits; ++i) {
            range_ >>= 1;
            const unsigned b = code_ >= range_;
            if (b) code_ -= range_;
            v = v << 1 | b;
            normalize();
        }
        return v;
    }
    const std::uint8_t* data_;
    std::size_t size_;
    std::uint64_t pos_ = 0;
    std::uint32_t code_ = 0, range_ = 0xffffffffu;
};

}  // namespace

DecodedBoxes decode_box_stream(const std::uint8_t* data, std::size_t size,
                               const std::vector<bool>& first_of_fiber, std::uint32_t levels) {
    DecodedBoxes out;
    if (size < 5) {  // the coder's first five bytes
        out.error = "its box stream is shorter than its boxes";
        return out;
    }
    BoxStreamDecoder d(data, size, levels);
    out.boxes.reserve(first_of_fiber.size());
    for (std::size_t b = 0; b < first_of_fiber.size(); ++b) {
        std::optional<GridBox> box;
        if (!d.next_box(box, first_of_fiber[b], out.error)) return out;
        out.boxes.push_back(box ? pack_cells(*box) : kUnboundedCells);
        if (d.consumed() > size) {
            out.error = "its box stream is shorter than its boxes";
            return out;
        }
    }
    if (d.consumed() != size) out.error = "its box stream is longer than its boxes";
    return out;
}

}  // namespace fiblet::detail
