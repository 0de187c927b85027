// Tests of the .trk and TRX readers and writers and of the DATA chunk:
// round trips with space and fields, nibabel's coordinates on the shared
// .trk files (their nibabel-written .tck twins), malformed input, and the
// data of a .trk kept (and checksummed) through a .fft.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/streamline_data_chunk.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/trk.hpp"
#include "fiblet/trx.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using test::TempDir;
using Fibers = std::vector<std::vector<Vec3f>>;

Fibers read_all(StreamlineSource& s) {
    Fibers out;
    std::vector<Vec3f> f;
    while (s.next(f)) out.push_back(f);
    return out;
}

Fibers three_fibers() {
    return {{{1, 2, 3}, {4, 5.5f, 6}, {7, 8, 9.25f}}, {{-10, 20, -30}}, {{0, 0, 0}, {1, 1, 1}}};
}

StreamlineField float_field(const std::string& name, std::uint32_t components, const std::vector<float>& v) {
    StreamlineField f{name, FieldType::float32, components, std::vector<std::uint8_t>(v.size() * 4)};
    std::memcpy(f.bytes.data(), v.data(), f.bytes.size());
    return f;
}

// An oblique-free but permuted, flipped, scaled space: exercises the
// voxel-order reorientation and the half-voxel shift.
TractogramSpace lps_space() {
    TractogramSpace s;
    s.voxel_to_rasmm = {-2, 0, 0, 90, 0, -1.5, 0, 120, 0, 0, 3, -70, 0, 0, 0, 1};
    s.dimensions = {91, 109, 40};
    s.voxel_sizes = {2, 1.5, 3};
    s.voxel_order = "LPS";
    return s;
}

void write(StreamlineSink& sink, const Fibers& fibers) {
    for (const auto& f : fibers) sink.write(&f.data()->x, f.size());
    sink.finish();
}

void expect_near(const Fibers& a, const Fibers& b, double tol) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].size(), b[i].size()) << i;
        for (std::size_t k = 0; k < a[i].size(); ++k) {
            EXPECT_NEAR(a[i][k].x, b[i][k].x, tol);
            EXPECT_NEAR(a[i][k].y, b[i][k].y, tol);
            EXPECT_NEAR(a[i][k].z, b[i][k].z, tol);
        }
    }
}

TEST(TrkFormat, RoundTripKeepsPointsSpaceAndFields) {
    TempDir dir;
    const std::string path = dir.path() + "/x.trk";
    const Fibers fibers = three_fibers();
    SinkHeader h;
    h.space = lps_space();
    h.fibers = 3, h.points = 6;
    h.fields = {float_field("dpv/fa", 1, {.1f, .2f, .3f, .4f, .5f, .6f}),
                float_field("dps/rgb", 3, {1, 2, 3, 4, 5, 6, 7, 8, 9})};
    {
        TrkWriter w(path, h, false);
        write(w, fibers);
    }
    TrkReader r(path);
    EXPECT_EQ(r.header().space.voxel_order, "LPS");
    EXPECT_EQ(r.header().space.dimensions, (std::array<int, 3>{91, 109, 40}));
    EXPECT_EQ(r.header().n_count, 3u);
    for (std::size_t i = 0; i < 16; ++i) EXPECT_EQ(r.header().space.voxel_to_rasmm[i], lps_space().voxel_to_rasmm[i]);
    expect_near(read_all(r), fibers, 2e-5);  // float32 voxmm in between
    const auto fields = r.take_fields();
    ASSERT_EQ(fields.size(), 2u);
    EXPECT_EQ(fields[0].name, "dpv/fa");
    EXPECT_EQ(fields[0].bytes, h.fields[0].bytes);
    EXPECT_EQ(fields[1].name, "dps/rgb");
    EXPECT_EQ(fields[1].components, 3u);
    EXPECT_EQ(fields[1].bytes, h.fields[1].bytes);
    // A second pass reads the same points (compress makes several).
    r.rewind();
    expect_near(read_all(r), fibers, 2e-5);
}

// The bundles' .tck twins were written by nibabel from the .trk's
// load(...).streamlines: the .trk reader must give those floats.
// A property of 20000 values is written "w\020000" (nibabel's encoding,
// int16 counts): fiblet's reader takes back what its writer writes.
TEST(TrkFormat, FiveDigitValueCountsRoundTrip) {
    TempDir dir;
    const std::string path = dir.path() + "/wide.trk";
    SinkHeader h;
    h.fibers = 3, h.points = 6;
    std::vector<float> values(3 * 20000);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = float(i % 977);
    h.fields = {float_field("dps/w", 20000, values)};
    {
        TrkWriter w(path, h, false);
        write(w, three_fibers());
    }
    TrkReader r(path);
    expect_near(read_all(r), three_fibers(), 2e-5);
    const auto fields = r.take_fields();
    ASSERT_EQ(fields.size(), 1u);
    EXPECT_EQ(fields[0].name, "dps/w");
    EXPECT_EQ(fields[0].components, 20000u);
    EXPECT_EQ(fields[0].bytes, h.fields[0].bytes);
}

