// Tests of the .tck header parser and the streaming reader: shared real and
// conformance files, and hand-made files covering every data-section rule.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using test::shared_data;
using test::TempDir;
using Streamlines = std::vector<std::vector<Vec3f>>;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

#define SKIP_WITHOUT_SHARED_DATA() \
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared test data at " << test::shared_data_dir()

// Raw encoders for hand-made data sections.
template <class T, class U>
void put(std::string& out, T v, bool big_endian) {
    U u;
    std::memcpy(&u, &v, sizeof u);
    char b[sizeof u];
    std::memcpy(b, &u, sizeof u);
    if (big_endian) std::reverse(b, b + sizeof u);
    out.append(b, sizeof u);
}

std::string f32(std::initializer_list<float> values, bool big_endian = false) {
    std::string s;
    for (float v : values) put<float, std::uint32_t>(s, v, big_endian);
    return s;
}

std::string f64(std::initializer_list<double> values, bool big_endian = false) {
    std::string s;
    for (double v : values) put<double, std::uint64_t>(s, v, big_endian);
    return s;
}

int digits(std::uint64_t v) { return int(std::to_string(v).size()); }

// A complete .tck file: header lines `extra`, the datatype, and `data` right after END.
std::string make_tck(const std::string& data, const std::string& datatype = "Float32LE",
                     const std::string& extra = "") {
    const std::string head = "mrtrix tracks\n" + extra + "datatype: " + datatype + "\nfile: . ";
    const std::size_t fixed = head.size() + 5;  // + "\nEND\n"
    std::size_t offset = 0;
    for (int d = 1; d < 20 && !offset; ++d)
        if (digits(fixed + d) == d) offset = fixed + d;
    return head + std::to_string(offset) + "\nEND\n" + data;
}

Streamlines read_all(const std::string& path, TckReadOptions options = {}) {
    TckReader r(path, options);
    Streamlines out;
    std::vector<Vec3f> pts;
    while (r.next(pts)) out.push_back(pts);
    EXPECT_EQ(r.streamlines_read(), out.size());
    return out;
}

// Order-sensitive hash of all coordinates' bits and of the streamline boundaries.
std::uint64_t hash_points(TckReader& r) {
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](std::uint64_t v) { h = (h ^ v) * 1099511628211ull; };
    std::vector<Vec3f> pts;
    while (r.next(pts)) {
        mix(pts.size());
        for (const Vec3f& p : pts)
            mix(std::bit_cast<std::uint32_t>(p.x)), mix(std::bit_cast<std::uint32_t>(p.y)),
                mix(std::bit_cast<std::uint32_t>(p.z));
    }
    return h;
}

// Runs `f`, expects a fiblet::Error of category `code` whose message contains every word of `words`.
template <class F>
void expect_error(F&& f, Errc code, std::initializer_list<std::string> words) {
    try {
        f();
        ADD_FAILURE() << "no error thrown, expected " << errc_name(code);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), code) << e.what();
        for (const auto& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
    }
}

// ---- Shared files: counts from shared/data/README.md ----

struct SharedFile {
    const char* path;
    std::uint64_t streamlines, points;
};

const SharedFile kSharedFiles[] = {
    {"small-ifod1-step0.05.tck", 1000, 1859567},
    {"small-ifod1.tck", 2000, 1844852},
    {"small-ifod2.tck", 3000, 550835},
    {"small-sdstream.tck", 1000, 853199},
    {"dwi-small64d-ifod1.tck", 500, 38593},
    {"bundles/AF_L-step0.1.tck", 50, 60492},
    {"bundles/AF_L.tck", 50, 1000},
    {"bundles/CC_ForcepsMajor-step0.1.tck", 50, 80727},
    {"bundles/CC_ForcepsMajor.tck", 50, 1000},
    {"bundles/CST_R-step0.1.tck", 50, 68781},
    {"bundles/CST_R.tck", 50, 1000},
    {"bundles/cingulum-1-step0.1.tck", 116, 75851},
    {"bundles/cingulum-1.tck", 116, 2088},
    {"bundles/cingulum-2-step0.1.tck", 113, 78681},
    {"bundles/cingulum-2.tck", 113, 2034},
    {"conformance/empty.tck", 0, 0},
    {"conformance/multiline_header_field.tck", 1, 253},
    {"conformance/simple.tck", 3, 8},
    {"conformance/simple_big_endian.tck", 3, 8},
    {"conformance/standard.tck", 120, 360},
};

