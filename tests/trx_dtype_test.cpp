// TRX dtypes through a .fft: a TRX written by hand per the spec (a
// directory and a stored zip) goes through `fiblet compress` and `fiblet
// decompress -o x.trx`; every array comes back in its dtype (positions
// float16/float64, offsets uint32/uint64, dps, dpv, groups, dpg), data
// exactly, points within the recorded error (or as decoded for a resampled
// input), and `--json` lists what did not come back in its dtype.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/source_dtypes.hpp"
#include "fiblet/streamline_field.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"
#include "tractogram/trx/trx_archive.hpp"

namespace fiblet {
namespace {

using test::run_cli;
using test::TempDir;
using Entries = std::map<std::string, std::string>;  // TRX entry -> bytes

template <class T>
std::string bytes_of(const std::vector<T>& v) {
    return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

template <class T>
std::vector<T> values_of(const std::string& bytes) {
    std::vector<T> v(bytes.size() / sizeof(T));
    std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
    return v;
}

std::uint32_t crc32(const std::string& s) {
    std::uint32_t c = 0xffffffffu;
    for (unsigned char b : s) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1)));
    }
    return ~c;
}

// A zip of stored entries (PKWARE APPNOTE 4.3: local headers, central directory, end record).
std::string stored_zip(const Entries& entries) {
    std::string out, central;
    const auto u16 = [](std::string& s, unsigned v) { s += char(v & 0xff), s += char((v >> 8) & 0xff); };
    const auto u32 = [&](std::string& s, std::uint32_t v) { u16(s, v & 0xffff), u16(s, v >> 16); };
    for (const auto& [name, data] : entries) {
        const std::uint32_t offset = std::uint32_t(out.size()), crc = crc32(data), size = std::uint32_t(data.size());
        u32(out, 0x04034b50), u16(out, 20), u16(out, 0), u16(out, 0), u16(out, 0), u16(out, 0x21);
        u32(out, crc), u32(out, size), u32(out, size), u16(out, unsigned(name.size())), u16(out, 0);
        out += name + data;
        u32(central, 0x02014b50), u16(central, 20), u16(central, 20), u16(central, 0), u16(central, 0);
        u16(central, 0), u16(central, 0x21), u32(central, crc), u32(central, size), u32(central, size);
        u16(central, unsigned(name.size())), u16(central, 0), u16(central, 0), u16(central, 0), u16(central, 0);
        u32(central, 0), u32(central, offset);
        central += name;
    }
    const std::uint32_t at = std::uint32_t(out.size());
    out += central;
    u32(out, 0x06054b50), u16(out, 0), u16(out, 0), u16(out, unsigned(entries.size())),
        u16(out, unsigned(entries.size())), u32(out, std::uint32_t(central.size())), u32(out, at), u16(out, 0);
    return out;
}

std::string header_json(std::size_t fibers, std::size_t points) {
    return R"({"VOXEL_TO_RASMM": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "DIMENSIONS": [100, 100, 100], )"
           R"("NB_STREAMLINES": )" +
           std::to_string(fibers) + R"(, "NB_VERTICES": )" + std::to_string(points) + "}";
}

Entries read_trx(const std::string& path) {
    Entries e;
    const auto archive = detail::TrxArchive::open(path);
    for (const std::string& name : archive->entries()) {
        const auto b = archive->read_all(name);
        e[name] = std::string(b.begin(), b.end());
    }
    return e;
}

std::vector<std::string> names(const Entries& e) {
    std::vector<std::string> n;
    for (const auto& kv : e) n.push_back(kv.first);
    return n;
}

// Helices sampled at a fixed arc length (a fixed-step input: not resampled),
// or with a varying step (resampled).
std::vector<double> helices(std::size_t fibers, std::size_t points, bool fixed_step) {
    std::vector<double> p;
    for (std::size_t f = 0; f < fibers; ++f)
        for (std::size_t i = 0; i < points; ++i) {
            const double t = fixed_step ? 0.1 * double(i) : 0.1 * double(i) + 0.004 * double(i * i % 7);
            p.insert(p.end(), {20 + 8 * std::cos(t), 30 + 8 * std::sin(t) + double(f), 10 + 2 * t});
        }
    return p;
}

