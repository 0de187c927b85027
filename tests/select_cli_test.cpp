// fiblet extract: the CLI writes what the library selects, agrees with
// MRtrix3's tckedit on -include / -exclude / -minlength / -maxlength (when
// tckedit is installed), writes valid subset .fft files, and rejects bad
// options with exit code 2 and no output.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "fiblet/compress.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"
#include "image_source.hpp"
#include "select_reference.hpp"
#include "test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

int run(const std::string& cmd) {
    const int status = std::system((cmd + " >/dev/null 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::vector<Vec3f>> as_fibers(const Streamlines& s) {
    std::vector<std::vector<Vec3f>> all(s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
        for (std::uint64_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k)
            all[i].push_back({s.xyz[3 * k], s.xyz[3 * k + 1], s.xyz[3 * k + 2]});
    return all;
}

bool have_tckedit() { return run("tckedit -version") == 0; }

// A sphere as tckedit's -include/-exclude take it: x,y,z,radius.
std::string sphere_spec(Vec3f c, float r) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g,%.6g", c.x, c.y, c.z, r);
    return buf;
}

class SelectCli : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!shared_data_available()) return;
        dir_ = new TempDir;
        CompressOptions o;
        o.threads = 2;
        compress_file(shared_data("small-sdstream.tck"), dir_->file("s.fft"), o);
    }
    static void TearDownTestSuite() {
        delete dir_;
        dir_ = nullptr;
    }
    void SetUp() override {
        if (!dir_) GTEST_SKIP() << "shared test data not found";
    }
    static std::string fft() { return dir_->file("s.fft"); }
    static std::string cli() { return FIBLET_CLI; }
    static std::string b_path() { return dir_->file("refused.tck"); }
    static inline TempDir* dir_ = nullptr;
};

TEST_F(SelectCli, WritesWhatTheLibrarySelects) {
    const FftFile file(fft());
    const BlockIndex index = BlockIndex::load(file);
    struct Case {
        std::string args;
        Query query;
    };
    std::vector<Case> cases;
    Query q;
    q.fibers = {{0, 0}, {5, 5}, {10, 20}};
    cases.push_back({"--fibers 0,5,10-20", q});
    q = {};
    q.random_fraction = 0.25, q.random_seed = 7;
    q.min_length_mm = 60;
    cases.push_back({"--random-fraction 0.25 --seed 7 --min-length 60", q});
    q = {};
    q.include = {Region::sphere({5, 3, -2}, 6), Region::box_between({-20, -10, 0}, {-5, 10, 20})};
    q.roi_mode = RoiMode::blocks;
    cases.push_back({"--include 5,3,-2,6 --include -5,10,20,-20,-10,0 --mode blocks", q});
    q = {};
    ViewSelection v;
    v.camera.position = {10, -150, 40}, v.camera.target = {0, 0, 5}, v.camera.up = {0, 0, 1};
    v.camera.fov_y_deg = 25, v.camera.aspect = 1.5f, v.camera.near_mm = 100, v.camera.far_mm = 200;
    v.lod = Viewport{300, 200}, v.lod_pixels = 5;
    q.view = v;
    cases.push_back({"--camera-position 10,-150,40 --camera-target 0,0,5 --camera-up 0,0,1 --fov 25 --aspect 1.5 "
                     "--near 100 --far 200 --lod 300x200 --lod-pixels 5",
                     q});
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const std::string out = dir_->file("case" + std::to_string(i) + ".tck");
        ASSERT_EQ(run(cli() + " extract " + fft() + " -o " + out + " " + cases[i].args), 0) << cases[i].args;
        const auto expected = as_fibers(select_streamlines(file, index, cases[i].query));
        EXPECT_FALSE(expected.empty()) << cases[i].args;
        EXPECT_EQ(test::read_tck_fibers(out), expected) << cases[i].args;
    }
}

