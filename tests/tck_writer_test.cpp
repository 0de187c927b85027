// Tests of the .tck writer: round trips through TckReader, header layout, atomic
// output, and interoperability with nibabel and MRtrix3 when they are installed.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using test::CommandResult;
using test::run_command;
using test::TempDir;
using Streamlines = std::vector<std::vector<Vec3f>>;
using Properties = std::vector<std::pair<std::string, std::string>>;

// Random streamlines of varied lengths (including empty and single-point ones) and values.
Streamlines random_streamlines(std::size_t n, unsigned seed, bool allow_empty = true) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> coord(-120.0f, 120.0f);
    std::uniform_int_distribution<int> len(allow_empty ? 0 : 1, 300);
    Streamlines s(n);
    for (std::size_t i = 0; i < n; ++i) {
        s[i].resize(i % 7 == 3 ? 1 : std::size_t(len(rng)));
        for (Vec3f& p : s[i]) p = {coord(rng), coord(rng), coord(rng)};
    }
    // Values that must survive bit for bit.
    if (!s.empty() && !s[0].empty()) s[0][0] = {-0.0f, 1e-40f, FLT_MAX};
    return s;
}

Streamlines read_all(const std::string& path) {
    TckReader r(path);
    Streamlines out;
    std::vector<Vec3f> pts;
    while (r.next(pts)) out.push_back(pts);
    return out;
}

bool same_bits(const Streamlines& a, const Streamlines& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].size() != b[i].size() || (!a[i].empty() && std::memcmp(a[i].data(), b[i].data(), 12 * a[i].size())))
            return false;
    return true;
}

void write_tck(const std::string& path, const Streamlines& s, const Properties& props = {}, bool overwrite = false) {
    TckWriter w(path, props, overwrite);
    for (const auto& sl : s) w.write(sl);
    EXPECT_EQ(w.count(), s.size());
    w.finish();
}

std::vector<std::string> list_dir(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

template <class F>
void expect_error(F&& f, Errc code, const std::string& word) {
    try {
        f();
        ADD_FAILURE() << "no error thrown, expected " << errc_name(code);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), code) << e.what();
        EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
}

TEST(TckWriter, RoundTripIsExact) {
    TempDir d;
    const std::string p = d.file("out.tck");
    const Streamlines s = random_streamlines(500, 1);
    const Properties props = {{"command_history", "tckgen a b\ntckedit c d"},
                              {"step_size", "0.5"},
                              {"count", "999"},       // owned by the writer: dropped
                              {"file", ". 12"},       // idem
                              {"datatype", "Float64BE"},
                              {"END", ""},
                              {"total_count", "2007"}};
    write_tck(p, s, props);
    EXPECT_EQ(list_dir(d.path()), std::vector<std::string>{"out.tck"});  // no temporary left

    TckReader r(p);
    const TckHeader& h = r.header();
    EXPECT_EQ(h.datatype, TckDataType::float32le);
    EXPECT_EQ(h.count(), 500u);
    EXPECT_EQ(h.get("total_count"), "2007");
    EXPECT_EQ(h.step_size(), 0.5);
    // The multi-line value comes back as repeated entries, in order.
    const Properties expected = {{"command_history", "tckgen a b"}, {"command_history", "tckedit c d"},
                                 {"step_size", "0.5"},              {"total_count", "2007"},
                                 {"count", "0000000500"}};
    EXPECT_EQ(h.properties, expected);
    Streamlines back;
    std::vector<Vec3f> pts;
    while (r.next(pts)) back.push_back(pts);
    EXPECT_TRUE(same_bits(back, s));
    EXPECT_EQ(r.bytes_consumed(), r.data_bytes());
}

TEST(TckWriter, HeaderLayout) {
    TempDir d;
    const std::string p = d.file("out.tck");
    write_tck(p, {{{1, 2, 3}}, {}, {{4, 5, 6}, {7, 8, 9}}}, {{"method", "tests"}});
    const std::string bytes = test::read_file(p);
    // 81 bytes of text, zero-padded to a 16-byte aligned data offset.
    const std::string head = "mrtrix tracks\nmethod: tests\ncount: 0000000003\ndatatype: Float32LE\nfile: . 96\nEND\n";
    ASSERT_GE(bytes.size(), 96u);
    EXPECT_EQ(bytes.substr(0, head.size()), head);
    EXPECT_EQ(bytes.substr(head.size(), 96 - head.size()), std::string(96 - head.size(), '\0'));
    // 3 points, 3 NaN separators (the empty streamline is a lone separator), 1 Inf marker.
    ASSERT_EQ(bytes.size(), 96u + 7 * 12);
    float data[21];
    std::memcpy(data, bytes.data() + 96, sizeof data);
    EXPECT_EQ(data[0], 1.0f);
    EXPECT_EQ(data[14], 9.0f);
    for (int i : {3, 4, 5, 6, 7, 8, 15, 16, 17}) EXPECT_TRUE(std::isnan(data[i])) << i;
    for (int i : {18, 19, 20}) EXPECT_TRUE(std::isinf(data[i]) && data[i] > 0) << i;
    const Streamlines back = read_all(p);
    ASSERT_EQ(back.size(), 3u);
    EXPECT_TRUE(back[1].empty());
    EXPECT_EQ(back[2], (std::vector<Vec3f>{{4, 5, 6}, {7, 8, 9}}));
}