TEST(FloatToHalf, RoundTripsEveryHalfAndRoundsToNearestEven) {
    for (std::uint32_t h = 0; h < 0x10000; ++h) {
        const float v = half_to_float(std::uint16_t(h));
        if (std::isnan(v)) EXPECT_TRUE(std::isnan(half_to_float(float_to_half(v))));
        else EXPECT_EQ(float_to_half(v), h) << h;
    }
    EXPECT_EQ(float_to_half(1.0f + 1.0f / 2048), 0x3c00);              // tie between 1 and 1 + 2^-10: even
    EXPECT_EQ(float_to_half(1.0f + 3.0f / 2048), 0x3c02);              // tie: up to even
    EXPECT_EQ(float_to_half(65519.0f), 0x7bff);                        // largest half
    EXPECT_EQ(float_to_half(65520.0f), 0x7c00);                        // rounds to infinity
    EXPECT_EQ(float_to_half(-std::ldexp(1.0f, -25) * 1.5f), 0x8001);  // subnormal, rounded up
}

// Fixed step: nothing interpolated, so every array but the positions comes
// back byte for byte, the positions within the file's recorded error.
TEST(TrxThroughFft, DirectoryArraysComeBackInTheirDtypes) {
    TempDir dir;
    const std::string src = dir.file("in.trx");
    const std::size_t fibers = 6, n = 40, points = fibers * n;
    const std::vector<double> pos = helices(fibers, n, true);
    std::vector<std::uint32_t> offsets;
    for (std::size_t f = 0; f < fibers; ++f) offsets.push_back(std::uint32_t(f * n));  // no sentinel (spec)
    std::vector<double> fa, weight;
    std::vector<std::uint8_t> idx;
    for (std::size_t i = 0; i < points; ++i) fa.push_back(0.1 + 1e-9 * double(i)), idx.push_back(std::uint8_t(i));
    for (std::size_t f = 0; f < fibers; ++f) weight.insert(weight.end(), {1.0 / 3 + double(f), -1e300});
    const Entries in{
        {"header.json", header_json(fibers, points)},
        {"positions.3.float64", bytes_of(pos)},
        {"offsets.uint32", bytes_of(offsets)},
        {"dps/label.int16", bytes_of(std::vector<std::int16_t>{-3, 7, 300, -32768, 0, 1})},
        {"dps/weight.2.float64", bytes_of(weight)},
        {"dpv/fa.float64", bytes_of(fa)},
        {"dpv/idx.uint8", bytes_of(idx)},
        {"groups/CST.uint32", bytes_of(std::vector<std::uint32_t>{4, 0, 2})},
        {"dpg/CST/volume.float64", bytes_of(std::vector<double>{1234.5678901234})},
    };
    for (const auto& [name, bytes] : in) {
        std::filesystem::create_directories(std::filesystem::path(dir.file("in.trx/" + name)).parent_path());
        test::write_file(dir.file("in.trx/" + name), bytes);
    }
    ASSERT_EQ(run_cli("compress -q " + src + " -o " + dir.file("a.fft")).status, 0);
    const auto r = run_cli("decompress -q --json " + dir.file("a.fft") + " -o " + dir.file("out.trx"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(R"("dtype_changes": [])"), std::string::npos) << r.output;
    const FftFile file(dir.file("a.fft"));
    ASSERT_EQ(file.header().points, points);  // not resampled

    const Entries out = read_trx(dir.file("out.trx"));
    std::vector<std::string> expected = names(in);
    EXPECT_EQ(names(out), expected);  // every entry, with its dtype
    for (const auto& [name, bytes] : in) {
        if (name.starts_with("dp") || name.starts_with("groups/")) {
            EXPECT_EQ(out.at(name), bytes) << name;
        }
    }
    std::vector<std::uint32_t> out_offsets = values_of<std::uint32_t>(out.at("offsets.uint32"));
    ASSERT_EQ(out_offsets.size(), fibers + 1);  // with the sentinel
    EXPECT_EQ(out_offsets.back(), points);
    out_offsets.pop_back();
    EXPECT_EQ(out_offsets, offsets);
    const std::vector<double> decoded = values_of<double>(out.at("positions.3.float64"));
    ASSERT_EQ(decoded.size(), pos.size());
    const double bound = file.header().max_error_mm + 1e-6;
    double worst = 0;
    for (std::size_t i = 0; i < points; ++i) {
        const double dx = decoded[3 * i] - pos[3 * i], dy = decoded[3 * i + 1] - pos[3 * i + 1],
                     dz = decoded[3 * i + 2] - pos[3 * i + 2];
        worst = std::max(worst, std::sqrt(dx * dx + dy * dy + dz * dz));
        EXPECT_EQ(decoded[3 * i], double(float(decoded[3 * i])));  // decoded float32 values, widened
    }
    EXPECT_LE(worst, bound);
    EXPECT_GT(worst, 0);  // the points went through the lossy codec
}

// Resampled input: float per-point values are interpolated, float64 ones
// come back as float64 (the interpolated values); integer ones (labels)
// take the nearer input point's value and keep their dtype; float16
// positions are the decoded points rounded to float16.
TEST(TrxThroughFft, ResampledZipKeepsEveryDtype) {
    TempDir dir;
    const std::size_t fibers = 4, n = 50, points = fibers * n;
    const std::vector<double> pos = helices(fibers, n, false);
    std::vector<std::uint16_t> pos16;
    for (double x : pos) pos16.push_back(float_to_half(float(x)));
    std::vector<std::uint64_t> offsets;
    for (std::size_t f = 0; f <= fibers; ++f) offsets.push_back(f * n);  // with the sentinel
    std::vector<double> fa;
    std::vector<std::uint8_t> idx;
    for (std::size_t i = 0; i < points; ++i) fa.push_back(double(i % n) / 64), idx.push_back(std::uint8_t(i % n));
    const Entries in{
        {"header.json", header_json(fibers, points)},
        {"positions.3.float16", bytes_of(pos16)},
        {"offsets.uint64", bytes_of(offsets)},
        {"dps/w.float32", bytes_of(std::vector<float>{1.5f, 2.5f, 3.5f, 4.5f})},
        {"dpv/fa.float64", bytes_of(fa)},
        {"dpv/idx.uint8", bytes_of(idx)},
    };
    test::write_file(dir.file("in.trx"), stored_zip(in));
    ASSERT_EQ(run_cli("compress -q " + dir.file("in.trx") + " -o " + dir.file("a.fft")).status, 0);
    const auto r = run_cli("decompress -q --json " + dir.file("a.fft") + " -o " + dir.file("out.trx"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(R"("dtype_changes": [])"), std::string::npos) << r.output;
    ASSERT_EQ(run_cli("decompress -q " + dir.file("a.fft") + " -o " + dir.file("out.tck")).status, 0);

    const FftFile file(dir.file("a.fft"));
    const std::uint64_t resampled = file.header().points;
    EXPECT_NE(resampled, points);
    const Entries out = read_trx(dir.file("out.trx"));
    EXPECT_EQ(names(out), (std::vector<std::string>{"dps/w.float32", "dpv/fa.float64", "dpv/idx.uint8", "header.json",
                                                    "offsets.uint64", "positions.3.float16"}));
    EXPECT_EQ(out.at("dps/w.float32"), in.at("dps/w.float32"));
    // The per-point values: the file's interpolated float32 values, as float64.
    const StreamlineField* stored_fa = nullptr;
    for (const StreamlineField& f : file.streamline_fields())
        if (f.name == "dpv/fa") stored_fa = &f;
    ASSERT_NE(stored_fa, nullptr);
    EXPECT_EQ(stored_fa->type, FieldType::float32);
    const std::vector<double> out_fa = values_of<double>(out.at("dpv/fa.float64"));
    ASSERT_EQ(out_fa.size(), resampled);
    for (std::uint64_t i = 0; i < resampled; ++i) ASSERT_EQ(out_fa[i], stored_fa->at(i, 0)) << i;
    // The labels: each input point's index along its fiber, so at the
    // resampled points they start at 0, end at n - 1 (the ends are kept)
    // and never go back; never a value between two labels.
    const std::vector<std::uint8_t> out_idx = values_of<std::uint8_t>(out.at("dpv/idx.uint8"));
    ASSERT_EQ(out_idx.size(), resampled);
    const std::vector<std::uint64_t> out_offsets = values_of<std::uint64_t>(out.at("offsets.uint64"));
    ASSERT_EQ(out_offsets.size(), fibers + 1);
    for (std::size_t f = 0; f < fibers; ++f) {
        const std::uint64_t a = out_offsets[f], b = out_offsets[f + 1];
        ASSERT_GT(b, a + 1);
        EXPECT_EQ(out_idx[a], 0) << f;
        EXPECT_EQ(out_idx[b - 1], n - 1) << f;
        for (std::uint64_t i = a + 1; i < b; ++i) EXPECT_LE(out_idx[i - 1], out_idx[i]) << f << " " << i;
    }
    // Positions: the decoded points (the .tck's), each rounded to float16.
    TckReader tck(dir.file("out.tck"));
    std::vector<Vec3f> fiber;
    std::vector<std::uint16_t> expected;
    std::vector<std::uint64_t> expected_offsets{0};
    while (tck.next(fiber)) {
        for (const Vec3f& p : fiber) expected.insert(expected.end(), {float_to_half(p.x), float_to_half(p.y), float_to_half(p.z)});
        expected_offsets.push_back(expected_offsets.back() + fiber.size());
    }
    EXPECT_EQ(values_of<std::uint16_t>(out.at("positions.3.float16")), expected);
    EXPECT_EQ(values_of<std::uint64_t>(out.at("offsets.uint64")), expected_offsets);
    // The recorded dtypes are not .tck header lines.
    EXPECT_EQ(test::read_file(dir.file("out.tck")).find("dtype"), std::string::npos);
}

// What each output cannot hold is listed; a file without recorded dtypes
// (a .tck source, or an older .fft) keeps float32 points and uint64 offsets.
TEST(SourceDtypes, RestorePlansEachOutput) {
    SinkHeader h;
    h.fibers = 1, h.points = 2;
    add_trx_dtype_properties(h.properties, FieldType::float64, FieldType::uint32);
    add_source_dtype_property(h.properties, "dpv/a b", FieldType::float16);
    h.fields = {{"dpv/a b", FieldType::float32, 1, std::vector<std::uint8_t>(8)},
                {"dps/n", FieldType::int16, 1, std::vector<std::uint8_t>(2)}};
    std::memcpy(h.fields[0].bytes.data(), std::vector<float>{0.5f, 2.0f}.data(), 8);
    SinkHeader trx = h;
    EXPECT_TRUE(restore_source_dtypes(trx, TractogramFormat::trx).empty());
    EXPECT_EQ(trx.positions_type, FieldType::float64);
    EXPECT_EQ(trx.offsets_type, FieldType::uint32);
    EXPECT_EQ(trx.fields[0].type, FieldType::float16);
    EXPECT_EQ(trx.fields[0].at(1, 0), 2.0);
    EXPECT_EQ(trx.fields[1].type, FieldType::int16);
    SinkHeader trk = h;
    const auto changes = restore_source_dtypes(trk, TractogramFormat::trk);
    ASSERT_EQ(changes.size(), 3u);
    EXPECT_EQ(changes[0].array, "positions");
    EXPECT_EQ(changes[1].array, "dpv/a b");
    EXPECT_EQ(changes[1].from, FieldType::float16);
    EXPECT_EQ(changes[2].array, "dps/n");
    SinkHeader plain;
    plain.properties = {{"trx_positions_dtype", "int8"}, {"source_dtype", "nonsense"}};
    EXPECT_TRUE(restore_source_dtypes(plain, TractogramFormat::trx).empty());
    EXPECT_EQ(plain.positions_type, FieldType::float32);
    EXPECT_EQ(plain.offsets_type, FieldType::uint64);
}

}  // namespace
}  // namespace fiblet