TEST_F(SelectCli, AgreesWithTckedit) {
    if (!have_tckedit()) GTEST_SKIP() << "MRtrix3 tckedit not installed";
    const std::string full = dir_->file("full.tck");
    ASSERT_EQ(run(cli() + " decompress " + fft() + " -o " + full + " -f"), 0);
    const FftFile file(fft());
    const DecodedFile d = decode_everything(file);
    QueryGenerator gen(d, 3);
    int nonempty = 0;
    for (int i = 0; i < 6; ++i) {
        // tckedit's options, and fiblet's spelling of them; fiblet also
        // takes tckedit's own (odd cases), as an MRtrix3 user types them.
        std::string args, ours;
        auto both = [&](const std::string& flag, const std::string& fiblet_flag, const std::string& value) {
            args += " -" + flag + " " + value;
            ours += (i % 2 ? " -" + flag : " --" + fiblet_flag) + " " + value;
        };
        for (int k = 0; k < 1 + i % 2; ++k) both("include", "include", sphere_spec(gen.some_point(), gen.uniform(3, 12)));
        if (i % 3 == 2) both("exclude", "exclude", sphere_spec(gen.some_point(), gen.uniform(3, 10)));
        // Lengths are multiples of the 0.1 mm step: thresholds between them.
        if (i == 4) both("minlength", "min-length", "70.05"), both("maxlength", "max-length", "120.05");
        if (i == 5) both("minlength", "min-length", "90.05");
        const std::string a = dir_->file("tckedit" + std::to_string(i) + ".tck");
        const std::string b = dir_->file("fiblet" + std::to_string(i) + ".tck");
        ASSERT_EQ(run("tckedit -quiet -force -nthreads 0 " + full + " " + a + args), 0) << args;
        ASSERT_EQ(run(cli() + " extract " + (i % 2 ? "-quiet -force " : "") + fft() + " -o " + b + ours), 0) << ours;
        const auto expected = test::read_tck_fibers(a);
        nonempty += !expected.empty();
        EXPECT_EQ(test::read_tck_fibers(b), expected) << args;
    }
    EXPECT_GT(nonempty, 2);
}