TEST(TckWriter, EmptyOutput) {
    TempDir d;
    const std::string p = d.file("empty.tck");
    write_tck(p, {});
    TckReader r(p);
    EXPECT_EQ(r.header().count(), 0u);
    EXPECT_EQ(r.data_bytes(), 12u);  // just the end marker
    std::vector<Vec3f> pts;
    EXPECT_FALSE(r.next(pts));
}

TEST(TckWriter, OffsetDigitsAcrossPowersOfTen) {
    // The data offset's own digits are part of the header: check the lengths where it gains a digit.
    TempDir d;
    const std::string p = d.file("o.tck");
    for (std::size_t len = 0; len < 1000; len += (len < 60 || len > 900) ? 1 : 97) {
        const std::string value(len, 'v');
        write_tck(p, {{{1, 2, 3}}}, {{"k", value}}, true);
        const std::string bytes = test::read_file(p);
        const TckHeader h = read_tck_header(p);
        EXPECT_EQ(h.data_offset % 16, 0u) << len;
        EXPECT_LT(h.data_offset - (bytes.find("\nEND\n") + 5), 16u) << len;  // padding shorter than the alignment
        EXPECT_EQ(h.get("k"), value) << len;
        const Streamlines s = read_all(p);
        ASSERT_EQ(s.size(), 1u) << len;
        EXPECT_EQ(s[0], (std::vector<Vec3f>{{1, 2, 3}})) << len;
    }
}

TEST(TckWriter, FlatArrayOverloadMatchesSpan) {
    TempDir d;
    const Streamlines s = random_streamlines(50, 2);
    write_tck(d.file("a.tck"), s);
    {
        TckWriter w(d.file("b.tck"), {}, false);
        for (const auto& sl : s) {
            std::vector<float> flat;
            for (const Vec3f& v : sl) flat.insert(flat.end(), {v.x, v.y, v.z});
            w.write(flat.data(), sl.size());
        }
        w.finish();
    }
    EXPECT_EQ(test::read_file(d.file("a.tck")), test::read_file(d.file("b.tck")));
}

TEST(TckWriter, RefusesToOverwriteWithoutPermission) {
    TempDir d;
    const std::string p = d.file("x.tck");
    test::write_file(p, "precious");
    expect_error([&] { TckWriter w(p, {}, false); }, Errc::exists, "x.tck");
    EXPECT_EQ(test::read_file(p), "precious");
    EXPECT_EQ(list_dir(d.path()), std::vector<std::string>{"x.tck"});
    write_tck(p, {{{1, 2, 3}}}, {}, true);
    EXPECT_EQ(read_all(p).size(), 1u);
}

TEST(TckWriter, AbandonedWriterLeavesNoFile) {
    TempDir d;
    const std::string p = d.file("x.tck");
    {
        TckWriter w(p, {{"method", "test"}}, false);
        for (const auto& sl : random_streamlines(200, 3)) w.write(sl);
        EXPECT_EQ(list_dir(d.path()).size(), 1u);  // the temporary, while writing
    }
    EXPECT_TRUE(list_dir(d.path()).empty());
    // Abandoning a replacement keeps the original.
    test::write_file(p, "original");
    {
        TckWriter w(p, {}, true);
        w.write(std::vector<Vec3f>{{1, 2, 3}});
    }
    EXPECT_EQ(test::read_file(p), "original");
    EXPECT_EQ(list_dir(d.path()), std::vector<std::string>{"x.tck"});
}

TEST(TckWriter, RejectsNonFiniteCoordinates) {
    TempDir d;
    const std::string p = d.file("x.tck");
    TckWriter w(p, {}, false);
    w.write(std::vector<Vec3f>{{1, 2, 3}});
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    expect_error([&] { w.write(std::vector<Vec3f>{{1, 2, 3}, {4, nan, 6}}); }, Errc::invalid_input, "streamline 1 (0-based)");
    const float flat[] = {1, 2, 3, 4, 5, -inf};
    expect_error([&] { w.write(flat, 2); }, Errc::invalid_input, "non-finite");
    w.write(std::vector<Vec3f>{{7, 8, 9}});
    w.finish();
    const Streamlines s = read_all(p);  // the rejected streamlines left no trace
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[1], (std::vector<Vec3f>{{7, 8, 9}}));
}