TEST(TckReaderShared, CountsMatchReadmeTable) {
    SKIP_WITHOUT_SHARED_DATA();
    for (const auto& f : kSharedFiles) {
        SCOPED_TRACE(f.path);
        TckReader r(shared_data(f.path));
        std::vector<Vec3f> pts;
        std::uint64_t n = 0, p = 0, last_consumed = 0;
        while (r.next(pts)) {
            ++n, p += pts.size();
            for (const Vec3f& q : pts) ASSERT_TRUE(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z));
            EXPECT_GE(r.bytes_consumed(), last_consumed);
            last_consumed = r.bytes_consumed();
        }
        EXPECT_EQ(n, f.streamlines);
        EXPECT_EQ(p, f.points);
        EXPECT_EQ(r.streamlines_read(), f.streamlines);
        EXPECT_EQ(r.points_read(), f.points);
        ASSERT_TRUE(r.header().count().has_value());
        EXPECT_EQ(*r.header().count(), f.streamlines);
        // Each streamline is followed by a NaN triplet, and the data by one Inf triplet, then EOF.
        const std::uint64_t triplets = f.points + f.streamlines + 1;
        EXPECT_EQ(r.data_bytes(), triplets * 12);
        EXPECT_EQ(r.bytes_consumed(), r.data_bytes());
        EXPECT_FALSE(r.next(pts));  // stays at the end
        EXPECT_TRUE(pts.empty());
    }
}

TEST(TckReaderShared, SimpleTckPoints) {
    SKIP_WITHOUT_SHARED_DATA();
    const Streamlines s = read_all(shared_data("conformance/simple.tck"));
    // nibabel's simple.trk/tck: streamlines of 1, 2 and 5 points counting up from (0, 1, 2).
    ASSERT_EQ(s.size(), 3u);
    const std::size_t sizes[] = {1, 2, 5};
    for (std::size_t i = 0; i < 3; ++i) {
        ASSERT_EQ(s[i].size(), sizes[i]);
        for (std::size_t j = 0; j < sizes[i]; ++j)
            EXPECT_EQ(s[i][j], (Vec3f{3.0f * j, 3.0f * j + 1, 3.0f * j + 2})) << i << " " << j;
    }
    EXPECT_EQ(read_all(shared_data("conformance/simple_big_endian.tck")), s);
    EXPECT_EQ(TckReader(shared_data("conformance/simple_big_endian.tck")).header().datatype, TckDataType::float32be);
}

