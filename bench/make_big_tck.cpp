// Writes a large synthetic .tck tractogram for the memory benchmark
// (scripts/bench_memory.sh), fast and deterministic, never stored:
//   make_big_tck OUT.tck [--bytes N] [--points P] [--step MM] [--seed S]
// Fibers are smooth random walks at a fixed step (default 0.1 mm) inside a
// brain-sized ball, with P points on average (default 80; each fiber has
// between P/2 and 3P/2); as many fibers as make about N bytes (default 5e9).
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"

namespace {

// splitmix64: a small, fast, well-mixed generator.
struct Rng {
    std::uint64_t s;
    std::uint64_t next() {
        std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
    double symmetric() { return 2 * uniform() - 1; }                // [-1, 1)
};

struct V {
    double x, y, z;
};
V operator+(V a, V b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V operator*(double s, V a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V unit(V a) { return (1 / std::sqrt(dot(a, a))) * a; }

void usage() {
    std::fprintf(stderr, "usage: make_big_tck OUT.tck [--bytes N] [--points P] [--step MM] [--seed S]\n");
    std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) usage();
    const std::string out = argv[1];
    double bytes = 5e9, points = 80, step = 0.1;
    std::uint64_t seed = 1;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        const double v = std::atof(argv[i + 1]);
        if (k == "--bytes") bytes = v;
        else if (k == "--points") points = v;
        else if (k == "--step") step = v;
        else if (k == "--seed") seed = std::uint64_t(v);
        else usage();
    }
    if (!(bytes > 0 && points >= 2 && step > 0)) usage();
    const auto fibers = std::uint64_t(std::ceil(bytes / (12.0 * (points + 1))));
    const double radius = 70, turn = 0.02;  // mm; about a degree of turn per step
    const auto t0 = std::chrono::steady_clock::now();
    try {
        fiblet::TckWriter w(out, {{"step_size", std::to_string(step)}, {"source", "make_big_tck"}}, true);
        Rng rng{seed};
        std::vector<fiblet::Vec3f> f;
        std::uint64_t total = 0;
        for (std::uint64_t i = 0; i < fibers; ++i) {
            const auto n = std::size_t(points / 2 + rng.uniform() * points);
            V p{radius * rng.symmetric() * 0.6, radius * rng.symmetric() * 0.6, radius * rng.symmetric() * 0.6};
            V d = unit({rng.symmetric(), rng.symmetric(), rng.symmetric() + 1e-9});
            f.resize(n);
            for (std::size_t k = 0; k < n; ++k) {
                f[k] = {float(p.x), float(p.y), float(p.z)};
                // Turn a little, and back towards the centre near the edge of the ball.
                V bend{rng.symmetric(), rng.symmetric(), rng.symmetric()};
                if (dot(p, p) > radius * radius) bend = bend + (-2.0 / radius) * p;
                d = unit(d + turn * bend);
                p = p + step * d;
            }
            w.write(f);
            total += n;
        }
        w.finish();
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::fprintf(stderr, "make_big_tck: %s: %llu fibers, %llu points (%.2f GB) in %.1f s\n", out.c_str(),
                     (unsigned long long)fibers, (unsigned long long)total, double(total + fibers) * 12 / 1e9, s);
    } catch (const fiblet::Error& e) {
        std::fprintf(stderr, "make_big_tck: %s\n", e.what());
        return 1;
    }
    return 0;
}
