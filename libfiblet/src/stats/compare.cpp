#include "fiblet/compare.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "fiblet/decode.hpp"
#include "core/streamline_label.hpp"
#include "fiblet/error.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/tck.hpp"

namespace fiblet {

Comparison compare_to_reference(const FftFile& fft, const std::string& tck_path, bool allow_count_mismatch,
                                const std::function<void(double)>& progress) {
    Comparison c;
    const FftHeader& h = fft.header();
    c.fibers = h.fibers, c.points = h.points, c.blocks = h.blocks, c.fft_bytes = fft.file_size();
    struct stat st {};
    if (::stat(tck_path.c_str(), &st) == 0) c.reference_bytes = std::uint64_t(st.st_size);

    double step = 0;
    if (const TrailerChunk* r = fft.find_chunk(kResampledTag); r && r->payload.size() == 8) {
        c.resampled = true;
        std::memcpy(&step, r->payload.data(), 8);
    }
    TckReader ref(tck_path, {.allow_count_mismatch = allow_count_mismatch});
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
                resample_fixed_step(original, step, resampled);
                target = resampled;
            }
            const std::uint64_t n = chunk.offsets[i + 1] - chunk.offsets[i];
            if (target.size() != n)
                mismatch(detail::streamline_label(fiber) + " has " + std::to_string(target.size()) +
                         " points, the decoded fiber " + std::to_string(n));
            const float* p = &chunk.xyz[3 * chunk.offsets[i]];
            std::size_t hint = 0;
            const std::size_t window = 16 + 2 * original.size() / std::max<std::size_t>(n, 1);
            for (std::size_t k = 0; k < n; ++k, p += 3) {
                const double dx = double(p[0]) - target[k].x, dy = double(p[1]) - target[k].y,
                             dz = double(p[2]) - target[k].z;
                c.error.add(std::sqrt(dx * dx + dy * dy + dz * dz), fiber);
                if (c.resampled)
                    c.error_vs_original.add(distance_to_polyline_near({p[0], p[1], p[2]}, original, hint, window), fiber);
            }
        }
        if (progress && h.fibers) progress(double(first + chunk.size()) / double(h.fibers));
    });
    if (ref.next(original)) mismatch("it has more than " + std::to_string(h.fibers) + " streamlines");
    return c;
}

}  // namespace fiblet