TEST(TckReaderShared, StandardTckBoundingBox) {
    SKIP_WITHOUT_SHARED_DATA();
    const Streamlines s = read_all(shared_data("conformance/standard.tck"));
    Vec3f lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
    for (const auto& sl : s) {
        EXPECT_EQ(sl.size(), 3u);
        for (const Vec3f& p : sl) {
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
    }
    EXPECT_EQ(lo, (Vec3f{-0.5f, -1.5f, -1.0f}));
    EXPECT_EQ(hi, (Vec3f{3.5f, 13.5f, 13.0f}));
}

TEST(TckReaderShared, MrtrixHeaderProperties) {
    SKIP_WITHOUT_SHARED_DATA();
    const TckHeader h = read_tck_header(shared_data("small-ifod1.tck"));
    EXPECT_EQ(h.datatype, TckDataType::float32le);
    EXPECT_EQ(h.data_offset, 656u);
    EXPECT_EQ(h.count(), 2000u);
    ASSERT_TRUE(h.step_size().has_value());
    EXPECT_DOUBLE_EQ(*h.step_size(), 0.1);
    EXPECT_EQ(h.get("total_count"), "2007");
    EXPECT_EQ(h.get("method"), "iFOD1");
    EXPECT_EQ(h.get("roi"), "seed phantom-mask.nii");
    ASSERT_FALSE(h.properties.empty());
    EXPECT_EQ(h.properties.front().first, "command_history");  // file order is kept
    EXPECT_EQ(h.properties.front().second.rfind("tckgen -force", 0), 0u);
    EXPECT_FALSE(h.get("file").has_value());
    EXPECT_FALSE(h.get("datatype").has_value());
    EXPECT_FALSE(h.get("mrtrix tracks").has_value());
}

TEST(TckReaderShared, MultilineHeaderField) {
    SKIP_WITHOUT_SHARED_DATA();
    TckReader r(shared_data("conformance/multiline_header_field.tck"));
    const auto ch = r.header().get("command_history");
    ASSERT_TRUE(ch.has_value());
    EXPECT_EQ(ch->rfind("tckgen -angle 22.5", 0), 0u);
    EXPECT_NE(ch->find("(version=3Tissue_v5.2.8)\ntckedit ZAPR01-FOD-Template-AmygdalaTargetMask"), std::string::npos)
        << *ch;
    EXPECT_EQ(r.header().get("downsample_factor"), "3");  // the entry after the continuation line
    EXPECT_EQ(r.header().data_offset, 1351u);
    std::vector<Vec3f> pts;
    ASSERT_TRUE(r.next(pts));
    EXPECT_EQ(pts.size(), 253u);
    EXPECT_FALSE(r.next(pts));
}

TEST(TckReaderShared, InvalidConformanceFilesRejected) {
    SKIP_WITHOUT_SHARED_DATA();
    for (const char* name : {"no_header_end.tck", "no_header_end_eof.tck"}) {
        const std::string p = shared_data(std::string("conformance/") + name);
        expect_error([&] { read_tck_header(p); }, Errc::tck_format, {name, "END"});
        expect_error([&] { TckReader r(p); }, Errc::tck_format, {name});
    }
    const std::string p = shared_data("conformance/no_magic_number.tck");
    expect_error([&] { TckReader r(p); }, Errc::tck_format, {"no_magic_number.tck", "mrtrix tracks"});
}

TEST(TckReaderShared, MatlabNanCountMismatch) {
    SKIP_WITHOUT_SHARED_DATA();
    const std::string p = shared_data("conformance/matlab_nan.tck");
    expect_error([&] { read_all(p); }, Errc::tck_format, {"615000", "1 streamlines"});
    try {
        read_all(p);
    } catch (const Error& e) {
        EXPECT_EQ(e.remedy(), Remedy::allow_count_mismatch);  // what reads it anyway (below)
    }
    TckReadOptions o;
    o.allow_count_mismatch = true;
    const Streamlines s = read_all(p, o);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].size(), 108u);
    EXPECT_EQ(TckReader(p).header().get("method"), "DT_STREAM");
}

TEST(TckReaderShared, ChunkSizeDoesNotChangeResult) {
    SKIP_WITHOUT_SHARED_DATA();
    for (const char* name : {"bundles/AF_L.tck", "conformance/simple_big_endian.tck", "conformance/empty.tck"}) {
        SCOPED_TRACE(name);
        TckReader ref(shared_data(name));
        const std::uint64_t h = hash_points(ref);
        for (std::size_t chunk : {0, 1, 12, 13, 25, 100, 4096}) {
            TckReadOptions o;
            o.chunk_bytes = chunk;
            TckReader r(shared_data(name), o);
            EXPECT_EQ(hash_points(r), h) << "chunk " << chunk;
            EXPECT_EQ(r.streamlines_read(), ref.streamlines_read());
            EXPECT_EQ(r.points_read(), ref.points_read());
        }
    }
    TckReadOptions o;
    o.chunk_bytes = 65537;
    TckReader big(shared_data("small-ifod2.tck")), small(shared_data("small-ifod2.tck"), o);
    EXPECT_EQ(hash_points(big), hash_points(small));
    EXPECT_EQ(small.points_read(), 550835u);
}