// tckedit's -ends_only, -inverse, -number and -skip, in its spelling and
// fiblet's. Where no region is given, tckedit 3.0.3's -inverse keeps every
// streamline (its length criteria then ignored); fiblet keeps those that
// fail them, as tckedit's help says: that case is checked against the
// complement of the plain selection instead.
TEST_F(SelectCli, EndsOnlyInverseNumberAndSkipAgreeWithTckedit) {
    if (!have_tckedit()) GTEST_SKIP() << "MRtrix3 tckedit not installed";
    const std::string full = dir_->file("full-eins.tck");
    ASSERT_EQ(run(cli() + " decompress " + fft() + " -f -o " + full), 0);
    const FftFile file(fft());
    const DecodedFile d = decode_everything(file);
    QueryGenerator gen(d, 5);
    const std::vector<std::string> cases = {
        " -include " + sphere_spec(gen.some_point(), 25) + " -ends_only",
        " -exclude " + sphere_spec(gen.some_point(), 20) + " -ends_only",
        " -include " + sphere_spec(gen.some_point(), 10) + " -inverse",
        " -include " + sphere_spec(gen.some_point(), 10) + " -minlength 80.05 -inverse",
        " -number 100 -skip 50",
        " -include " + sphere_spec(gen.some_point(), 12) + " -number 7 -skip 3",
        " -include " + sphere_spec(gen.some_point(), 30) + " -ends_only -inverse -number 20",
    };
    int nonempty = 0;
    for (std::size_t i = 0; i < cases.size(); ++i) {
        std::string ours = cases[i];
        if (i % 2)  // fiblet's spelling
            for (const auto& [mrtrix, fiblet] : std::vector<std::pair<std::string, std::string>>{
                     {" -include ", " --include "}, {" -exclude ", " --exclude "}, {" -ends_only", " --ends-only"},
                     {" -inverse", " --inverse"}, {" -minlength ", " --min-length "}, {" -number ", " --number "},
                     {" -skip ", " --skip "}})
                for (std::size_t at; (at = ours.find(mrtrix)) != std::string::npos;) ours.replace(at, mrtrix.size(), fiblet);
        const std::string a = dir_->file("tckedit-e" + std::to_string(i) + ".tck");
        const std::string b = dir_->file("fiblet-e" + std::to_string(i) + ".tck");
        ASSERT_EQ(run("tckedit -quiet -force -nthreads 0 " + full + " " + a + cases[i]), 0) << cases[i];
        ASSERT_EQ(run(cli() + " extract -q -f " + fft() + " -o " + b + ours), 0) << ours;
        const auto expected = test::read_tck_fibers(a);
        nonempty += !expected.empty() && expected.size() < file.header().fibers;
        EXPECT_EQ(test::read_tck_fibers(b), expected) << cases[i];
    }
    EXPECT_GE(nonempty, 5);
    // Lengths alone: --inverse keeps what --min-length drops.
    const std::string kept = dir_->file("long.tck"), dropped = dir_->file("short.tck");
    ASSERT_EQ(run(cli() + " extract -q -f " + fft() + " -o " + kept + " --min-length 80.05"), 0);
    ASSERT_EQ(run(cli() + " extract -q -f " + fft() + " -o " + dropped + " --min-length 80.05 --inverse"), 0);
    const auto long_fibers = test::read_tck_fibers(kept), short_fibers = test::read_tck_fibers(dropped);
    EXPECT_EQ(long_fibers.size() + short_fibers.size(), file.header().fibers);
    for (const auto& f : short_fibers) EXPECT_LT(double(f.size() - 1) * file.header().step * file.header().scaling, 80.05);
    // Whole-fiber tests in blocks mode are refused.
    EXPECT_EQ(run(cli() + " extract -q -f " + fft() + " -o " + b_path() + " --include 0,0,0,5 --mode blocks --inverse"), 2);
}

// A region where the tractogram has no point (a mask in voxel space, a
// sphere in another space) keeps nothing: said on stderr, not silently.
TEST_F(SelectCli, RegionsMissingTheTractogramAreWarnedAbout) {
    const std::string out = dir_->file("missed.tck");
    SourceImage far;  // a 4 mm cube of ones, 500 mm away from the tractogram
    far.dims = {4, 4, 4};
    far.transform = {{{1, 0, 0, 500}, {0, 1, 0, 500}, {0, 0, 1, 500}}};
    far.fill([](std::int64_t, std::int64_t, std::int64_t, std::int64_t) { return 1.0f; });
    far.write_mif(dir_->file("far.mif"));
    for (const std::string& region : std::vector<std::string>{"500,500,500,10", dir_->file("far.mif")}) {
        const CommandResult r = run_command(cli() + " extract -f " + fft() + " -o " + out + " --include " + region + " 2>&1");
        EXPECT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find("warning: --include " + region + " lies where"), std::string::npos) << r.output;
        EXPECT_TRUE(test::read_tck_fibers(out).empty());
    }
    // A region that meets the tractogram: no warning.
    const CommandResult hit = run_command(cli() + " extract -f " + fft() + " -o " + out + " --include 0,0,0,30 2>&1");
    EXPECT_EQ(hit.status, 0);
    EXPECT_EQ(hit.output.find("warning"), std::string::npos) << hit.output;
    EXPECT_FALSE(test::read_tck_fibers(out).empty());
}

