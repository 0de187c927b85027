// The conformance corpus (tests/conformance/, scripts/make_conformance.py):
// every file of every version and chunk decodes, with every decoder this
// CPU runs, to the points committed beside it: bit for bit for the decoders
// that compose frames in the file's order (scalar, lanes; float32 printed
// with 9 significant digits reads back exactly), within 0.5 um for the
// warp decoders, whose prefix products round in another order (0.06 um at
// most here; their proven per-point bound: decode_simd_test.cpp). The files
// are never regenerated, so a change to any decoder or reader that moves a
// point of an older file fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "exact_decoder.hpp"
#include "fftz_spec_reader.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

// A corpus text: per fiber its point count, then every coordinate (float32
// values in NAME.txt, float64 in NAME.f64.txt; both read back exactly).
template <class T>
struct Points {
    std::vector<std::uint64_t> counts;
    std::vector<T> xyz;
};
using Expected = Points<float>;

template <class T = float>
Points<T> read_expected(const fs::path& path) {
    std::ifstream in(path);
    Points<T> e;
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("fiber ", 0) == 0) {
            e.counts.push_back(std::stoull(line.substr(line.find(':') + 1)));
            continue;
        }
        std::istringstream words(line);
        std::string w;
        while (words >> w) e.xyz.push_back(T(std::strtod(w.c_str(), nullptr)));
    }
    return e;
}

std::vector<fs::path> corpus() {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(fs::path(FIBLET_TESTS_DIR) / "conformance"))
        if (entry.path().extension() == ".fft" || entry.path().extension() == ".fftz") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

TEST(Conformance, EveryFileDecodesToItsCommittedPointsWithEveryDecoder) {
    const auto files = corpus();
    ASSERT_GE(files.size(), 20u);
    std::size_t points = 0;
    std::vector<int> versions;
    for (const fs::path& path : files) {
        const Expected e = read_expected(path.string() + ".txt");
        const FftFile file(path.string());
        ASSERT_EQ(file.header().fibers, e.counts.size()) << path;
        versions.push_back(file.header().version);
        for (const std::string& decoder : available_decoders()) {
            DecodeOptions o;
            o.decoder = parse_decoder(decoder);
            o.threads = 1;
            Streamlines got;
            decode_file(file, [&](std::uint64_t, const Streamlines& chunk) {
                const std::uint64_t base = got.offsets.empty() ? 0 : got.offsets.back();
                if (got.offsets.empty()) got.offsets.push_back(0);
                for (std::size_t i = 1; i < chunk.offsets.size(); ++i) got.offsets.push_back(base + chunk.offsets[i]);
                got.xyz.insert(got.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
            }, o);
            std::vector<std::uint64_t> counts;
            for (std::size_t i = 1; i < got.offsets.size(); ++i) counts.push_back(got.offsets[i] - got.offsets[i - 1]);
            EXPECT_EQ(counts, e.counts) << path << " " << decoder;
            ASSERT_EQ(got.xyz.size(), e.xyz.size()) << path << " " << decoder;
            std::size_t differ = 0;
            double worst = 0;
            for (std::size_t i = 0; i < e.xyz.size(); ++i)
                differ += got.xyz[i] != e.xyz[i], worst = std::max(worst, double(std::abs(got.xyz[i] - e.xyz[i])));
            if (decoder.rfind("warp", 0) == 0)  // a prefix product: the float rounding of another order
                EXPECT_LE(worst, 5e-4) << path << " " << decoder;
            else
                EXPECT_EQ(differ, 0u) << path << " " << decoder;
        }
        points += e.xyz.size() / 3;
    }
    std::sort(versions.begin(), versions.end());
    versions.erase(std::unique(versions.begin(), versions.end()), versions.end());
    EXPECT_EQ(versions, (std::vector<int>{2, 16, 17})) << "every version in the corpus";
    EXPECT_GT(points, 5000u);
}

// The float64 points beside each .fft and .fftz (NAME.f64.txt, the
// reference decoder of tests/exact_decoder.hpp, written from formats/ alone;
// a container unpacked by tests/fftz_spec_reader.hpp): the reference decoder
// reproduces them exactly, and every fiblet decoder comes within 0.5 um of
// them (0.25 um at most on this corpus: float32 frames along the fallback
// helper and 255-point fibers; version 16 0.17 um).
TEST(Conformance, FloatDecodersStayNearTheFloat64Points) {
    std::size_t files = 0, containers = 0;
    for (const fs::path& path : corpus()) {
        const fs::path f64 = path.string() + ".f64.txt";
        ASSERT_TRUE(fs::exists(f64)) << f64;
        ++files;
        const Points<double> e = read_expected<double>(f64);
        std::string bytes = test::read_file(path.string());
        if (test::fftz_spec::is_fftz(bytes)) bytes = test::fftz_spec::unpack(bytes), ++containers;
        const auto exact = test::exact::decode(bytes);
        ASSERT_EQ(exact.fibers.size(), e.counts.size()) << path;
        std::size_t at = 0, differ = 0;
        for (std::size_t f = 0; f < exact.fibers.size(); ++f) {
            ASSERT_EQ(exact.fibers[f].size(), e.counts[f]) << path << " fiber " << f;
            for (const auto& p : exact.fibers[f])
                differ += (p.x != e.xyz[at]) + (p.y != e.xyz[at + 1]) + (p.z != e.xyz[at + 2]), at += 3;
        }
        EXPECT_EQ(differ, 0u) << path << ": the reference decoder no longer gives the committed float64 points";
        const FftFile file(path.string());
        for (const std::string& decoder : available_decoders()) {
            DecodeOptions o;
            o.decoder = parse_decoder(decoder);
            const Streamlines got = decode_fibers(file, 0, file.header().fibers, o);
            ASSERT_EQ(got.xyz.size(), e.xyz.size()) << path << " " << decoder;
            double worst = 0;
            for (std::size_t i = 0; i < e.xyz.size(); i += 3) {
                const double dx = got.xyz[i] - e.xyz[i], dy = got.xyz[i + 1] - e.xyz[i + 1], dz = got.xyz[i + 2] - e.xyz[i + 2];
                worst = std::max(worst, std::sqrt(dx * dx + dy * dy + dz * dz));
            }
            EXPECT_LE(worst, 5e-4) << path << " " << decoder;
        }
    }
    EXPECT_GE(files, 20u);
    EXPECT_GE(containers, 10u);
}

// The container's spec alone unpacks each 8-bit .fftz of the corpus to the
// .fft beside it, byte for byte (tests/fftz_spec_reader.hpp shares no code
// with the library's container reader).
TEST(Conformance, ContainersUnpackByTheSpecToTheirFft) {
    std::size_t pairs = 0;
    for (const fs::path& path : corpus()) {
        if (path.extension() != ".fftz") continue;
        const std::string name = path.filename().string();
        const fs::path fft = path.parent_path() / (name.substr(0, name.size() - 5) + ".fft");
        if (!fs::exists(fft)) continue;  // version 16 exists only in the container
        EXPECT_TRUE(test::fftz_spec::unpack(test::read_file(path.string())) == test::read_file(fft.string())) << path;
        ++pairs;
    }
    EXPECT_GE(pairs, 5u);
}