TEST(TckReaderShared, RewindRestartsFromFirstStreamline) {
    SKIP_WITHOUT_SHARED_DATA();
    TckReadOptions o;
    o.chunk_bytes = 1000;
    TckReader r(shared_data("dwi-small64d-ifod1.tck"), o);
    std::vector<Vec3f> first, pts;
    ASSERT_TRUE(r.next(first));
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(r.next(pts));
    EXPECT_GT(r.bytes_consumed(), 0u);
    r.rewind();
    EXPECT_EQ(r.streamlines_read(), 0u);
    EXPECT_EQ(r.points_read(), 0u);
    EXPECT_EQ(r.bytes_consumed(), 0u);
    ASSERT_TRUE(r.next(pts));
    EXPECT_EQ(pts, first);
    r.rewind();
    const std::uint64_t h1 = hash_points(r);
    EXPECT_EQ(r.streamlines_read(), 500u);
    r.rewind();  // also after reaching the end
    EXPECT_EQ(hash_points(r), h1);
    EXPECT_EQ(r.points_read(), 38593u);
}

// ---- Header parsing on hand-made files ----

TEST(TckHeader, Accessors) {
    TckHeader h;
    h.properties = {{"command_history", "a"}, {"count", "0000000042"}, {"command_history", "b"}, {"x", "1"}};
    EXPECT_EQ(h.get("command_history"), "a");
    EXPECT_FALSE(h.get("missing").has_value());
    EXPECT_EQ(h.count(), 42u);
    h.set("command_history", "c");  // replaces both, keeps the first position
    ASSERT_EQ(h.properties.size(), 3u);
    EXPECT_EQ(h.properties[0], (std::pair<std::string, std::string>{"command_history", "c"}));
    h.set("new", "v");
    EXPECT_EQ(h.properties.back().first, "new");
    h.erase("x");
    EXPECT_FALSE(h.get("x").has_value());
    EXPECT_EQ(h.properties.size(), 3u);

    for (const char* bad : {"", "abc", "-1", "12x", "1.5", "99999999999999999999999"}) {
        h.set("count", bad);
        EXPECT_FALSE(h.count().has_value()) << bad;
    }
    h.erase("count");
    EXPECT_FALSE(h.count().has_value());

    EXPECT_FALSE(h.step_size().has_value());
    h.set("step_size", "0.5");
    EXPECT_EQ(h.step_size(), 0.5);
    for (const char* bad : {"0", "-0.1", "nan", "inf", "x", "0.1mm", ""}) {
        h.set("step_size", bad);
        EXPECT_FALSE(h.step_size().has_value()) << bad;
    }
}

TEST(TckHeader, DatatypeNamesAndSizes) {
    EXPECT_STREQ(tck_datatype_name(TckDataType::float32le), "Float32LE");
    EXPECT_STREQ(tck_datatype_name(TckDataType::float32be), "Float32BE");
    EXPECT_STREQ(tck_datatype_name(TckDataType::float64le), "Float64LE");
    EXPECT_STREQ(tck_datatype_name(TckDataType::float64be), "Float64BE");
    EXPECT_EQ(tck_datatype_size(TckDataType::float32be), 4);
    EXPECT_EQ(tck_datatype_size(TckDataType::float64le), 8);
}

