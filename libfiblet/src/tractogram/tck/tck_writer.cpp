// MRtrix3 .tck writer (Float32LE), through an AtomicOutputFile.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>

#include "core/streamline_label.hpp"
#include "fiblet/error.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/tck.hpp"

namespace fiblet {
namespace {

static_assert(sizeof(Vec3f) == 12, "Vec3f must be three packed floats: points are written with memcpy");

// MRtrix writes "count:" as 10 zero-padded digits; the field is patched in place at finish().
constexpr int kCountDigits = 10;
constexpr std::uint64_t kMaxCount = 9'999'999'999ull;
// Data offset alignment (MRtrix pads its headers too; keeps the floats aligned).
constexpr std::uint64_t kAlign = 16;

int digits(std::uint64_t v) {
    int d = 1;
    while (v >= 10) v /= 10, ++d;
    return d;
}

std::string zero_padded(std::uint64_t v, int width) {
    std::string s = std::to_string(v);
    return std::string(std::size_t(std::max(0, width - int(s.size()))), '0') + s;
}

bool owned_key(std::string_view k) { return k == "count" || k == "file" || k == "datatype" || k == "END"; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

}  // namespace

struct TckWriter::Impl {
    AtomicOutputFile out;
    std::uint64_t count = 0;
    std::uint64_t count_field = 0;  // file offset of the count digits
    bool finished = false;

    Impl(const std::string& path, bool overwrite) : out(path, overwrite) {}

    void check_open() const {
        if (finished) throw Error(Errc::invalid_argument, out.path() + ": TckWriter used after finish()");
    }

    // NaN separates streamlines (so no point may hold one, nor Inf, which ends the data).
    static constexpr float kSeparator[3] = {std::numeric_limits<float>::quiet_NaN(),
                                            std::numeric_limits<float>::quiet_NaN(),
                                            std::numeric_limits<float>::quiet_NaN()};

    // Whether streamline `index` (its 3n floats at v) may be written: the
    // writer open, no NaN or Inf unless the caller proved there is none,
    // within the count's digits.
    void check_streamline(std::uint64_t index, const float* v, std::uint64_t n, bool check_finite) const {
        check_open();
        if (check_finite && !finite_values(v, 3 * n))
            throw Error(Errc::invalid_input, out.path() + ": cannot write a non-finite coordinate (" +
                                                 detail::streamline_label(index) + "): a .tck cannot hold NaN or Inf");
        if (index >= kMaxCount)
            throw Error(Errc::unsupported, out.path() + ": more than " + std::to_string(kMaxCount) + " streamlines");
    }

    // Appends one streamline of n packed xyz float triplets and its separator.
    void append(const float* xyz, std::size_t n) {
        check_streamline(count, xyz, n, true);
        if (n > 0) out.write(xyz, n * sizeof(Vec3f));
        out.write(kSeparator, sizeof kSeparator);
        ++count;
    }

    // Appends streamlines i = 0 .. offsets.size() - 2 of a chunk, handed to
    // the kernel where they lie (writev), each checked for non-finite
    // values unless the caller proved them finite.
    void append_chunk(const float* xyz, std::span<const std::uint64_t> offsets, bool check_finite) {
        if (offsets.size() < 2) return;
        const std::size_t fibers = offsets.size() - 1;
        std::vector<const void*> data;
        std::vector<std::size_t> sizes;
        data.reserve(2 * fibers), sizes.reserve(2 * fibers);
        for (std::size_t i = 0; i < fibers; ++i) {
            const float* p = xyz + 3 * offsets[i];
            const std::uint64_t n = offsets[i + 1] - offsets[i];
            check_streamline(count + i, p, n, check_finite);
            if (n > 0) data.push_back(p), sizes.push_back(std::size_t(n) * sizeof(Vec3f));
            data.push_back(kSeparator), sizes.push_back(sizeof kSeparator);
        }
        out.write_pieces(data.data(), sizes.data(), data.size());
        count += fibers;
    }

    // NaN and Inf have every exponent bit set: one mask and compare a value,
    // which vectorizes (the sink thread's time is the writes').
    static bool finite_values(const float* v, std::uint64_t n) {
        std::uint32_t bad = 0;
        for (std::uint64_t k = 0; k < n; ++k) {
            std::uint32_t b;
            std::memcpy(&b, v + k, 4);
            bad |= std::uint32_t((b & 0x7f800000u) == 0x7f800000u);
        }
        return !bad;
    }
};

TckWriter::TckWriter(const std::string& path, const std::vector<std::pair<std::string, std::string>>& properties,
                     bool overwrite)
    : impl_(std::make_unique<Impl>(path, overwrite)) {
    std::string h = "mrtrix tracks\n";
    for (const auto& [key, value] : properties) {
        const std::string_view k = trim(key);
        if (owned_key(k)) continue;
        // Such a key could not be read back as the same key. (An empty key
        // can: ": value" reads back as it, so a .tck that has one round-trips
        // through compress and decompress.) Properties are data (usually an
        // input file's), so a bad one is invalid input, not a bad command line.
        if (k.find_first_of(":\n") != std::string_view::npos)
            throw Error(Errc::invalid_input, path + ": the .tck header key \"" + key +
                                                 "\" holds ':' or a line break: it cannot be written");
        // A multi-line value becomes repeated "key: line" entries, as MRtrix writes them.
        std::string_view v = value;
        for (;;) {
            const std::size_t nl = v.find('\n');
            h.append(k).append(": ").append(trim(v.substr(0, nl))).append("\n");
            if (nl == std::string_view::npos) break;
            v.remove_prefix(nl + 1);
        }
    }
    h += "count: ";
    impl_->count_field = h.size();
    h += zero_padded(0, kCountDigits) + "\n";
    h += "datatype: Float32LE\n";
    h += "file: . ";
    const std::size_t fixed = h.size() + std::string_view("\nEND\n").size();
    // The offset's own digits count toward the header: take the fewest digits that fit.
    std::uint64_t offset = 0;
    for (int d = 1; d <= 20; ++d) {
        const std::uint64_t candidate = (fixed + d + kAlign - 1) / kAlign * kAlign;
        if (digits(candidate) == d) {
            offset = candidate;
            break;
        }
    }
    h += std::to_string(offset) + "\nEND\n";
    h.resize(offset, '\0');
    impl_->out.write(h.data(), h.size());
}

TckWriter::~TckWriter() = default;

void TckWriter::write(std::span<const Vec3f> streamline) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are 3 packed floats");
    impl_->append(reinterpret_cast<const float*>(streamline.data()), streamline.size());
}

void TckWriter::write(const float* xyz, std::size_t n_points) { impl_->append(xyz, n_points); }

void TckWriter::write_chunk(const float* xyz, std::span<const std::uint64_t> offsets) {
    impl_->append_chunk(xyz, offsets, true);
}

void TckWriter::write_finite_chunk(const float* xyz, std::span<const std::uint64_t> offsets) {
    impl_->append_chunk(xyz, offsets, false);
}

void TckWriter::finish() {
    Impl& m = *impl_;
    m.check_open();
    const float inf = std::numeric_limits<float>::infinity();
    const float end[3] = {inf, inf, inf};
    m.out.write(end, sizeof end);
    const std::string c = zero_padded(m.count, kCountDigits);
    m.out.write_at(c.data(), c.size(), m.count_field);
    m.finished = true;
    m.out.commit();
}

std::uint64_t TckWriter::count() const { return impl_->count; }

}  // namespace fiblet
