#include "fiblet/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "fiblet/decode.hpp"
#include "core/streamline_label.hpp"
#include "fiblet/error.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_format.hpp"

namespace fiblet {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "decoded xyz arrays are read as Vec3f");

Comparison compare_to_reference(const FftFile& fft, const std::string& tck_path, bool allow_count_mismatch,
                                const std::function<void(double)>& progress) {
    Comparison c;
    const FftHeader& h = fft.header();
    c.fibers = h.fibers, c.points = h.points, c.blocks = h.blocks, c.fft_bytes = fft.file_size();
    c.reference_bytes = tractogram_bytes(tck_path);  // a TRX directory: its files

    const Resampling resampling = fft.resampling().value_or(Resampling{});  // validated at open: step finite, > 0
    c.resampled = fft.resampling().has_value();
    const bool keeps_ends = fft.end_fractions() != nullptr;
    const auto source = open_streamline_source(tck_path, {.allow_count_mismatch = allow_count_mismatch});
    StreamlineSource& ref = *source;  // a .tck, .trk or TRX
    std::vector<Vec3f> original, resampled;
    auto mismatch = [&](const std::string& what) {
        throw Error(Errc::invalid_input, tck_path + " is not the source of " + fft.path() + ": " + what);
    };
    decode_file(fft, [&](std::uint64_t first, const Streamlines& chunk) {
        for (std::size_t i = 0; i < chunk.size(); ++i) {
            const std::uint64_t fiber = first + i;
            if (!ref.next(original)) mismatch("it has only " + std::to_string(fiber) + " streamlines");
            std::span<const Vec3f> target = original;
            if (c.resampled) {
                // Files with an ENDS chunk keep each fiber's end point; older
                // ones dropped the tail shorter than a step.
                if (keeps_ends) resample_keeping_end(original, resampling, resampled);
                else resample_fixed_step(original, resampling, resampled);
                target = resampled;
            }
            const std::uint64_t n = chunk.offsets[i + 1] - chunk.offsets[i];
            if (target.size() != n)
                mismatch(detail::streamline_label(fiber) + " has " + std::to_string(target.size()) +
                         " points, the decoded fiber " + std::to_string(n));
            const std::span<const Vec3f> decoded{reinterpret_cast<const Vec3f*>(&chunk.xyz[3 * chunk.offsets[i]]), n};
            for (std::size_t k = 0; k < n; ++k) {
                const double dx = double(decoded[k].x) - target[k].x, dy = double(decoded[k].y) - target[k].y,
                             dz = double(decoded[k].z) - target[k].z;
                c.error.add(std::sqrt(dx * dx + dy * dy + dz * dz), fiber);
            }
            c.geometry.add_fiber(original, decoded, fiber);
        }
        if (progress && h.fibers) progress(double(first + chunk.size()) / double(h.fibers));
    });
    if (ref.next(original)) mismatch("it has more than " + std::to_string(h.fibers) + " streamlines");
    if (c.resampled) c.error_vs_original = c.geometry.decoded_to_input();
    return c;
}

}  // namespace fiblet