TEST(TckHeader, ContinuationRepeatsAndWhitespace) {
    TempDir d;
    const std::string p = d.file("h.tck");
    // Trailing spaces after the magic, CRLF lines, a continued value and a repeated key.
    const std::string data = f32({kInf, kInf, kInf});
    std::string text = "mrtrix tracks   \r\ncommand_history: first\r\n  continued here\ncount: 0\n"
                       "command_history: second\n  key with spaces  :  v : w  \nfile: . 1000\n"
                       "datatype: float32le\nEND\n";
    text.resize(1000, '\0');
    test::write_file(p, text + data);
    const TckHeader h = read_tck_header(p);
    ASSERT_EQ(h.properties.size(), 4u);
    EXPECT_EQ(h.properties[0], (std::pair<std::string, std::string>{"command_history", "first\ncontinued here"}));
    EXPECT_EQ(h.properties[1].first, "count");
    EXPECT_EQ(h.properties[2], (std::pair<std::string, std::string>{"command_history", "second"}));
    EXPECT_EQ(h.properties[3], (std::pair<std::string, std::string>{"key with spaces", "v : w"}));
    EXPECT_EQ(h.data_offset, 1000u);
    EXPECT_EQ(h.datatype, TckDataType::float32le);
    EXPECT_TRUE(read_all(p).empty());
}

TEST(TckHeader, MalformedHeadersRejected) {
    TempDir d;
    const std::string p = d.file("bad.tck");
    const std::string inf = f32({kInf, kInf, kInf});
    auto expect_bad = [&](const std::string& bytes, Errc code, std::initializer_list<std::string> words) {
        test::write_file(p, bytes);
        expect_error([&] { read_tck_header(p); }, code, words);
        expect_error([&] { TckReader r(p); }, code, words);
    };
    expect_bad("mrtrix track\nfile: . 30\nEND\n", Errc::tck_format, {"bad.tck", "mrtrix tracks"});
    expect_bad("", Errc::tck_format, {"mrtrix tracks"});
    expect_bad("mrtrix tracks extra\nfile: . 40\nEND\n", Errc::tck_format, {"mrtrix tracks"});
    expect_bad("mrtrix tracks\ndatatype: Float32LE\nEND\n" + inf, Errc::tck_format, {"file"});
    expect_bad("mrtrix tracks\nfile: 40\nEND\n" + inf, Errc::tck_format, {"file"});
    expect_bad("mrtrix tracks\nfile: data.dat 40\nEND\n" + inf, Errc::tck_format, {"file"});
    expect_bad("mrtrix tracks\nfile: . forty\nEND\n" + inf, Errc::tck_format, {"file"});
    expect_bad("mrtrix tracks\nfile: . -4\nEND\n" + inf, Errc::tck_format, {"file"});
    expect_bad("mrtrix tracks\nfile: . 10\nEND\n" + inf, Errc::tck_format, {"offset 10", "inside the header"});
    expect_bad("mrtrix tracks\nfile: . 5000\nEND\n" + inf, Errc::tck_format, {"offset 5000", "past the end"});
    expect_bad("mrtrix tracks\nfile: . 30\n" + inf, Errc::tck_format, {"END"});
    expect_bad("mrtrix tracks\nno colon first\nfile: . 50\nEND\n" + inf, Errc::tck_format, {"line 2"});
    expect_bad(make_tck(inf, "Int16LE"), Errc::unsupported, {"Int16LE"});
    expect_bad(make_tck(inf, "Float32"), Errc::unsupported, {"Float32"});
    expect_error([&] { read_tck_header(d.file("missing.tck")); }, Errc::io, {"missing.tck"});
    expect_error([&] { TckReader r(d.file("missing.tck")); }, Errc::io, {"missing.tck"});
}

