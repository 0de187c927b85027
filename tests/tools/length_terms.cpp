// fiblet_length_terms FILE.fft INPUT.tck: where a fixed-step file's decoded
// lengths differ from its input's (docs/encode.md, "Fixed-step lengths").
// Per segment, input s = t_k - t_{k-1} (direction u), decoded d = p_k - p_{k-1}:
//   |d| - |s| = (d - s).u + (|d| - d.u)
// The first term is the along-track change of the point error e = p - t; its
// sum over a fiber telescopes to the end points' along-track errors plus
// the error's component across the track's turns (e_k.(u_{k+1} - u_k)). The
// second, |d| (1 - cos angle(d, u)), is never negative: the across-track
// scatter. A direction-coded segment can only take one of the 256 codes of
// the decoder's frame at its point, so its across term is at least
// |d| (1 - cos a_min), a_min the smallest angle between u and those 256
// directions (frames as actually decoded, float64 reference decoder,
// tests/exact_decoder.hpp). Prints, over the fibers, mean and max of the
// length change, of its two terms, of the across term's lower bound, and
// of the largest shortening the along term could give at the recorded
// error E: E (2 + sum |u_{k+1} - u_k|), and of the mean inward offset of the
// point errors the along term needs to take the across term's bound back to
// within E: max(0, bound - E) / (2 + sum |u_{k+1} - u_k|), to compare with the
// file's mean error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <sstream>
#include <vector>

#include "exact_decoder.hpp"
#include "fiblet/tck.hpp"

namespace ex = fiblet::test::exact;