TEST(TrkFormat, GivesNibabelsCoordinatesOnSharedBundles) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    for (const char* name : {"AF_L", "CC_ForcepsMajor", "CST_R"}) {
        TrkReader trk(test::shared_data(std::string("bundles/") + name + ".trk"));
        TckReader tck(test::shared_data(std::string("bundles/") + name + ".tck"));
        std::vector<Vec3f> a, b;
        std::size_t n = 0;
        while (trk.next(a)) {
            ASSERT_TRUE(tck.next(b));
            ASSERT_EQ(a, b) << name << " streamline " << n;
            ++n;
        }
        EXPECT_FALSE(tck.next(b));
        EXPECT_EQ(n, 50u);
    }
}

TEST(TrkFormat, BigEndianFileReadsAsLittleEndianTwin) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    TrkReader le(test::shared_data("conformance/complex.trk"));
    TrkReader be(test::shared_data("conformance/complex_big_endian.trk"));
    EXPECT_TRUE(be.header().big_endian);
    EXPECT_FALSE(le.header().big_endian);
    const Fibers a = read_all(le), b = read_all(be);
    EXPECT_EQ(a, b);
    const auto fa = le.take_fields(), fb = be.take_fields();
    ASSERT_EQ(fa.size(), 5u);
    ASSERT_EQ(fa.size(), fb.size());
    for (std::size_t i = 0; i < fa.size(); ++i) EXPECT_EQ(fa[i].bytes, fb[i].bytes) << fa[i].name;
}

// A copy of `src` with `bytes` written at `offset` (or cut to `offset` when bytes is empty).
std::string patched(const std::string& src, std::size_t offset, const std::string& bytes, const std::string& out) {
    std::string data = test::read_file(src);
    if (bytes.empty()) data.resize(offset);
    else data.replace(offset, bytes.size(), bytes);
    test::write_file(out, data);
    return out;
}

std::optional<Errc> read_error(const std::string& path) {
    return test::error_of([&] {
        auto s = open_streamline_source(path);
        read_all(*s);
    });
}

TEST(TrkFormat, MalformedFilesAreClearErrors) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    TempDir dir;
    const std::string src = test::shared_data("conformance/simple.trk");
    auto le32 = [](std::int32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    EXPECT_EQ(read_error(patched(src, 500, "", dir.path() + "/header_cut.trk")), Errc::trk_format);
    EXPECT_EQ(read_error(patched(src, 1050, "", dir.path() + "/data_cut.trk")), Errc::trk_format);
    EXPECT_EQ(read_error(patched(src, 996, le32(999), dir.path() + "/hdr_size.trk")), Errc::trk_format);
    EXPECT_EQ(read_error(patched(src, 992, le32(7), dir.path() + "/version.trk")), Errc::unsupported);
    EXPECT_EQ(read_error(patched(src, 988, le32(5), dir.path() + "/count_high.trk")), Errc::trk_format);
    EXPECT_EQ(read_error(patched(src, 988, le32(2), dir.path() + "/count_low.trk")), Errc::trk_format);
    EXPECT_EQ(read_error(patched(src, 1000, le32(-4), dir.path() + "/negative.trk")), Errc::trk_format);
    EXPECT_EQ(read_error(patched(src, 1000, le32(1 << 30), dir.path() + "/huge.trk")), Errc::trk_format);
    // count 0 = not recorded: read to the end.
    auto s = open_streamline_source(patched(src, 988, le32(0), dir.path() + "/count_zero.trk"));
    EXPECT_EQ(read_all(*s).size(), 3u);
}

TEST(TrxFormat, ZipRoundTripKeepsPointsSpaceAndFields) {
    TempDir dir;
    const std::string path = dir.path() + "/x.trx";
    SinkHeader h;
    h.space = lps_space();
    h.fibers = 3, h.points = 6;
    StreamlineField group{"groups/CST", FieldType::uint32, 1, std::vector<std::uint8_t>(8)};
    const std::uint32_t members[2] = {2, 0};
    std::memcpy(group.bytes.data(), members, 8);
    h.fields = {float_field("dpv/fa", 1, {.1f, .2f, .3f, .4f, .5f, .6f}), float_field("dps/w", 1, {7, 8, 9}), group};
    {
        TrxWriter w(path, h, false);
        write(w, three_fibers());
    }
    EXPECT_EQ(detect_tractogram_format(path), TractogramFormat::trx);
    TrxReader r(path);
    EXPECT_EQ(r.streamline_count(), 3u);
    EXPECT_EQ(r.point_count(), 6u);
    EXPECT_EQ(r.space().voxel_to_rasmm, lps_space().voxel_to_rasmm);
    EXPECT_EQ(r.space().voxel_order, "LPS");  // from the affine's axes
    EXPECT_EQ(read_all(r), three_fibers());   // float32 positions: exact
    auto fields = r.take_fields();
    ASSERT_EQ(fields.size(), 3u);
    std::sort(fields.begin(), fields.end(), [](auto& a, auto& b) { return a.name < b.name; });
    EXPECT_EQ(fields[0].name, "dps/w");
    EXPECT_EQ(fields[1].name, "dpv/fa");
    EXPECT_EQ(fields[2].name, "groups/CST");
    EXPECT_EQ(fields[2].bytes, group.bytes);
    EXPECT_EQ(test::error_of([&] { TrxWriter(path, h, false); }), Errc::exists);
}