TEST(TckHeader, HeaderSizeIsCapped) {
    TempDir d;
    const std::string p = d.file("huge.tck");
    // 20 MiB of header lines without END: must stop at the cap, not read to the end.
    std::string text = "mrtrix tracks\n";
    const std::string line = "key: value value value value value value value value value value value\n";
    while (text.size() < (20u << 20)) text += line;
    test::write_file(p, text);
    expect_error([&] { read_tck_header(p); }, Errc::tck_format, {"MiB"});
    // Same without any newline after the magic.
    test::write_file(p, "mrtrix tracks\n" + std::string(20u << 20, 'x'));
    expect_error([&] { read_tck_header(p); }, Errc::tck_format, {"MiB"});
}

// ---- Data section rules on hand-made files ----

class TckReaderData : public ::testing::Test {
protected:
    TempDir dir;
    std::string path = dir.file("t.tck");

    Streamlines read(const std::string& data, const std::string& datatype = "Float32LE",
                     const std::string& extra = "", TckReadOptions o = {}) {
        test::write_file(path, make_tck(data, datatype, extra));
        return read_all(path, o);
    }
    void expect_bad(const std::string& data, std::initializer_list<std::string> words,
                    const std::string& datatype = "Float32LE") {
        test::write_file(path, make_tck(data, datatype));
        for (std::size_t chunk : {std::size_t(4) << 20, std::size_t(12), std::size_t(36)}) {
            TckReadOptions o;
            o.chunk_bytes = chunk;
            expect_error([&] { read_all(path, o); }, Errc::tck_format, words);
        }
    }
};

TEST_F(TckReaderData, Float32LittleEndianValues) {
    const Streamlines s = read(f32({1.5f, -2.25f, 3e-8f, 4, 5, 6, kNaN, kNaN, kNaN, -7, 8, 9.125f, kNaN, kNaN, kNaN,
                                    kInf, kInf, kInf}));
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[0], (std::vector<Vec3f>{{1.5f, -2.25f, 3e-8f}, {4, 5, 6}}));
    EXPECT_EQ(s[1], (std::vector<Vec3f>{{-7, 8, 9.125f}}));  // single-point fiber
}

TEST_F(TckReaderData, Float32BigEndianValues) {
    const Streamlines s = read(f32({1.5f, -2.25f, 1e30f, kNaN, kNaN, kNaN, kInf, kInf, kInf}, true), "Float32BE");
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0], (std::vector<Vec3f>{{1.5f, -2.25f, 1e30f}}));
}

TEST_F(TckReaderData, Float64ConvertedToFloat32) {
    const double n = std::numeric_limits<double>::quiet_NaN(), i = std::numeric_limits<double>::infinity();
    for (bool be : {false, true}) {
        SCOPED_TRACE(be ? "Float64BE" : "Float64LE");
        const Streamlines s =
            read(f64({0.1, -0.2, 1e-3, 10, 20, 30, n, n, n, 1.0 / 3, 2, 3, n, n, n, i, i, i}, be),
                 be ? "Float64BE" : "Float64LE");
        ASSERT_EQ(s.size(), 2u);
        EXPECT_EQ(s[0], (std::vector<Vec3f>{{0.1f, -0.2f, 1e-3f}, {10, 20, 30}}));
        EXPECT_EQ(s[1], (std::vector<Vec3f>{{float(1.0 / 3), 2, 3}}));
        TckReader r(path);
        EXPECT_EQ(r.header().datatype, be ? TckDataType::float64be : TckDataType::float64le);
        EXPECT_EQ(r.data_bytes(), 18u * 8);
    }
    // A finite double beyond the float32 range cannot be read as float32.
    test::write_file(path, make_tck(f64({1e300, 0, 0, n, n, n, i, i, i}), "Float64LE"));
    expect_error([&] { read_all(path); }, Errc::invalid_input, {"float32"});
}