namespace {

struct Summary {
    double sum = 0, max = -INFINITY;
    std::size_t n = 0;
    void add(double v) { sum += v, max = std::max(max, v), ++n; }
    double mean() const { return n ? sum / double(n) : 0; }
};

// One fiber's decoded points (normalized) and, per point, the frame before
// its code (only direction-coded points have one).
void decode_fiber(const std::string& bytes, const ex::Header& h, const std::array<ex::Frame3, 256>& table,
                  std::uint64_t fiber, std::vector<ex::V3>& points, std::vector<ex::Frame3>& frames,
                  std::vector<char>& coded) {
    points.clear(), frames.clear(), coded.clear();
    const std::size_t lut = 58 + 8 * h.buffer_ends.size(), blocks = lut + 8 * h.fibers;
    const auto x = ex::le<std::uint32_t>(bytes, lut + 8 * fiber), y = ex::le<std::uint32_t>(bytes, lut + 8 * fiber + 4);
    const unsigned buffer = x >> 16, count = x & 0xffff;
    const std::uint64_t first = y + (buffer > 0 ? h.buffer_ends.at(buffer - 1) : 0);
    for (unsigned b = 0; b < count; ++b) {
        const std::size_t at = blocks + (first + b) * h.block_bytes();
        if (at + h.block_bytes() > bytes.size()) throw std::runtime_error("block past the end");
        const auto* blk = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
        const unsigned n = blk[16] & 63;
        const auto a = ex::anchors(blk);
        const ex::V3 a0{a[0], a[1], a[2]}, a1{a[3], a[4], a[5]};
        points.push_back(a0), frames.push_back({}), coded.push_back(0);
        if (n < 2) continue;
        points.push_back(a1), frames.push_back({}), coded.push_back(0);
        const ex::V3 d = a1 - a0;
        ex::Frame3 f = ex::frame_of(ex::dot(d, d) > 0 ? ex::unit(d) : ex::V3{1, 0, 0});
        ex::V3 p = a1;
        for (unsigned k = 0; k + 2 < n; ++k) {
            frames.push_back(f), coded.push_back(1);
            f = ex::compose(f, table[blk[18 + k]]);
            p = p + double(h.step) * f.c[0];
            points.push_back(p);
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: fiblet_length_terms FILE.fft INPUT.tck\n");
        return 2;
    }
    try {
        std::ifstream file(argv[1], std::ios::binary);
        std::stringstream ss;
        ss << file.rdbuf();
        const std::string bytes = ss.str();
        const ex::Header h = ex::read_header(bytes);
        if (h.version != 2) throw std::runtime_error("8-bit (version 2) files only");
        std::array<ex::Frame3, 256> table;
        std::array<ex::V3, 256> directions;
        for (unsigned c = 0; c < 256; ++c) directions[c] = ex::code_direction(c, h.ratio), table[c] = ex::frame_of(directions[c]);
        const double recorded = double(h.max_error);
        fiblet::TckReader in(argv[2]);
        std::vector<fiblet::Vec3f> f;
        std::vector<ex::V3> points, normalized;
        std::vector<ex::Frame3> frames;
        std::vector<char> coded;
        Summary change, along, across, bound, ends, turns, reach, coded_across, offset;
        for (std::uint64_t i = 0; in.next(f); ++i) {
            if (i >= h.fibers) throw std::runtime_error("more input streamlines than fibers");
            decode_fiber(bytes, h, table, i, normalized, frames, coded);
            if (normalized.size() != f.size()) throw std::runtime_error("point counts differ: resampled input?");
            if (f.size() < 3) continue;
            points = ex::to_millimetres(normalized, h);
            std::vector<ex::V3> t(f.size());
            for (std::size_t k = 0; k < f.size(); ++k) t[k] = {f[k].x, f[k].y, f[k].z};
            double c = 0, al = 0, ac = 0, lb = 0, cac = 0, turning = 0;
            ex::V3 u_prev{};
            for (std::size_t k = 1; k < f.size(); ++k) {
                const ex::V3 s = t[k] - t[k - 1], d = points[k] - points[k - 1];
                const double ls = std::sqrt(ex::dot(s, s)), ld = std::sqrt(ex::dot(d, d));
                if (!(ls > 0)) continue;
                const ex::V3 u = (1.0 / ls) * s;
                c += ld - ls;
                al += ex::dot(d - s, u);
                ac += ld - ex::dot(d, u);
                if (k > 1) turning += std::sqrt(ex::dot(u - u_prev, u - u_prev));
                u_prev = u;
                if (!coded[k]) continue;
                cac += ld - ex::dot(d, u);
                double best = -1;  // largest cosine between u and a code's direction
                for (unsigned code = 0; code < 256; ++code) best = std::max(best, ex::dot(ex::apply(frames[k], directions[code]), u));
                lb += ld * (1 - std::min(1.0, best));
            }
            const ex::V3 e0 = points[0] - t[0], en = points.back() - t.back();
            const ex::V3 u0 = ex::unit(t[1] - t[0]), un = ex::unit(t.back() - t[t.size() - 2]);
            change.add(c * 1e3), along.add(al * 1e3), across.add(ac * 1e3), bound.add(lb * 1e3), coded_across.add(cac * 1e3);
            ends.add((ex::dot(en, un) - ex::dot(e0, u0)) * 1e3), turns.add(turning);
            reach.add(recorded * (2 + turning) * 1e3);
            offset.add(std::max(0.0, lb - recorded) / (2 + turning) * 1e3);
        }
        auto row = [](const char* what, const Summary& s) { std::printf("%-58s %9.2f %9.2f\n", what, s.mean(), s.max); };
        std::printf("%zu fibers; recorded max / mean error %.3f / %.3f um; per fiber, um:   mean       max\n", change.n,
                    recorded * 1e3, double(h.mean_error) * 1e3);
        row("length change, signed (decoded - input)", change);
        row("  along-track term (d - s).u", along);
        row("    of which the end points' along-track errors", ends);
        row("  across-track term |d| - d.u (>= 0)", across);
        row("    of which on direction-coded segments", coded_across);
        row("    lower bound from the code grid (coded segments)", bound);
        row("total turning sum |u_{k+1} - u_k| (rad)", turns);
        row("largest shortening the along term allows, E (2 + turning)", reach);
        row("inward offset the along term needs, (bound - E) / (2 + turning)", offset);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fiblet_length_terms: %s\n", e.what());
        return 1;
    }
}