TEST(TrxFormat, DirectoryWithFloat16AndNoSentinel) {
    TempDir dir;
    const std::string root = dir.path() + "/d.trx";
    std::filesystem::create_directories(root + "/dps");
    test::write_file(root + "/header.json",
                     R"({"VOXEL_TO_RASMM": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "DIMENSIONS": [10, 10, 10],)"
                     R"( "NB_STREAMLINES": 2, "NB_VERTICES": 3})");
    // float16: 1.0 = 0x3c00, 2.0 = 0x4000, -0.5 = 0xb800, 0.25 = 0x3400
    const std::uint16_t pos[9] = {0x3c00, 0x4000, 0xb800, 0x3400, 0, 0x3c00, 0x4000, 0x4000, 0x4000};
    test::write_file(root + "/positions.3.float16", std::string(reinterpret_cast<const char*>(pos), sizeof pos));
    const std::uint32_t off[2] = {0, 1};
    test::write_file(root + "/offsets.uint32", std::string(reinterpret_cast<const char*>(off), sizeof off));
    const std::int16_t label[2] = {-3, 12};
    test::write_file(root + "/dps/label.int16", std::string(reinterpret_cast<const char*>(label), sizeof label));
    TrxReader r(root);
    const Fibers f = read_all(r);
    ASSERT_EQ(f.size(), 2u);
    EXPECT_EQ(f[0], (std::vector<Vec3f>{{1, 2, -0.5f}}));
    EXPECT_EQ(f[1], (std::vector<Vec3f>{{0.25f, 0, 1}, {2, 2, 2}}));
    const auto fields = r.take_fields();
    ASSERT_EQ(fields.size(), 1u);
    EXPECT_EQ(fields[0].type, FieldType::int16);
    EXPECT_EQ(fields[0].at(0, 0), -3);
    // Damage: offsets past NB_VERTICES, a missing header key, a bit array.
    const std::uint32_t bad_off[2] = {0, 4};
    test::write_file(root + "/offsets.uint32", std::string(reinterpret_cast<const char*>(bad_off), sizeof bad_off));
    EXPECT_EQ(read_error(root), Errc::trx_format);
    test::write_file(root + "/offsets.uint32", std::string(reinterpret_cast<const char*>(off), sizeof off));
    test::write_file(root + "/dps/flag.bit", "\x01");
    EXPECT_EQ(read_error(root), Errc::unsupported);
    std::filesystem::remove(root + "/dps/flag.bit");
    test::write_file(root + "/header.json", R"({"DIMENSIONS": [1, 1, 1], "NB_STREAMLINES": 2, "NB_VERTICES": 3})");
    EXPECT_EQ(read_error(root), Errc::trx_format);
}

TEST(StreamlineFormats, RecognisedButUnsupportedAndUnknown) {
    TempDir dir;
    test::write_file(dir.path() + "/a.vtk", "# vtk DataFile Version 3.0\n");
    test::write_file(dir.path() + "/b.tck.gz", std::string("\x1f\x8b\x08\0\0\0\0\0", 8));
    test::write_file(dir.path() + "/c.bin", "hello, not a tractogram");
    test::write_file(dir.path() + "/d.zip", std::string("PK\x03\x04", 4) + std::string(40, '\0'));
    EXPECT_EQ(read_error(dir.path() + "/a.vtk"), Errc::unsupported);
    EXPECT_EQ(read_error(dir.path() + "/b.tck.gz"), Errc::unsupported);
    EXPECT_EQ(read_error(dir.path() + "/c.bin"), Errc::invalid_input);
    EXPECT_EQ(read_error(dir.path() + "/d.zip"), Errc::trx_format);  // a damaged zip: read as TRX, malformed
    // A .trk opened as a .fft is named, not parsed as a .fft version 84.
    if (test::shared_data_available()) {
        try {
            FftFile f(test::shared_data("conformance/simple.trk"));
            FAIL() << "opened a .trk as a .fft";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), Errc::unsupported);
            EXPECT_NE(std::string(e.what()).find("TrackVis .trk"), std::string::npos) << e.what();
        }
    }
}

