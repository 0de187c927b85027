// The BIDX version-3 box stream: an LZMA-style binary range coder (11-bit
// probabilities, adapted by 1/32 of the error) over the symbols of
// formats/fft-index.md §2.
#include "index/box_stream.hpp"

#include <bit>

namespace fiblet::detail {

namespace {

constexpr unsigned kProbBits = 11, kAdaptShift = 5;
constexpr std::uint16_t kHalf = 1u << (kProbBits - 1);
constexpr std::uint32_t kTop = 1u << 24;

void adapt(std::uint16_t& p, unsigned b) {
    if (b) p = std::uint16_t(p - (p >> kAdaptShift));
    else p = std::uint16_t(p + (((1u << kProbBits) - p) >> kAdaptShift));
}

std::uint32_t zigzag(std::int64_t d) { return std::uint32_t(d >= 0 ? 2 * d : -2 * d - 1); }
std::int64_t unzigzag(std::uint32_t z) { return z & 1 ? -std::int64_t(z / 2) - 1 : std::int64_t(z / 2); }
std::uint32_t sign_of(std::int64_t d) { return d < 0 ? 0 : (d == 0 ? 1 : 2); }

}  // namespace

BoxModel::BoxModel(std::uint32_t levels)
    : bounded_(kHalf), levels_(levels), level_bits_(unsigned(std::bit_width(levels > 1 ? levels - 1 : 1u))) {
    for (Axis& a : axes_) {
        for (auto& t : a.extent_steps) t.fill(kHalf);
        for (auto& t : a.delta_steps) t.fill(kHalf);
    }
}

void BoxStreamEncoder::shift_low() {
    if (std::uint32_t(low_) < 0xff000000u || (low_ >> 32) != 0) {
        const auto carry = std::uint8_t(low_ >> 32);
        std::uint8_t byte = cache_;
        do {
            out_.push_back(std::uint8_t(byte + carry));
            byte = 0xff;
        } while (--cache_size_ != 0);
        cache_ = std::uint8_t(low_ >> 24);
    }
    ++cache_size_;
    low_ = (low_ & 0x00ffffffu) << 8;
}

void BoxStreamEncoder::bit(std::uint16_t& p, unsigned b) {
    const std::uint32_t bound = (range_ >> kProbBits) * p;
    if (b) low_ += bound, range_ -= bound;
    else range_ = bound;
    adapt(p, b);
    while (range_ < kTop) range_ <<= 8, shift_low();
}

void BoxStreamEncoder::unary(std::uint16_t* p, std::uint32_t max, std::uint32_t v) {
    for (std::uint32_t i = 0; i < max; ++i) {
        bit(p[i], v > i);
        if (v == i) return;
    }
}

void BoxStreamEncoder::direct(unsigned bits, std::uint32_t v) {
    for (unsigned i = bits; i-- > 0;) {
        range_ >>= 1;
        if ((v >> i) & 1) low_ += range_;
        while (range_ < kTop) range_ <<= 8, shift_low();
    }
}

void BoxStreamEncoder::add(const std::optional<GridBox>& box, bool first_of_fiber) {
    if (first_of_fiber)
        for (Axis& a : axes_) a.sign = 3;
    bit(bounded_, box.has_value());
    if (!box) return;
    for (int k = 0; k < 3; ++k) {
        Axis& a = axes_[k];
        const std::uint32_t e = box->extent[k];
        unary(a.extent_context(), kMaxBoxExtent, e);
        const std::int64_t d = std::int64_t(box->lo[k]) - std::int64_t(a.lo);
        const std::uint32_t z = first_of_fiber ? kEscape : std::min(zigzag(d), kEscape);
        if (!first_of_fiber) unary(a.delta_context(e), kEscape, z);
        if (z == kEscape) direct(level_bits_, box->lo[k]);
        a.sign = z == kEscape ? 3 : sign_of(d);
        a.lo = box->lo[k], a.extent = e;
    }
}

std::vector<std::uint8_t> BoxStreamEncoder::finish() const {
    BoxStreamEncoder e = *this;
    for (int i = 0; i < 5; ++i) e.shift_low();
    return std::move(e.out_);
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
            b.lo[k] = a.lo, b.extent[k] = std::uint8_t(e);
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
    out.boxes.resize(first_of_fiber.size());
    for (std::size_t b = 0; b < out.boxes.size(); ++b) {
        if (!d.next_box(out.boxes[b], first_of_fiber[b], out.error)) return out;
        if (d.consumed() > size) {
            out.error = "its box stream is shorter than its boxes";
            return out;
        }
    }
    if (d.consumed() != size) out.error = "its box stream is longer than its boxes";
    return out;
}

}  // namespace fiblet::detail