TEST_F(TckReaderData, EmptyDataSectionAndEndMarkerOnly) {
    EXPECT_TRUE(read("").empty());
    EXPECT_TRUE(read(f32({kInf, kInf, kInf})).empty());
    EXPECT_TRUE(read(f32({-kInf, -kInf, -kInf}) + "garbage after the end").empty());
    EXPECT_TRUE(read("", "Float64BE").empty());
    TckReader r(path);
    EXPECT_EQ(r.data_bytes(), 0u);
}

TEST_F(TckReaderData, EmptyStreamlinesAreKept) {
    // Every NaN triplet closes one streamline, even with no points before it.
    Streamlines s = read(f32({1, 2, 3, 4, 5, 6, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kInf, kInf, kInf}));
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[0].size(), 2u);
    EXPECT_TRUE(s[1].empty());
    s = read(f32({kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kInf, kInf, kInf}));
    ASSERT_EQ(s.size(), 2u);
    EXPECT_TRUE(s[0].empty() && s[1].empty());
}

TEST_F(TckReaderData, LastStreamlineClosedByEndMarker) {
    const Streamlines s = read(f32({1, 2, 3, kNaN, kNaN, kNaN, 4, 5, 6, 7, 8, 9, kInf, kInf, kInf, 1, 1}));
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[1], (std::vector<Vec3f>{{4, 5, 6}, {7, 8, 9}}));
}

TEST_F(TckReaderData, NegativeNaNSeparatorAndNegativeInfEnd) {
    // matlab_nan.tck style: sign bit set on both markers.
    const Streamlines s = read(f32({1, 2, 3, -kNaN, -kNaN, -kNaN, -kInf, -kInf, -kInf}));
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].size(), 1u);
}

TEST_F(TckReaderData, DataAfterEndMarkerIgnored) {
    const Streamlines s = read(f32({1, 2, 3, kNaN, kNaN, kNaN, kInf, kInf, kInf, 4, 5, 6, kNaN, kNaN, kNaN}) + "xy");
    ASSERT_EQ(s.size(), 1u);
    TckReader r(path);
    std::vector<Vec3f> pts;
    while (r.next(pts)) {
    }
    EXPECT_EQ(r.bytes_consumed(), 36u);
    EXPECT_EQ(r.data_bytes(), 60u + 2u);
}

TEST_F(TckReaderData, TruncatedMidPoint) {
    const std::string full = f32({1, 2, 3, kNaN, kNaN, kNaN, 4, 5, 6, kNaN, kNaN, kNaN, kInf, kInf, kInf});
    expect_bad(full.substr(0, 24 + 5), {"t.tck", "truncated in the middle of a point"});
    expect_bad(full.substr(0, 1), {"truncated in the middle of a point"});
    expect_bad(full.substr(0, full.size() - 1), {"truncated in the middle of a point"});
    expect_bad(f64({1, 2, 3}).substr(0, 20), {"truncated in the middle of a point"}, "Float64LE");
}

TEST_F(TckReaderData, MissingEndMarker) {
    expect_bad(f32({1, 2, 3, kNaN, kNaN, kNaN}), {"t.tck", "no end-of-data marker", "truncated?"});
    expect_bad(f32({1, 2, 3, kNaN, kNaN, kNaN, 4, 5, 6}), {"no end-of-data marker"});
    expect_bad(f32({1, 2, 3}, true), {"no end-of-data marker"}, "Float32BE");
}

