// Measuring a .fft against the points its encoder aimed at, with the float64
// reference decoder (exact_decoder.hpp) and with fiblet's own decoders: the
// figures the "decoder-independent error" tests and tools/exact_error report.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "exact_decoder.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

namespace fiblet::test {

struct ErrorFigures {
    double max_mm = 0, sum_mm = 0;
    std::uint64_t points = 0;
    double mean_mm() const { return points ? sum_mm / double(points) : 0.0; }
    void add(double e) { max_mm = std::max(max_mm, e), sum_mm += e, ++points; }
};

struct ExactMeasurement {
    double header_max_mm = 0, header_mean_mm = 0;
    bool resampled = false;
    ErrorFigures exact;  // float64 reference decode vs target points
    ErrorFigures original;  // the same with the original decoder's frame rule (no fallback near ±C; version 2)
    ErrorFigures fiblet; // one of the library's decoders (automatic by default) vs target points
    double exact_ratio() const { return exact.max_mm / header_max_mm; }
    double fiblet_ratio() const { return fiblet.max_mm / header_max_mm; }
};

// The points the encoder targets for one input streamline: the input itself,
// or its fixed-step resampling when the file says so (RSMP chunk).
inline const std::vector<Vec3f>& target_points(const std::vector<Vec3f>& input, const Resampling& resampling,
                                               std::vector<Vec3f>& scratch) {
    if (!(resampling.step_mm > 0)) return input;
    resample_fixed_step(input, resampling, scratch);
    return scratch;
}

inline double distance(const exact::V3& p, const Vec3f& t) {
    const double dx = p.x - double(t.x), dy = p.y - double(t.y), dz = p.z - double(t.z);
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Decodes `fft_path` both ways and measures every decoded point that has a
// target (the first min(decoded, target) points of each fiber: a tail point
// added beyond the fixed-step targets is not this measure's business).
inline ExactMeasurement measure_exact(const std::string& fft_path, const std::string& tck_path,
                                      const std::string& decoder = "auto") {
    const std::string bytes = read_file(fft_path);
    const exact::Decoded dec = exact::decode(bytes);
    const exact::Decoded original = exact::decode(bytes, exact::FrameRule::original);
    ExactMeasurement m;
    m.header_max_mm = dec.header.max_error, m.header_mean_mm = dec.header.mean_error;
    // RSMP: f64 step, then (16-byte form) u32 curve; the 8-byte form is the polyline.
    Resampling resampling{.step_mm = 0, .curve = ResampleCurve::polyline};
    const std::string rsmp = exact::trailer_chunk(bytes, "RSMP");
    if (rsmp.size() >= 8) std::memcpy(&resampling.step_mm, rsmp.data(), 8);
    if (rsmp.size() == 16) std::memcpy(&resampling.curve, rsmp.data() + 8, 4);
    m.resampled = resampling.step_mm > 0;
    // Curve 2's tension allows for the decoder's step over the resampling step.
    if (m.resampled) resampling.stretch = decoder_stretch(dec.header.step, dec.header.scaling, resampling.step_mm);

    FftFile file(fft_path);
    DecodeOptions options;
    options.decoder = parse_decoder(decoder);
    const Streamlines own = decode_fibers(file, 0, file.header().fibers, options);
    TckReader reader(tck_path);
    std::vector<Vec3f> input, scratch;
    for (std::size_t f = 0; reader.next(input); ++f) {
        if (f >= dec.fibers.size()) throw std::runtime_error(fft_path + ": fewer fibers than " + tck_path);
        const auto& targets = target_points(input, resampling, scratch);
        const auto& exact_points = dec.fibers[f];
        const std::size_t n = std::min(targets.size(), exact_points.size());
        if (exact_points.size() < targets.size())
            throw std::runtime_error(fft_path + ": fiber " + std::to_string(f) + " has fewer points than its targets");
        for (std::size_t k = 0; k < n; ++k) {
            m.exact.add(distance(exact_points[k], targets[k]));
            m.original.add(distance(original.fibers[f][k], targets[k]));
            const float* q = &own.xyz[3 * (own.offsets[f] + k)];
            m.fiblet.add(distance(exact::V3{q[0], q[1], q[2]}, targets[k]));
        }
    }
    return m;
}

}  // namespace fiblet::test