TEST(TckWriter, MisuseIsReported) {
    TempDir d;
    // A key that cannot be read back is data that cannot be written (exit 4), not a bad command line.
    expect_error([&] { TckWriter w(d.file("k.tck"), {{"bad:key", "v"}}, false); }, Errc::invalid_input, "bad:key");
    {  // an empty key reads back as itself (": v"): written, so .tck files holding one round-trip
        TckWriter e(d.file("e.tck"), {{"", "v"}}, false);
        e.finish();
    }
    EXPECT_EQ(read_tck_header(d.file("e.tck")).get(""), std::optional<std::string>("v"));
    TckWriter w(d.file("f.tck"), {}, false);
    w.finish();
    expect_error([&] { w.write(std::vector<Vec3f>{{1, 2, 3}}); }, Errc::invalid_argument, "finish");
    expect_error([&] { w.finish(); }, Errc::invalid_argument, "finish");
    EXPECT_EQ(read_all(d.file("f.tck")).size(), 0u);
    expect_error([&] { TckWriter x(d.path() + "/no/such/dir/o.tck", {}, false); }, Errc::io, "o.tck");
}

// ---- Interoperability (skipped when the tool is missing) ----

bool have_nibabel() { return run_command("/usr/bin/python3 -c 'import nibabel' 2>/dev/null").status == 0; }
bool have_tckinfo() { return run_command("command -v tckinfo >/dev/null 2>&1").status == 0; }

TEST(TckWriterInterop, NibabelReadsWhatWeWrite) {
    if (!have_nibabel()) GTEST_SKIP() << "/usr/bin/python3 with nibabel not available";
    TempDir d;
    const std::string p = d.file("nib.tck");
    const Streamlines s = random_streamlines(40, 4, false);
    write_tck(p, s, {{"command_history", "fiblet test\nsecond line"}, {"total_count", "77"}});
    test::write_file(d.file("load.py"),
                     "import sys\n"
                     "import nibabel as nib\n"
                     "t = nib.streamlines.load(sys.argv[1])\n"
                     "print(t.header['count'], t.header['total_count'], len(t.streamlines))\n"
                     "for s in t.streamlines:\n"
                     "    print(len(s))\n"
                     "    for q in s:\n"
                     "        print('%.9g %.9g %.9g' % (q[0], q[1], q[2]))\n");
    const CommandResult r = run_command("/usr/bin/python3 " + d.file("load.py") + " " + p + " 2>&1");
    ASSERT_EQ(r.status, 0) << r.output;
    std::istringstream in(r.output);
    std::string count, total;
    std::size_t n = 0;
    in >> count >> total >> n;
    EXPECT_EQ(std::stoull(count), s.size());
    EXPECT_EQ(total, "77");
    ASSERT_EQ(n, s.size());
    Streamlines back(n);
    for (auto& sl : back) {
        std::size_t m = 0;
        in >> m;
        sl.resize(m);
        for (Vec3f& q : sl) {
            std::string x, y, z;
            in >> x >> y >> z;
            q = {std::strtof(x.c_str(), nullptr), std::strtof(y.c_str(), nullptr), std::strtof(z.c_str(), nullptr)};
        }
    }
    ASSERT_TRUE(in) << r.output.substr(0, 2000);
    EXPECT_EQ(back, s);  // %.9g round-trips float32 exactly
}

TEST(TckWriterInterop, TckinfoReportsCount) {
    if (!have_tckinfo()) GTEST_SKIP() << "MRtrix3 tckinfo not available";
    TempDir d;
    const std::string p = d.file("mr.tck");
    const Streamlines s = random_streamlines(123, 5);  // includes empty streamlines
    write_tck(p, s, {{"fiblet_note", "hello"}});
    const CommandResult r = run_command("tckinfo -count " + p + " 2>&1");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("fiblet_note"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("count:"), std::string::npos) << r.output;
    std::istringstream in(r.output);
    std::string line;
    bool header_count = false, actual_count = false;
    while (std::getline(in, line)) {
        const auto at = [&](const std::string& key) { return line.find(key); };
        if (at("actual count in file:") != std::string::npos) {
            EXPECT_EQ(std::stoull(line.substr(at("actual count in file:") + 21)), s.size()) << line;
            actual_count = true;
        } else if (at("count:") != std::string::npos && at("total_count") == std::string::npos) {
            EXPECT_EQ(std::stoull(line.substr(at("count:") + 6)), s.size()) << line;
            header_count = true;
        }
    }
    EXPECT_TRUE(header_count) << r.output;
    EXPECT_TRUE(actual_count) << r.output;
}

}  // namespace
}  // namespace fiblet
