// fiblet_exact_error FILE.fft INPUT.tck: the error of the float64 reference
// decode and of fiblet's decoder against the points the encoder targeted,
// next to the header's figures (the measure of formats/error-bound.md's
// "decoder-independent error" section).
#include <cstdio>
#include <exception>

#include "exact_error.hpp"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: fiblet_exact_error FILE.fft INPUT.tck\n");
        return 2;
    }
    try {
        const auto m = fiblet::test::measure_exact(argv[1], argv[2]);
        std::printf("header max/mean %.3f / %.3f um; float64 max/mean %.3f / %.3f um (ratio %.3f); "
                    "fiblet decoder max/mean %.3f / %.3f um (ratio %.3f); %llu points%s\n",
                    m.header_max_mm * 1e3, m.header_mean_mm * 1e3, m.exact.max_mm * 1e3, m.exact.mean_mm() * 1e3,
                    m.exact_ratio(), m.fiblet.max_mm * 1e3, m.fiblet.mean_mm() * 1e3, m.fiblet_ratio(),
                    static_cast<unsigned long long>(m.exact.points), m.resampled ? " (resampled targets)" : "");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fiblet_exact_error: %s\n", e.what());
        return 1;
    }
}
