// fiblet_exact_points FILE: the float64 reference decode of a version-2, 16
// or 17 .fft file, or of the .fft a .fftz holds (tests/exact_decoder.hpp,
// tests/fftz_spec_reader.hpp), in the conformance corpus's
// text form: `fiber N: M points`, then `x y z` per point in world mm, each
// double printed with 17 significant digits (reads back exactly). The
// corpus's NAME.f64.txt files (scripts/make_conformance.py).
#include <cstdio>
#include <exception>

#include "exact_decoder.hpp"
#include "fftz_spec_reader.hpp"
#include "test_util.hpp"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: fiblet_exact_points FILE.fft|FILE.fftz\n");
        return 2;
    }
    try {
        std::string bytes = fiblet::test::read_file(argv[1]);
        if (fiblet::test::fftz_spec::is_fftz(bytes)) bytes = fiblet::test::fftz_spec::unpack(bytes);
        const auto decoded = fiblet::test::exact::decode(bytes);
        for (std::size_t f = 0; f < decoded.fibers.size(); ++f) {
            std::printf("fiber %zu: %zu points\n", f, decoded.fibers[f].size());
            for (const auto& p : decoded.fibers[f]) std::printf("%.17g %.17g %.17g\n", p.x, p.y, p.z);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fiblet_exact_points: %s\n", e.what());
        return 1;
    }
}