TEST_F(SelectCli, FftOutputIsAValidSubset) {
    const std::string sub = dir_->file("sub.fft"), a = dir_->file("sub-a.tck"), b = dir_->file("sub-b.tck");
    const std::string args = " --include 0,0,0,10 --mode blocks --random-fraction 0.5";
    ASSERT_EQ(run(cli() + " extract " + fft() + " -o " + sub + args), 0);
    ASSERT_EQ(run(cli() + " info " + sub), 0);
    ASSERT_EQ(run(cli() + " decompress " + sub + " -o " + a), 0);
    ASSERT_EQ(run(cli() + " extract " + fft() + " -o " + b + args), 0);
    const auto got = test::read_tck_fibers(a);
    EXPECT_FALSE(got.empty());
    EXPECT_EQ(got, test::read_tck_fibers(b));
    // The subset has its own index: extracting everything from it reads it back.
    const std::string c = dir_->file("sub-c.tck");
    ASSERT_EQ(run(cli() + " extract " + sub + " -o " + c), 0);
    EXPECT_EQ(test::read_tck_fibers(c), got);
}

// Fibers-mode regions alone into a .fft (decided on all cores where the
// library's rule says so: kept_fiber_runs) keep what the .tck output's
// streaming selection keeps.
TEST_F(SelectCli, FftOutputOfRegionsAloneKeepsTheTckOutputsFibers) {
    const std::string sub = dir_->file("regions.fft"), a = dir_->file("regions-a.tck"), b = dir_->file("regions-b.tck");
    const std::string args = " --include 0,0,0,20 --exclude 5,5,5,3";
    ASSERT_EQ(run(cli() + " extract " + fft() + " -o " + sub + args), 0);
    ASSERT_EQ(run(cli() + " decompress " + sub + " -o " + a), 0);
    ASSERT_EQ(run(cli() + " extract " + fft() + " -o " + b + args), 0);
    const auto got = test::read_tck_fibers(a);
    EXPECT_FALSE(got.empty());
    EXPECT_EQ(got, test::read_tck_fibers(b));
}

TEST_F(SelectCli, AddsAnIndexToOfficialEncoderFiles) {
    const std::string out = dir_->file("indexed.fft");
    ASSERT_EQ(run(cli() + " extract " + shared_data("reference/small-sdstream.fft") + " -o " + out), 0);
    const FftFile src(shared_data("reference/small-sdstream.fft")), indexed(out);
    EXPECT_EQ(src.find_chunk(kBlockIndexTag), nullptr);
    EXPECT_NE(indexed.find_chunk(kBlockIndexTag), nullptr);
    EXPECT_EQ(indexed.header().points, src.header().points);
    EXPECT_EQ(decode_everything(indexed).points.xyz, decode_everything(src).points.xyz);
}

TEST_F(SelectCli, BadOptionsExitWithUsageErrorAndWriteNothing) {
    const std::string out = dir_->file("bad.tck"), out_fft = dir_->file("bad.fft");
    for (const std::string args : {" --include 1,2,3", " --include 1,2,x,4", " --fibers 5-", " --fibers 9-3",
                                   " --random-fraction 2", " --min-length 50 --max-length 10", " --include 0,0,0,-1",
                                   " --camera-position 0,0,100", " --lod 100x100", " --mode strands",
                                   " --camera-position 0,0,100 --camera-target 0,0,0 --lod 100",
                                   " --camera-position 0,0,100 --camera-target 0,0,100"}) {
        EXPECT_EQ(run(cli() + " extract " + fft() + " -o " + out + args), 2) << args;
        EXPECT_FALSE(std::filesystem::exists(out)) << args;
    }
    EXPECT_EQ(run(cli() + " extract " + fft() + " -o " + out_fft +
                  " --camera-position 0,0,100 --camera-target 0,0,0 --lod 100x100"),
              2);
    EXPECT_FALSE(std::filesystem::exists(out_fft));
    EXPECT_EQ(run(cli() + " extract " + fft() + " -o " + dir_->file("bad.txt")), 2);
    // An existing output needs --force.
    ASSERT_EQ(run(cli() + " extract " + fft() + " -o " + out + " --fibers 0"), 0);
    EXPECT_EQ(run(cli() + " extract " + fft() + " -o " + out + " --fibers 1"), 5);
    EXPECT_EQ(run(cli() + " extract " + fft() + " -o " + out + " --fibers 1 -f"), 0);
}

}  // namespace