TEST_F(TckReaderData, NaNOrInfInsideACoordinate) {
    const std::string end = f32({kNaN, kNaN, kNaN, kInf, kInf, kInf});
    const std::string first = f32({0, 0, 0, kNaN, kNaN, kNaN});  // so the bad one is streamline 1 (0-based)
    expect_bad(first + f32({1, kNaN, 3}) + end, {"NaN/Inf inside a coordinate at streamline 1 (0-based)"});
    expect_bad(first + f32({kNaN, 2, 3}) + end, {"NaN/Inf inside a coordinate at streamline 1 (0-based)"});
    expect_bad(first + f32({kNaN, kNaN, 3}) + end, {"NaN/Inf inside a coordinate"});
    expect_bad(first + f32({1, 2, kInf}) + end, {"NaN/Inf inside a coordinate"});
    expect_bad(first + f32({kInf, kInf, 3}) + end, {"NaN/Inf inside a coordinate"});
    expect_bad(first + f32({kInf, kNaN, kInf}) + end, {"NaN/Inf inside a coordinate"});
    const double n = std::numeric_limits<double>::quiet_NaN();
    expect_bad(f64({1, n, 3, n, n, n}, true), {"NaN/Inf inside a coordinate at streamline 0 (0-based)"}, "Float64BE");
}

TEST_F(TckReaderData, CountMismatch) {
    const std::string data = f32({1, 2, 3, kNaN, kNaN, kNaN, 4, 5, 6, kNaN, kNaN, kNaN, kInf, kInf, kInf});
    EXPECT_EQ(read(data, "Float32LE", "count: 0000000002\n").size(), 2u);
    test::write_file(path, make_tck(data, "Float32LE", "count: 3\n"));
    expect_error([&] { read_all(path); }, Errc::tck_format, {"t.tck", "count: 3", "2 streamlines"});
    // The option that reads it anyway, for each front end to name (the library's message does not).
    try {
        read_all(path);
    } catch (const Error& e) {
        EXPECT_EQ(e.remedy(), Remedy::allow_count_mismatch);
        EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
    }
    TckReadOptions o;
    o.allow_count_mismatch = true;
    EXPECT_EQ(read(data, "Float32LE", "count: 3\n", o).size(), 2u);
    // No count, or an unparsable one, cannot disagree.
    EXPECT_EQ(read(data).size(), 2u);
    EXPECT_EQ(read(data, "Float32LE", "count: unknown\n").size(), 2u);
    // An empty data section against a non-zero count.
    test::write_file(path, make_tck("", "Float32LE", "count: 1\n"));
    expect_error([&] { read_all(path); }, Errc::tck_format, {"count: 1", "0 streamlines"});
}

TEST_F(TckReaderData, ProgressCounters) {
    const std::string data = f32({1, 2, 3, 4, 5, 6, kNaN, kNaN, kNaN, 7, 8, 9, kNaN, kNaN, kNaN, kInf, kInf, kInf});
    test::write_file(path, make_tck(data));
    TckReadOptions o;
    o.chunk_bytes = 24;
    TckReader r(path, o);
    EXPECT_EQ(r.data_bytes(), data.size());
    EXPECT_EQ(r.bytes_consumed(), 0u);
    std::vector<Vec3f> pts;
    ASSERT_TRUE(r.next(pts));
    EXPECT_EQ(r.bytes_consumed(), 36u);
    EXPECT_EQ(r.points_read(), 2u);
    ASSERT_TRUE(r.next(pts));
    EXPECT_EQ(r.bytes_consumed(), 60u);
    EXPECT_EQ(r.points_read(), 3u);
    EXPECT_FALSE(r.next(pts));
    EXPECT_EQ(r.bytes_consumed(), 72u);
    EXPECT_EQ(r.streamlines_read(), 2u);
}

TEST_F(TckReaderData, MovedReaderKeepsState) {
    test::write_file(path, make_tck(f32({1, 2, 3, kNaN, kNaN, kNaN, 4, 5, 6, kNaN, kNaN, kNaN, kInf, kInf, kInf})));
    TckReader a(path);
    std::vector<Vec3f> pts;
    ASSERT_TRUE(a.next(pts));
    TckReader b(std::move(a));
    ASSERT_TRUE(b.next(pts));
    EXPECT_EQ(pts, (std::vector<Vec3f>{{4, 5, 6}}));
    EXPECT_EQ(b.path(), path);
    EXPECT_FALSE(b.next(pts));
}

}  // namespace
}  // namespace fiblet