TEST(ResamplePointValues, LinearAlongEachSegment) {
    // A value equal to x along a polyline of uneven segments: interpolation
    // at the resampled points must give their x (a linear function stays exact).
    const std::vector<Vec3f> in{{0, 0, 0}, {0.3f, 0, 0}, {0.3f, 0.7f, 0}, {1.5f, 0.7f, 0}, {1.5f, 0.7f, 2}};
    std::vector<float> x;
    for (const Vec3f& p : in) x.push_back(p.x + 10 * p.z);
    std::vector<Vec3f> out;
    std::vector<PolylinePosition> pos;
    resample_keeping_end(in, 0.25, out, ResampleCurve::polyline, &pos);
    ASSERT_EQ(out.size(), pos.size());
    std::vector<float> v(out.size());
    interpolate_point_values(pos, x.data(), 1, v.data());
    for (std::size_t k = 0; k < out.size(); ++k) EXPECT_NEAR(v[k], out[k].x + 10 * out[k].z, 1e-5) << k;
    EXPECT_FLOAT_EQ(v.back(), x.back());
}

TEST(StreamlineDataChunk, ValidationRejectsInconsistentFields) {
    const std::vector<StreamlineField> good{float_field("dps/w", 1, {1, 2}), float_field("dpv/fa", 2, {1, 2, 3, 4, 5, 6})};
    const TrailerChunk c = make_streamline_data_chunk(good);
    const auto back = parse_streamline_data_chunk(c, 2, 3, "x.fft");
    ASSERT_EQ(back.size(), 2u);
    EXPECT_EQ(back[1].bytes, good[1].bytes);
    auto bad = [&](std::uint64_t fibers, std::uint64_t points, const TrailerChunk& chunk) {
        return test::error_of([&] { parse_streamline_data_chunk(chunk, fibers, points, "x.fft"); });
    };
    EXPECT_EQ(bad(3, 3, c), Errc::fft_format);  // dps rows != fibers
    EXPECT_EQ(bad(2, 4, c), Errc::fft_format);  // dpv rows != points
    TrailerChunk cut = c;
    cut.payload.resize(cut.payload.size() - 1);
    EXPECT_EQ(bad(2, 3, cut), Errc::fft_format);
    EXPECT_EQ(bad(2, 3, make_streamline_data_chunk({good[0], good[0]})), Errc::fft_format);  // twice
    StreamlineField group{"groups/g", FieldType::uint32, 1, std::vector<std::uint8_t>(4)};
    group.bytes[0] = 2;  // streamline 2 of 2
    EXPECT_EQ(bad(2, 3, make_streamline_data_chunk({group})), Errc::fft_format);
    EXPECT_EQ(bad(2, 3, make_streamline_data_chunk({float_field("other/x", 1, {1, 2})})), Errc::fft_format);
}

// A .trk's scalars and properties go through a .fft unchanged (no
// resampling: a fixed step), the space comes back, and the DATA chunk is
// covered by the checksums.
TEST(TrkThroughFft, DataAndSpaceKeptAndChecksummed) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    TempDir dir;
    const std::string src = test::shared_data("conformance/complex_big_endian.trk");
    const std::string fft = dir.path() + "/c.fft";
    CompressOptions o;
    o.threads = 1;
    const CompressReport rep = compress_file(src, fft, o);
    EXPECT_FALSE(rep.resampled);
    TrkReader in(src);
    read_all(in);
    const auto expected = in.take_fields();
    {
        FftFile f(fft);
        ASSERT_EQ(f.streamline_fields().size(), expected.size());
        for (std::size_t i = 0; i < expected.size(); ++i) {
            EXPECT_EQ(f.streamline_fields()[i].name, expected[i].name);
            EXPECT_EQ(f.streamline_fields()[i].bytes, expected[i].bytes);
        }
        const auto space = space_from_properties(f.properties(), fft);
        ASSERT_TRUE(space);
        EXPECT_EQ(space->voxel_to_rasmm, in.header().space.voxel_to_rasmm);
        EXPECT_EQ(space->voxel_order, in.header().space.voxel_order);
    }
    // One byte of the DATA chunk's values flipped: the checksum catches it.
    std::string bytes = test::read_file(fft);
    const auto at = bytes.find("dpv/fa");
    ASSERT_NE(at, std::string::npos);
    bytes[at + 6 + 16 + 1] ^= 0x40;
    test::write_file(dir.path() + "/d.fft", bytes);
    EXPECT_EQ(test::error_of([&] { FftFile f(dir.path() + "/d.fft"); }), Errc::checksum);
}

}  // namespace
}  // namespace fiblet
