// A downstream program built against an installed fiblet: compresses a .tck,
// decodes it, and checks the decode against the source read independently
// (same fibers and points, every point within the error the file records).
#include <fiblet/fiblet.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: downstream IN.tck OUT.fft\n");
        return 2;
    }
    try {
        fiblet::CompressOptions options;
        options.overwrite = true;
        fiblet::compress_file(argv[1], argv[2], options);

        const fiblet::FftFile file(argv[2]);
        const fiblet::Streamlines decoded = fiblet::decode_fibers(file, 0, file.header().fibers);

        fiblet::TckReader reader(argv[1]);
        std::vector<fiblet::Vec3f> fiber;
        std::size_t i = 0;
        double worst = 0;
        while (reader.next(fiber)) {
            if (i >= decoded.size() || decoded.offsets[i + 1] - decoded.offsets[i] != fiber.size()) {
                std::fprintf(stderr, "fiber %zu: point count differs\n", i);
                return 1;
            }
            for (std::size_t k = 0; k < fiber.size(); ++k) {
                const float* p = &decoded.xyz[3 * (decoded.offsets[i] + k)];
                worst = std::max(worst, std::hypot(double(p[0]) - fiber[k].x, double(p[1]) - fiber[k].y,
                                                   double(p[2]) - fiber[k].z));
            }
            ++i;
        }
        if (i != decoded.size()) {
            std::fprintf(stderr, "fiber count differs: %zu vs %zu\n", i, decoded.size());
            return 1;
        }
        // The header's bound is computed in float: allow its rounding.
        const double bound = double(file.header().max_error_mm) * (1 + 1e-3) + 1e-6;
        std::printf("downstream: %zu fibers, %llu points, max error %.3f um (recorded %.3f um)\n", decoded.size(),
                    static_cast<unsigned long long>(decoded.point_count()), worst * 1e3,
                    file.header().max_error_mm * 1e3);
        if (!(worst <= bound)) {
            std::fprintf(stderr, "decoded points exceed the recorded error bound\n");
            return 1;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "downstream: %s\n", e.what());
        return 1;
    }
    return 0;
}
