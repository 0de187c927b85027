// What the .trk and TRX readers refuse where they read it, so that compress
// never writes a file its own readers then refuse: non-finite coordinates
// (named by streamline and point), a .trk version or dimension no reader
// takes, a TRX affine beyond float32, one TRX array under two dtypes, and
// header counts that are not integers in range (checked before any cast).
// Each case: the reader's category through the API, and compress exiting 4
// with no output left.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/trk.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using test::TempDir;

void read_all(const std::string& path) {
    auto s = open_streamline_source(path);
    std::vector<Vec3f> points;
    while (s->next(points)) {
    }
}

// The reader's error (category and message) for `path`.
struct Refusal {
    std::optional<Errc> code;
    std::string message;
};
Refusal refusal(const std::string& path) {
    try {
        read_all(path);
    } catch (const Error& e) {
        return {e.code(), e.what()};
    }
    return {};
}

// compress refuses it as bad input (exit 4) and leaves no output.
void expect_compress_refuses(const TempDir& dir, const std::string& input) {
    const std::string out = dir.file("out.fft");
    const auto r = test::run_cli("compress -q " + input + " -o " + out);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

// `path` is refused by its reader with `code` and a message holding `what`,
// and by compress.
void expect_refused(const TempDir& dir, const std::string& path, Errc code, const std::string& what) {
    const Refusal r = refusal(path);
    EXPECT_EQ(r.code, code);
    EXPECT_NE(r.message.find(what), std::string::npos) << r.message;
    expect_compress_refuses(dir, path);
}

std::string le32(std::int32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string le16(std::int16_t v) { return std::string(reinterpret_cast<const char*>(&v), 2); }
std::string f32(float v) { return std::string(reinterpret_cast<const char*>(&v), 4); }

// A .trk of two 3-point streamlines (identity space), written by fiblet.
std::string trk_file(const TempDir& dir, const std::string& name) {
    const std::string path = dir.file(name);
    SinkHeader h;
    h.fibers = 2, h.points = 6;
    TrkWriter w(path, h, true);
    const float xyz[] = {1, 2, 3, 1.5f, 2, 3, 2, 2, 3, 5, 5, 5, 5, 5.5f, 5, 5, 6, 5};
    w.write(xyz, 3);
    w.write(xyz + 9, 3);
    w.finish();
    return path;
}

// `src` with `bytes` written at `offset`, as `name`.
std::string patched(const TempDir& dir, const std::string& src, std::size_t offset, const std::string& bytes,
                    const std::string& name) {
    std::string data = test::read_file(src);
    data.replace(offset, bytes.size(), bytes);
    test::write_file(dir.file(name), data);
    return dir.file(name);
}

// The first point's y of the second streamline: after the 1000-byte header,
// streamline 0 (a count and 3 points), the count of streamline 1, x.
constexpr std::size_t kTrkSecondY = 1000 + 4 + 36 + 4 + 4;
constexpr std::size_t kTrkDimY = 6 + 2;  // int16 dim[3] after "TRACK\0"
constexpr std::size_t kTrkVersion = 992;

TEST(ReaderRefusals, TrkNonFiniteCoordinatesNameTheirStreamlineAndPoint) {
    TempDir dir;
    const std::string good = trk_file(dir, "good.trk");
    ASSERT_FALSE(refusal(good).code);
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        const std::string path = patched(dir, good, kTrkSecondY, f32(bad), "bad.trk");
        expect_refused(dir, path, Errc::trk_format, "streamline 1 (0-based) point 0 (0-based) is not finite");
    }
}

// A point count beyond the file is damage in every command (compress said
// "unsupported", exit 6, where info said malformed, exit 4).
TEST(ReaderRefusals, TrkCountBeyondTheFileIsMalformedEverywhere) {
    TempDir dir;
    const std::string path = patched(dir, trk_file(dir, "good.trk"), 1000, le32(0x7fffffff), "count.trk");
    expect_refused(dir, path, Errc::trk_format, "streamline 0 (0-based) claims 2147483647 points, more than the file holds");
    EXPECT_EQ(test::run_cli("info " + path).status, 4);
}

TEST(ReaderRefusals, TrkVersionThreeAndNegativeDimensions) {
    TempDir dir;
    const std::string good = trk_file(dir, "good.trk");
    EXPECT_EQ(refusal(patched(dir, good, kTrkVersion, le32(3), "v3.trk")).code, Errc::unsupported);
    const std::string negative = patched(dir, good, kTrkDimY, le16(-4), "dim.trk");
    expect_refused(dir, negative, Errc::trk_format, "dimension -4 is negative");
}

// A TRX directory: header.json as given, two streamlines of 1 and 2 float32 points.
std::string trx_dir(const TempDir& dir, const std::string& name, const std::string& header_json,
                    std::vector<float> positions = {1, 2, 3, 4, 5, 6, 4, 5, 7}) {
    const std::string root = dir.file(name);
    std::filesystem::create_directories(root);
    test::write_file(root + "/header.json", header_json);
    test::write_file(root + "/positions.3.float32",
                     std::string(reinterpret_cast<const char*>(positions.data()), positions.size() * 4));
    const std::uint32_t offsets[2] = {0, 1};
    test::write_file(root + "/offsets.uint32", std::string(reinterpret_cast<const char*>(offsets), sizeof offsets));
    return root;
}

std::string trx_header(const std::string& affine_scale, const std::string& streamlines, const std::string& vertices) {
    return R"({"VOXEL_TO_RASMM": [[)" + affine_scale + R"(,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "DIMENSIONS": [10, 10, 10], )" +
           R"("NB_STREAMLINES": )" + streamlines + R"(, "NB_VERTICES": )" + vertices + "}";
}

TEST(ReaderRefusals, TrxNonFinitePositionsNameTheirStreamlineAndPoint) {
    TempDir dir;
    ASSERT_FALSE(refusal(trx_dir(dir, "good.trx", trx_header("1", "2", "3"))).code);
    const std::string path =
        trx_dir(dir, "nan.trx", trx_header("1", "2", "3"), {1, 2, 3, 4, 5, 6, 4, std::nanf(""), 7});
    expect_refused(dir, path, Errc::trx_format, "streamline 1 (0-based) point 1 (0-based) is not finite");
}

TEST(ReaderRefusals, TrxAffineBeyondFloat32) {
    TempDir dir;
    const std::string path = trx_dir(dir, "huge.trx", trx_header("1e300", "2", "3"));
    expect_refused(dir, path, Errc::trx_format, "not a float32 number");
}

TEST(ReaderRefusals, TrxOneArrayUnderTwoDtypes) {
    TempDir dir;
    const std::string root = trx_dir(dir, "twice.trx", trx_header("1", "2", "3"));
    std::filesystem::create_directories(root + "/dps");
    const float w32[2] = {1, 2};
    const double w64[2] = {1, 2};
    test::write_file(root + "/dps/w.float32", std::string(reinterpret_cast<const char*>(w32), sizeof w32));
    test::write_file(root + "/dps/w.float64", std::string(reinterpret_cast<const char*>(w64), sizeof w64));
    expect_refused(dir, root, Errc::trx_format, "more than one array named dps/w");
}

TEST(ReaderRefusals, TrxCountsAreIntegersInRangeBeforeAnyCast) {
    TempDir dir;
    // 1e30 and 2^62 + 1 overflowed (or wrapped a size product); 10.5 was cut to 10; -3 is no count.
    for (const std::string vertices : {"1e30", "4611686018427387905", "10.5", "-3", "\"3\""}) {
        SCOPED_TRACE(vertices);
        const Refusal r = refusal(trx_dir(dir, "count.trx", trx_header("1", "2", vertices)));
        EXPECT_EQ(r.code, Errc::trx_format);
        EXPECT_NE(r.message.find("NB_VERTICES is"), std::string::npos) << r.message;
        std::filesystem::remove_all(dir.file("count.trx"));
    }
    // An integral float is a count.
    EXPECT_FALSE(refusal(trx_dir(dir, "float.trx", trx_header("1", "2.0", "3.0"))).code);
}

// The CLI's exit status and peak RSS (MB) for `args`.
std::pair<int, double> status_and_peak_rss_mb(const std::vector<std::string>& args) {
    const test::PeakRun r = test::run_cli_peak(args);
    return {r.status, r.peak_mb};
}

// Small files that claimed gigabytes were given them: memory follows what the
// file holds, not what it says (issue 32, class 3). Peak RSS before the fix:
// 1.27 GB (header.json of nested '['), ~1.5 GB (the gzip mask).
TEST(ReaderRefusals, SmallFilesClaimingGigabytesStayWithinAFewMegabytes) {
    TempDir dir;
    const double bound_mb = test::kSanitized ? 1024 : 200;
    // header.json of 8 MiB of '[': the parser built ~80 bytes per level.
    const std::string deep = trx_dir(dir, "deep.trx", std::string(8u << 20, '['));
    const Refusal r = refusal(deep);
    EXPECT_EQ(r.code, Errc::trx_format);
    EXPECT_NE(r.message.find("nests deeper than 32 levels"), std::string::npos) << r.message;
    const auto [deep_status, deep_mb] = status_and_peak_rss_mb({"compress", "-q", deep, "-o", dir.file("deep.fft")});
    EXPECT_EQ(deep_status, 4);
    EXPECT_LT(deep_mb, bound_mb);

    // A .nii.gz whose header claims 1000 x 1000 x 1500 uint8 voxels (1.5 GB,
    // within the 1032:1 deflate ratio of its 1.5 MB) and holds 1.5 MB.
    std::string nii(352, '\0');
    auto put16 = [&](std::size_t at, std::int16_t v) { std::memcpy(&nii[at], &v, 2); };
    auto put32 = [&](std::size_t at, std::int32_t v) { std::memcpy(&nii[at], &v, 4); };
    auto putf = [&](std::size_t at, float v) { std::memcpy(&nii[at], &v, 4); };
    put32(0, 348);
    const std::int16_t dims[4] = {3, 1000, 1000, 1500};
    for (int i = 0; i < 4; ++i) put16(40 + 2 * std::size_t(i), dims[i]);
    for (int i = 4; i < 8; ++i) put16(40 + 2 * std::size_t(i), 1);
    put16(70, 2), put16(72, 8);  // uint8, 8 bits
    for (int i = 0; i < 8; ++i) putf(76 + 4 * std::size_t(i), 1.0f);
    putf(108, 352.0f);
    std::memcpy(&nii[344], "n+1", 4);
    std::mt19937 rng(7);
    std::string noise(std::size_t(1.5 * (1 << 20)), '\0');
    for (char& c : noise) c = char(rng());
    test::write_file(dir.file("mask.nii"), nii + noise);
    ASSERT_EQ(test::run_command("gzip -1 " + dir.file("mask.nii")).status, 0);
    const std::string tck = dir.file("t.tck"), fft = dir.file("t.fft");
    std::string data = "mrtrix tracks\ndatatype: Float32LE\nfile: . 64\nEND\n";
    data.resize(64, '\0');
    const float pts[] = {0, 0, 0, 1, 0, 0, NAN, NAN, NAN, INFINITY, INFINITY, INFINITY};
    data.append(reinterpret_cast<const char*>(pts), sizeof pts);
    test::write_file(tck, data);
    ASSERT_EQ(test::run_cli("compress -q " + tck + " -o " + fft).status, 0);
    const auto [mask_status, mask_mb] = status_and_peak_rss_mb(
        {"extract", "-q", fft, "--include", dir.file("mask.nii.gz"), "-o", dir.file("o.tck")});
    EXPECT_EQ(mask_status, 4);
    EXPECT_LT(mask_mb, bound_mb);
}

// An honest mask: 400^3 uint8 voxels (64 MB), a cube of ones, gzipped to a
// few hundred kB, with a second volume. Read as a mask it costs a byte a
// voxel of its first volume (was: every volume widened to float32 after
// its raw bytes, 330 MB), and it selects what it should.
TEST(ReaderRefusals, MasksAreReadAsBytesNotFloats) {
    TempDir dir;
    const std::int16_t n = 400;
    std::string nii(352, '\0');
    auto put16 = [&](std::size_t at, std::int16_t v) { std::memcpy(&nii[at], &v, 2); };
    auto putf = [&](std::size_t at, float v) { std::memcpy(&nii[at], &v, 4); };
    const std::int32_t header = 348;
    std::memcpy(&nii[0], &header, 4);
    const std::int16_t dims[5] = {4, n, n, n, 2};
    for (int i = 0; i < 5; ++i) put16(40 + 2 * std::size_t(i), dims[i]);
    for (int i = 5; i < 8; ++i) put16(40 + 2 * std::size_t(i), 1);
    put16(70, 2), put16(72, 8);  // uint8
    for (int i = 0; i < 8; ++i) putf(76 + 4 * std::size_t(i), 1.0f);  // 1 mm voxels, identity axes
    putf(108, 352.0f);
    std::memcpy(&nii[344], "n+1", 4);
    const std::size_t volume = std::size_t(n) * n * n;
    std::string voxels(2 * volume, '\0');
    for (std::size_t k = 190; k < 210; ++k)  // the first volume's cube: voxels 190..209 on each axis
        for (std::size_t j = 190; j < 210; ++j) std::memset(&voxels[190 + n * (j + n * k)], 1, 20);
    test::write_file(dir.file("mask.nii"), nii + voxels);
    voxels.clear(), voxels.shrink_to_fit();
    ASSERT_EQ(test::run_command("gzip -1 " + dir.file("mask.nii")).status, 0);
    // MRtrix's default transform centres the grid on the origin: the cube
    // spans world -10.5 .. 9.5 mm on each axis. Two fibers: one through it.
    const std::string tck = dir.file("t.tck"), fft = dir.file("t.fft");
    std::string data = "mrtrix tracks\ndatatype: Float32LE\nfile: . 64\nEND\n";
    data.resize(64, '\0');
    std::vector<float> pts;
    for (int f = 0; f < 2; ++f) {
        for (int k = 0; k < 100; ++k) pts.insert(pts.end(), {-50.0f + float(k), f ? 40.0f : 0.0f, 0.0f});
        pts.insert(pts.end(), {NAN, NAN, NAN});
    }
    pts.insert(pts.end(), {INFINITY, INFINITY, INFINITY});
    data.append(reinterpret_cast<const char*>(pts.data()), pts.size() * sizeof(float));
    test::write_file(tck, data);
    ASSERT_EQ(test::run_cli("compress -q " + tck + " -o " + fft).status, 0);
    const auto [status, mb] = status_and_peak_rss_mb(
        {"extract", "-q", fft, "--include", dir.file("mask.nii.gz"), "-o", dir.file("o.fft")});
    ASSERT_EQ(status, 0);
    EXPECT_LT(mb, test::kSanitized ? 1024 : 200);
    EXPECT_EQ(FftFile(dir.file("o.fft")).header().fibers, 1u);
}

// A TRX directory of a three-point streamline reaching `length` mm (its
// uneven spacing resampled to ~1 mm: thousands of points) and a one-point
// one, with `components` uint8 values a point (dpv/x).
std::string long_resampled_trx(const TempDir& dir, const std::string& name, float length, std::size_t components,
                               const std::string& dtype = "uint8", std::size_t value_size = 1) {
    const std::string root = trx_dir(dir, name, trx_header("1", "2", "4"), {0, 0, 0, 1, 0, 0, length, 0, 0, 5, 5, 5});
    const std::uint32_t offsets[2] = {0, 3};
    test::write_file(root + "/offsets.uint32", std::string(reinterpret_cast<const char*>(offsets), sizeof offsets));
    std::filesystem::create_directories(root + "/dpv");
    test::write_file(root + "/dpv/x." + std::to_string(components) + "." + dtype,
                     std::string(4 * components * value_size, '\x07'));
    return root;
}

// Per-point data x resampling: 400 kB of values on a 20 m segment would
// take 1.9 GB once resampled (was: allocated until bad_alloc, exit 1). It
// is sized against the memory budget before anything is allocated.
TEST(ReaderRefusals, ResampledPerPointDataIsSizedAgainstTheMemoryBudget) {
    TempDir dir;
    const std::string big = long_resampled_trx(dir, "big.trx", 20000, 100000);
    const auto [status, mb] = status_and_peak_rss_mb({"compress", "-q", big, "-o", dir.file("big.fft"), "--max-memory", "1G"});
    EXPECT_EQ(status, 6);
    EXPECT_LT(mb, test::kSanitized ? 1024 : 200);
    EXPECT_FALSE(std::filesystem::exists(dir.file("big.fft")));
    const auto r = test::run_cli("compress -q " + big + " -o " + dir.file("big.fft") + " --max-memory 1G");
    EXPECT_NE(r.output.find("more than the memory budget of 1024 MiB; --max-memory"), std::string::npos) << r.output;
    // Within the budget: written, the labels in their dtype, a row a point.
    const std::string small = long_resampled_trx(dir, "small.trx", 2000, 50);
    ASSERT_EQ(test::run_cli("compress -q " + small + " -o " + dir.file("small.fft") + " --max-memory 64M").status, 0);
    const FftFile f(dir.file("small.fft"));
    ASSERT_EQ(f.streamline_fields().size(), 1u);
    EXPECT_EQ(f.streamline_fields()[0].type, FieldType::uint8);
    EXPECT_GT(f.header().points, 1000u);
    EXPECT_EQ(f.streamline_fields()[0].rows(), f.header().points);
    EXPECT_EQ(f.streamline_fields()[0].bytes, std::vector<std::uint8_t>(50 * f.header().points, 7));
}

// The budget counts two copies of the resampled per-point arrays (the values
// and the DATA chunk made of them), and the peak holds to it: the resampler's
// columns are released as the fields take them, the checksum hashes the
// trailer chunk by chunk, a large write goes straight to the file. Before,
// a 320 MB array peaked at 1.25 GB (four copies).
TEST(ReaderRefusals, ResampledPerPointDataPeaksAtTwoCopies) {
    TempDir dir;
    // ~20,000 resampled points x 1250 float32: 100 MB of values.
    const std::string trx = long_resampled_trx(dir, "float.trx", 20000, 1250, "float32", 4);
    const auto [status, mb] = status_and_peak_rss_mb({"compress", "-q", "-j", "1", trx, "-o", dir.file("f.fft")});
    ASSERT_EQ(status, 0);
    const FftFile f(dir.file("f.fft"));
    ASSERT_EQ(f.streamline_fields().size(), 1u);
    const double values_mb = double(f.streamline_fields()[0].bytes.size()) / (1 << 20);
    EXPECT_GT(values_mb, 80);
    if (!test::kSanitized) {
        EXPECT_LT(mb, 2.4 * values_mb + 40) << values_mb << " MB of values";
    }
}

// Without --max-memory the budget is half of what the process may use: under
// `ulimit -v` that limit, not the machine's memory, so a file whose arrays
// would not fit is refused (exit 6) instead of failing in the allocator
// (bad_alloc, exit 1, as before).
TEST(ReaderRefusals, DefaultBudgetFollowsTheProcessLimits) {
    const std::uint64_t unlimited = default_memory_budget();
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const std::uint64_t limit = std::uint64_t(1) << 30;
    if (const pid_t pid = ::fork(); pid == 0) {
        const rlimit r{limit, limit};
        std::uint64_t budget = ::setrlimit(RLIMIT_DATA, &r) == 0 ? default_memory_budget() : 0;
        ::write(fds[1], &budget, sizeof budget);
        ::_exit(0);
    } else {
        std::uint64_t budget = 0;
        EXPECT_EQ(::read(fds[0], &budget, sizeof budget), ssize_t(sizeof budget));
        ::waitpid(pid, nullptr, 0);
        ::close(fds[0]), ::close(fds[1]);
        EXPECT_EQ(budget, std::min(unlimited, limit / 2));
    }
    if (test::kSanitized) return;  // ASan reserves its shadow memory beyond any such ulimit -v
    TempDir dir;
    const std::string big = long_resampled_trx(dir, "big.trx", 20000, 100000);  // 1.9 GB once resampled
    const auto r = test::run_cli("compress -q " + big + " -o " + dir.file("big.fft"), "ulimit -v 2000000;");
    EXPECT_EQ(r.status, 6) << r.output;
    EXPECT_NE(r.output.find("more than the memory budget of"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("big.fft")));
}

// A TRX's data arrays count against the memory budget before each is read
// (a 1.3 MB zip of twenty 64 MiB dpg arrays took 1.29 GB): here four
// 400 kB dpg arrays, against budgets of 1 MiB and 8 MiB.
TEST(ReaderRefusals, TrxDataArraysDrawFromTheMemoryBudget) {
    TempDir dir;
    const std::string root = trx_dir(dir, "dpg.trx", trx_header("1", "2", "3"));
    for (int g = 0; g < 4; ++g) {
        const std::string group = "G" + std::to_string(g);
        std::filesystem::create_directories(root + "/dpg/" + group);
        test::write_file(root + "/dpg/" + group + "/v.uint8", std::string(400000, '\x01'));
    }
    const auto r = test::run_cli("compress -q " + root + " -o " + dir.file("a.fft") + " --max-memory 1M");
    EXPECT_EQ(r.status, 6) << r.output;
    EXPECT_NE(r.output.find("more than the memory budget of 1 MiB; --max-memory"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("a.fft")));
    ASSERT_EQ(test::run_cli("compress -q " + root + " -o " + dir.file("a.fft") + " --max-memory 8M").status, 0);
    EXPECT_EQ(FftFile(dir.file("a.fft")).streamline_fields().size(), 4u);
}

// 2^21 empty streamlines (an 8 MiB offsets array, 131 kB zipped at 2^24):
// compress's memory follows the per-fiber tables of its output, no longer
// one batch of them all and a tuning sample of every one (2^21: 297 MB
// before, 90 MB now; 2^24: 1.84 GB before, 486 MB for a 151 MB output);
// those tables draw from the memory budget as the scan counts them (2^21
// of ~32 bytes: 64 MiB, refused under a 32 MiB budget, before pass 2).
TEST(ReaderRefusals, EmptyStreamlinesCostTheirTablesOnly) {
    TempDir dir;
    const std::uint32_t n = 1u << 21;
    const std::string root = dir.file("empty.trx");
    std::filesystem::create_directories(root);
    test::write_file(root + "/header.json", trx_header("1", std::to_string(n), "0"));
    test::write_file(root + "/positions.3.float32", "");
    test::write_file(root + "/offsets.uint32", std::string(std::size_t(n) * 4, '\0'));
    const auto [status, mb] = status_and_peak_rss_mb({"compress", "-q", root, "-o", dir.file("e.fft")});
    EXPECT_EQ(status, 0);
    EXPECT_LT(mb, test::kSanitized ? 2048 : 160);
    const auto info = test::run_cli("info --json " + dir.file("e.fft"));
    EXPECT_NE(info.output.find("\"fibers\": " + std::to_string(n)), std::string::npos) << info.output.substr(0, 300);
    const auto refused = test::run_cli("compress -q " + root + " -o " + dir.file("f.fft") + " --max-memory 32M");
    EXPECT_EQ(refused.status, 6) << refused.output;
    EXPECT_NE(refused.output.find("streamlines and counting: their tables (about 32 bytes each) would take more than "
                                  "the memory budget of 32 MiB; --max-memory"),
              std::string::npos)
        << refused.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("f.fft")));
    // The offsets array and its 64-bit table (8 + 16 MiB) count before they are read.
    const auto [offsets_status, offsets_mb] =
        status_and_peak_rss_mb({"compress", "-q", root, "-o", dir.file("g.fft"), "--max-memory", "16M"});
    EXPECT_EQ(offsets_status, 6);
    EXPECT_LT(offsets_mb, test::kSanitized ? 2048 : 24);
    const auto offsets = test::run_cli("compress -q " + root + " -o " + dir.file("g.fft") + " --max-memory 16M");
    EXPECT_NE(offsets.output.find("its arrays take 24 MiB and more (offsets.uint32 included)"), std::string::npos)
        << offsets.output;
}

}  // namespace
}  // namespace fiblet
