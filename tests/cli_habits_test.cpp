// What MRtrix3 and zstd users type (issue 13, "CLI habits"): MRtrix3's
// single-dash options, thread counts from the environment, an --output-dir
// that does not exist yet, one --fibers syntax.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/tractogram_format.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

using test::read_tck_fibers;

bool mentions(const test::CommandResult& r, const std::string& text) {
    return r.output.find(text) != std::string::npos;
}

// `fiblet ARGS` run inside `dir` (where a split `-force` would leave a file "rce").
test::CommandResult run_in(const test::TempDir& dir, const std::string& args, const std::string& env = "") {
    return test::run_command("cd " + dir.path() + " && " + env + " " + FIBLET_CLI + " " + args + " 2>&1");
}

struct Fixture {
    test::TempDir dir;
    Fixture() {
        test::write_three_fiber_tck(dir.file("in.tck"));
        const auto r = test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft"));
        if (r.status != 0) throw std::runtime_error(r.output);
    }
};

}  // namespace

TEST(CliHabits, MrtrixSpellingsMeanTheirFibletOptions) {
    Fixture fx;
    { std::ofstream(fx.dir.file("out.fft")) << "old"; }
    // -force overwrites (it was -f -o rce), -quiet prints nothing, -nthreads N takes its value.
    const auto r = run_in(fx.dir, "compress in.tck -o out.fft -force -quiet -nthreads 1");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output, "");
    EXPECT_FALSE(fs::exists(fx.dir.file("rce")));
    EXPECT_EQ(FftFile(fx.dir.file("out.fft")).header().fibers, 3u);
    // Without -force the existing output is kept (exit 5), as with --force absent.
    EXPECT_EQ(run_in(fx.dir, "compress in.tck -o out.fft -quiet").status, 5);

    const auto d = run_in(fx.dir, "decompress in.fft -o out.tck -nthreads 2 -quiet");
    EXPECT_EQ(d.status, 0) << d.output;
    EXPECT_EQ(d.output, "");
    EXPECT_EQ(read_tck_fibers(fx.dir.file("out.tck")).size(), 3u);
    EXPECT_TRUE(mentions(run_in(fx.dir, "-version"), "fiblet "));
    EXPECT_TRUE(mentions(run_in(fx.dir, "decompress -help"), "--output"));
}

TEST(CliHabits, OtherSingleDashWordsAreRejectedNamingTheOption) {
    Fixture fx;
    struct Case {
        std::string args, message;
    };
    for (const Case& c : {Case{"compress in.tck -o x.fft -json", "long options take two dashes: --json"},
                          Case{"compress in.tck -o x.fft -info", "MRtrix3's -info has no counterpart"},
                          Case{"compress in.tck -o x.fft -fq", "not an option of fiblet compress"},
                          Case{"compress in.tck -ox.fft", "not an option of fiblet compress"},
                          Case{"extract in.fft -o x.tck -nthreads 2", "fiblet extract has no --threads option"},
                          Case{"info in.fft -quiet", "fiblet info has no --quiet option"},
                          Case{"-bogus", "not an option of fiblet "}}) {
        const auto r = run_in(fx.dir, c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
        EXPECT_TRUE(mentions(r, c.message)) << c.args << "\n" << r.output;
        EXPECT_FALSE(fs::exists(fx.dir.file("x.fft")) || fs::exists(fx.dir.file("x.tck"))) << c.args;
    }
    // Nothing but in.tck, in.fft: no file named after the letters of a split word.
    EXPECT_EQ(std::distance(fs::directory_iterator(fx.dir.path()), fs::directory_iterator{}), 2);
}

TEST(CliHabits, ValuesAndOperandsThatLookLikeOptionsAreLeftAlone) {
    Fixture fx;
    // An option's value, an operand after --, a short option with its number
    // attached, and a negative number are not single-dash options.
    EXPECT_EQ(run_in(fx.dir, "compress -q in.tck -o -odd.fft").status, 0);
    EXPECT_EQ(FftFile(fx.dir.file("-odd.fft")).header().fibers, 3u);
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("-in.tck"));
    EXPECT_EQ(run_in(fx.dir, "compress -q -j1 -o two.fft -- -in.tck").status, 0);
    EXPECT_TRUE(fs::exists(fx.dir.file("two.fft")));
    const auto r = run_in(fx.dir, "extract -q in.fft -o box.tck --include -1,0,0,8,3,3");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_tck_fibers(fx.dir.file("box.tck")).size(), 3u);
}

TEST(CliHabits, ThreadCountFromTheEnvironment) {
    Fixture fx;
    const std::string cmd = "compress -q -f in.tck -o e.fft";
    // An absurd count from either variable is refused as it is on the command line.
    for (const char* env : {"FIBLET_NTHREADS=4294967295", "MRTRIX_NTHREADS=4294967295"}) {
        const auto r = run_in(fx.dir, cmd, std::string("env -u FIBLET_NTHREADS -u MRTRIX_NTHREADS ") + env);
        EXPECT_EQ(r.status, 2) << env << "\n" << r.output;
        EXPECT_TRUE(mentions(r, "at most 1024")) << r.output;
    }
    const auto bad = run_in(fx.dir, cmd, "env -u MRTRIX_NTHREADS FIBLET_NTHREADS=many");
    EXPECT_EQ(bad.status, 2) << bad.output;
    EXPECT_TRUE(mentions(bad, "FIBLET_NTHREADS='many' is not a thread count")) << bad.output;
    // fiblet's own variable wins over MRtrix3's; the command line over both.
    EXPECT_EQ(run_in(fx.dir, cmd, "env FIBLET_NTHREADS=1 MRTRIX_NTHREADS=4294967295").status, 0);
    EXPECT_EQ(run_in(fx.dir, cmd + " -j 1", "env FIBLET_NTHREADS=4294967295").status, 0);
    EXPECT_EQ(run_in(fx.dir, "decompress -q in.fft -o e.tck", "env -u FIBLET_NTHREADS MRTRIX_NTHREADS=2").status, 0);
    EXPECT_EQ(read_tck_fibers(fx.dir.file("e.tck")).size(), 3u);
}

TEST(CliHabits, OutputDirIsCreated) {
    Fixture fx;
    const auto r = run_in(fx.dir, "compress -q in.tck --output-dir new/nested");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(FftFile(fx.dir.file("new/nested/in.fft")).header().fibers, 3u);
    const auto file = run_in(fx.dir, "compress -q in.tck --output-dir in.fft");
    EXPECT_EQ(file.status, 2) << file.output;
    EXPECT_TRUE(mentions(file, "names a file, not a directory")) << file.output;
}

TEST(CliHabits, FibersTakeOneSyntaxWithMrtrixRanges) {
    Fixture fx;
    ASSERT_EQ(run_in(fx.dir, "extract -q in.fft -o dash.tck --fibers 1-2").status, 0);
    ASSERT_EQ(run_in(fx.dir, "extract -q in.fft -o colon.tck --fibers 1:2").status, 0);
    const auto dash = read_tck_fibers(fx.dir.file("dash.tck"));
    const auto colon = read_tck_fibers(fx.dir.file("colon.tck"));
    EXPECT_EQ(dash.size(), 2u);
    EXPECT_EQ(dash, colon);
    EXPECT_EQ(run_in(fx.dir, "extract -q in.fft -o bad.tck --fibers 2:1").status, 2);
}

TEST(CliHabits, DecompressSeveralInputsAndFolderTrees) {
    Fixture fx;
    fs::create_directories(fx.dir.file("tree/sub-01/dwi"));
    fs::create_directories(fx.dir.file("tree/sub-02/dwi"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("tree/sub-01/dwi/a.tck"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("tree/sub-02/dwi/b.tck"));
    { std::ofstream(fx.dir.file("tree/README")) << "not a tractogram"; }
    // A directory needs -r; with it, every .tck below, the tree mirrored.
    const auto no_r = run_in(fx.dir, "compress -q tree --output-dir out");
    EXPECT_EQ(no_r.status, 2) << no_r.output;
    EXPECT_TRUE(mentions(no_r, "is a directory (-r")) << no_r.output;
    const auto r = run_in(fx.dir, "compress -q -r tree --output-dir out");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(fx.dir.file("out/sub-01/dwi/a.fft")) && fs::exists(fx.dir.file("out/sub-02/dwi/b.fft")));
    EXPECT_FALSE(fs::exists(fx.dir.file("out/README")));
    // decompress: several inputs at once, next to each (as zstd -d), or -r into --output-dir.
    const auto two = run_in(fx.dir, "decompress -q out/sub-01/dwi/a.fft out/sub-02/dwi/b.fft");
    ASSERT_EQ(two.status, 0) << two.output;
    const auto original = read_tck_fibers(fx.dir.file("in.tck"));
    EXPECT_EQ(read_tck_fibers(fx.dir.file("out/sub-01/dwi/a.tck")).size(), original.size());
    EXPECT_EQ(read_tck_fibers(fx.dir.file("out/sub-02/dwi/b.tck")),
              read_tck_fibers(fx.dir.file("out/sub-01/dwi/a.tck")));
    const auto tree = run_in(fx.dir, "decompress -q -r out --output-dir back");
    ASSERT_EQ(tree.status, 0) << tree.output;
    EXPECT_EQ(read_tck_fibers(fx.dir.file("back/sub-02/dwi/b.tck")),
              read_tck_fibers(fx.dir.file("out/sub-02/dwi/b.tck")));
    // -o names one output; one bad input among several fails the run, the others are written.
    EXPECT_EQ(run_in(fx.dir, "decompress -q out/sub-01/dwi/a.fft out/sub-02/dwi/b.fft -o x.tck").status, 2);
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("bad.fft"));
    const auto mixed = run_in(fx.dir, "decompress -q bad.fft in.fft --output-dir mixed");
    EXPECT_EQ(mixed.status, 6) << mixed.output;  // a .tck named .fft: recognised, not what decompress reads
    EXPECT_TRUE(mentions(mixed, "bad.fft") && mentions(mixed, "some inputs failed")) << mixed.output;
    EXPECT_FALSE(fs::exists(fx.dir.file("mixed/bad.tck")));
    EXPECT_EQ(read_tck_fibers(fx.dir.file("mixed/in.tck")).size(), original.size());
}

namespace {

// The numbers of the second line of a tckstats-style table (mean median std min max count).
std::vector<double> table_values(const std::string& text) {
    std::istringstream lines(text);
    std::string header, values;
    std::getline(lines, header), std::getline(lines, values);
    std::istringstream in(values);
    std::vector<double> v;
    for (double x; in >> x;) v.push_back(x);
    return v;
}

}  // namespace

TEST(CliHabits, StatsWithoutReferenceAgreesWithTckstats) {
    if (!test::shared_data_available()) GTEST_SKIP() << "shared data not found";
    if (test::run_command("tckstats -version >/dev/null 2>&1").status != 0) GTEST_SKIP() << "MRtrix3 not installed";
    test::TempDir dir;
    const std::string source = test::shared_data_dir() + "/bundles/cingulum-1-step0.1.tck";
    ASSERT_EQ(test::run_cli("compress -q " + source + " -o " + dir.file("c.fft")).status, 0);
    ASSERT_EQ(test::run_cli("decompress -q " + dir.file("c.fft") + " -o " + dir.file("c.tck")).status, 0);
    // MRtrix3 measures the decoded fibers (written out as .tck); fiblet measures them in the .fft.
    const auto mrtrix = test::run_command("tckstats -quiet " + dir.file("c.tck"));
    const auto ours = test::run_cli("stats " + dir.file("c.fft"));
    ASSERT_EQ(ours.status, 0) << ours.output;
    const auto expected = table_values(mrtrix.output), got = table_values(ours.output);
    ASSERT_EQ(expected.size(), 6u) << mrtrix.output;
    ASSERT_EQ(got.size(), 6u) << ours.output;
    for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(got[i], expected[i], 2e-5 * expected[i]) << i << "\n" << ours.output;
    EXPECT_EQ(got[5], expected[5]);
    const auto json = test::run_cli("stats --json " + dir.file("c.fft"));
    EXPECT_NE(json.output.find("\"count\": " + std::to_string(std::uint64_t(expected[5]))), std::string::npos)
        << json.output;
    EXPECT_EQ(test::run_cli("stats --max-error 5 " + dir.file("c.fft")).status, 2);
}

TEST(CliHabits, JsonKeysMeanOneThing) {
    Fixture fx;
    const auto info = test::run_cli("info --json " + fx.dir.file("in.fft"));
    ASSERT_EQ(info.status, 0) << info.output;
    // "ratio" is the compression ratio (compress, stats); the direction code's is "cap_ratio".
    EXPECT_EQ(info.output.find("\"ratio\""), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("\"cap_ratio\": "), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("\"trailer_chunks\": [\""), std::string::npos) << info.output;

    // Percentiles are 0.01 µm bin edges: printed with at most 2 decimals, not as 4.500000000000001.
    if (!test::shared_data_available()) return;
    const std::string tck = test::shared_data_dir() + "/dwi-small64d-ifod1.tck";
    ASSERT_EQ(test::run_cli("compress -q " + tck + " -o " + fx.dir.file("dwi.fft")).status, 0);
    const auto stats = test::run_cli("stats --json " + fx.dir.file("dwi.fft") + " -r " + tck);
    ASSERT_EQ(stats.status, 0) << stats.output;
    int percentiles = 0;
    for (std::size_t at = stats.output.find("_um\": "); at != std::string::npos; at = stats.output.find("_um\": ", at + 1)) {
        const std::size_t key = stats.output.rfind('"', at - 1), value = at + 6;
        if (stats.output.compare(key + 1, 1, "p") != 0) continue;
        const std::string number = stats.output.substr(value, stats.output.find_first_of(",}", value) - value);
        const std::size_t point = number.find('.');
        EXPECT_TRUE(point == std::string::npos || number.size() - point - 1 <= 2) << number << "\n" << stats.output;
        ++percentiles;
    }
    EXPECT_EQ(percentiles, 9);  // p50, p95, p99 of the error and of both directed distances
}

TEST(CliHabits, BashCompletionOffersEachSubcommandsOptions) {
    Fixture fx;
    const std::string script = fx.dir.file("completion.bash");
    ASSERT_EQ(test::run_cli("help --bash-completion > " + script).status, 0);
    auto complete = [&](const std::string& words, int cword) {
        return test::run_command("bash -c 'source " + script + " && COMP_WORDS=(" + words + ") && COMP_CWORD=" +
                                 std::to_string(cword) + " && _fiblet && printf \"%s\\n\" \"${COMPREPLY[@]}\"'")
            .output;
    };
    EXPECT_EQ(complete("fiblet decomp", 1), "decompress\n");
    EXPECT_EQ(complete("fiblet help ext", 2), "extract\n");
    // Every long option `fiblet compress --help` lists (CLI11's own help) is offered.
    const std::string help = test::run_cli("compress --help").output, offered = complete("fiblet compress --", 2);
    int checked = 0;
    for (std::size_t at = help.find("  --"); at != std::string::npos; at = help.find("  --", at + 1), ++checked) {
        const std::string option = help.substr(at + 2, help.find_first_of(" ,=\n", at + 2) - at - 2);
        EXPECT_NE(offered.find(option + "\n"), std::string::npos) << option << "\n" << offered;
    }
    EXPECT_GT(checked, 10);
    // The values of options that take one of a fixed set, not file names.
    EXPECT_EQ(complete("fiblet compress in.tck --bits \"\"", 4), "auto\n8\n16\n");
    EXPECT_EQ(complete("fiblet extract in.fft --mode b", 4), "blocks\n");
    if (test::run_cli("render --help").output.find("--style") != std::string::npos) {
        EXPECT_EQ(complete("fiblet render in.fft --style t", 4), "tubes\n");
        EXPECT_EQ(complete("fiblet render in.fft --transparency v", 4), "voxlines\n");
    }
    EXPECT_EQ(complete("fiblet compress " + fx.dir.file("in.t"), 2), fx.dir.file("in.tck") + "\n") << "files elsewhere";
}

TEST(CliHabits, ManPageRendersWithoutWarnings) {
    Fixture fx;
    const std::string page = fx.dir.file("fiblet.1");
    ASSERT_EQ(test::run_cli("help --man > " + page).status, 0);
    const auto warnings = test::run_command("MANWIDTH=100 man --warnings -l " + page + " 2>&1 >/dev/null");
    EXPECT_EQ(warnings.output, "");
    const auto text = test::run_command("MANWIDTH=100 man -l " + page + " | col -b").output;
    for (const char* s : {"fiblet compress", "fiblet decompress", "--output-dir", "MRTRIX_NTHREADS", "EXIT STATUS"})
        EXPECT_NE(text.find(s), std::string::npos) << s << "\n" << text.substr(0, 2000);
}

TEST(CliHabits, DashIsStandardInputAndOutput) {
    Fixture fx;
    fs::create_directories(fx.dir.file("spool"));
    const std::string env = "env TMPDIR=" + fx.dir.file("spool") + " ";
    const std::string cli = env + FIBLET_CLI;
    const auto in_dir = [&](const std::string& cmd) { return test::run_command("cd " + fx.dir.path() + " && " + cmd); };
    ASSERT_EQ(in_dir(cli + " decompress -q in.fft -o file.tck").status, 0);
    ASSERT_EQ(in_dir(cli + " compress -q in.tck -o file.fft -f").status, 0);
    // The data on stdout is the file a path would get; the report goes to stderr.
    ASSERT_EQ(in_dir(cli + " decompress in.fft -o - > piped.tck 2> report.txt").status, 0);
    EXPECT_EQ(test::read_file(fx.dir.file("piped.tck")), test::read_file(fx.dir.file("file.tck")));
    EXPECT_NE(test::read_file(fx.dir.file("report.txt")).find("in.fft -> -: 3 fibers"), std::string::npos);
    ASSERT_EQ(in_dir("cat in.tck | " + cli + " compress - -o - --json > piped.fft 2> report.json").status, 0);
    EXPECT_EQ(test::read_file(fx.dir.file("piped.fft")), test::read_file(fx.dir.file("file.fft")));
    EXPECT_NE(test::read_file(fx.dir.file("report.json")).find("\"fibers\": 3"), std::string::npos);
    ASSERT_EQ(in_dir("cat in.fft | " + cli + " decompress -q - -o - > twice.tck").status, 0);
    EXPECT_EQ(test::read_file(fx.dir.file("twice.tck")), test::read_file(fx.dir.file("file.tck")));
    // Standard input has no name to derive an output from; the spool files are gone.
    const auto r = in_dir("cat in.tck | " + cli + " compress - 2>&1");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(mentions(r, "standard input (-) needs -o")) << r.output;
    // Bad data on standard input is named so, not by the spool's temporary name.
    const auto bad = in_dir("echo garbage | " + cli + " compress - -o bad.fft 2>&1");
    EXPECT_EQ(bad.status, 4) << bad.output;
    EXPECT_TRUE(mentions(bad, "standard input: invalid .tck header")) << bad.output;
    EXPECT_FALSE(mentions(bad, "fiblet-stdio-")) << bad.output;
    const auto bad_fft = in_dir("echo garbage | " + cli + " decompress - -o bad.tck 2>&1");
    EXPECT_EQ(bad_fft.status, 4) << bad_fft.output;
    EXPECT_TRUE(mentions(bad_fft, "standard input: not a valid .fft file")) << bad_fft.output;
    EXPECT_FALSE(mentions(bad_fft, "fiblet-stdio-")) << bad_fft.output;
    EXPECT_TRUE(fs::is_empty(fx.dir.file("spool")));
}

TEST(CliHabits, ATrxDirectoryIsOneInputWithOrWithoutRecursion) {
    // TRX may be a directory: it is one tractogram (x.trx/ too), and -r
    // takes it whole instead of walking into it.
    Fixture fx;
    ASSERT_EQ(run_in(fx.dir, "decompress -q in.fft -o zip.trx").status, 0);
    fs::create_directories(fx.dir.file("tree/sub-01/dwi.trx"));
    const auto unzip = test::run_command("cd " + fx.dir.path() +
                                         " && python3 -c \"import zipfile; zipfile.ZipFile('zip.trx')"
                                         ".extractall('tree/sub-01/dwi.trx')\" 2>&1");
    ASSERT_EQ(unzip.status, 0) << unzip.output;
    const auto one = run_in(fx.dir, "compress -q tree/sub-01/dwi.trx/ -o one.fft");
    ASSERT_EQ(one.status, 0) << one.output;
    EXPECT_EQ(FftFile(fx.dir.file("one.fft")).header().fibers, 3u);
    const auto tree = run_in(fx.dir, "compress -q -r tree --output-dir out");
    ASSERT_EQ(tree.status, 0) << tree.output;
    EXPECT_EQ(FftFile(fx.dir.file("out/sub-01/dwi.fft")).header().fibers, 3u);
    EXPECT_EQ(test::read_file(fx.dir.file("out/sub-01/dwi.fft")), test::read_file(fx.dir.file("one.fft")));
    // A TRX directory is known by its header.json, whatever its name.
    fs::rename(fx.dir.file("tree/sub-01/dwi.trx"), fx.dir.file("tree/sub-01/tractogram"));
    const auto named = run_in(fx.dir, "compress -q tree/sub-01/tractogram -o named.fft");
    ASSERT_EQ(named.status, 0) << named.output;
    EXPECT_EQ(test::read_file(fx.dir.file("named.fft")), test::read_file(fx.dir.file("one.fft")));
    const auto renamed_tree = run_in(fx.dir, "compress -q -r tree --output-dir out2");
    ASSERT_EQ(renamed_tree.status, 0) << renamed_tree.output;
    EXPECT_EQ(test::read_file(fx.dir.file("out2/sub-01/tractogram.fft")), test::read_file(fx.dir.file("one.fft")));
    // A directory with no header.json is still a folder of inputs (-r).
    const auto folder = run_in(fx.dir, "compress -q tree -o x.fft");
    EXPECT_EQ(folder.status, 2);
    EXPECT_TRUE(mentions(folder, "is a directory (-r reads the files below it)")) << folder.output;
}

// -r confines its outputs to --output-dir: a symlinked input maps to the
// link's own path in the tree, never its target's (which may lie outside
// the tree: "..", and folders created on the way).
TEST(CliHabits, RecursiveOutputsStayInTheOutputDirForSymlinkedInputs) {
    Fixture fx;
    fs::create_directories(fx.dir.file("elsewhere/deep"));
    fs::create_directories(fx.dir.file("tree/sub"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("elsewhere/deep/x.tck"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("tree/a.tck"));
    fs::create_symlink("../../elsewhere/deep/x.tck", fx.dir.file("tree/sub/link.tck"));
    const auto r = run_in(fx.dir, "compress -q -r tree --output-dir out");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(FftFile(fx.dir.file("out/a.fft")).header().fibers, 3u);
    EXPECT_EQ(FftFile(fx.dir.file("out/sub/link.fft")).header().fibers, 3u);
    // Nothing beside the tree, nothing next to the link's target.
    EXPECT_FALSE(fs::exists(fx.dir.file("elsewhere/deep/x.fft")));
    EXPECT_FALSE(fs::exists(fx.dir.file("deep")));
    std::size_t outputs = 0;
    for (const auto& e : fs::recursive_directory_iterator(fx.dir.path()))
        outputs += e.path().extension() == ".fft" && e.path().filename() != "in.fft";
    EXPECT_EQ(outputs, 2u);
}

// Two inputs that would write one output are refused before anything is
// written (exit 2, both named): x.tck beside x.trk, or two x.tck into one
// --output-dir.
TEST(CliHabits, InputsThatWouldWriteOneOutputAreRefusedUpFront) {
    Fixture fx;
    fs::create_directories(fx.dir.file("tree"));
    fs::create_directories(fx.dir.file("a"));
    fs::create_directories(fx.dir.file("b"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("tree/x.tck"));
    ASSERT_EQ(run_in(fx.dir, "decompress -q in.fft -o tree/x.trk").status, 0);
    const auto pair = run_in(fx.dir, "compress -q -f -r tree --output-dir out");
    EXPECT_EQ(pair.status, 2) << pair.output;
    EXPECT_TRUE(mentions(pair, "tree/x.tck and tree/x.trk -> out/x.fft")) << pair.output;
    EXPECT_FALSE(fs::exists(fx.dir.file("out")));
    const auto beside = run_in(fx.dir, "compress -q -f -r tree");
    EXPECT_EQ(beside.status, 2) << beside.output;
    EXPECT_FALSE(fs::exists(fx.dir.file("tree/x.fft")));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("a/x.tck"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("b/x.tck"));
    const auto flat = run_in(fx.dir, "compress -q a/x.tck b/x.tck --output-dir flat");
    EXPECT_EQ(flat.status, 2) << flat.output;
    EXPECT_TRUE(mentions(flat, "a/x.tck and b/x.tck -> flat/x.fft")) << flat.output;
    EXPECT_FALSE(fs::exists(fx.dir.file("flat")));
}

// An option the subcommand does not have is named first, before any path is
// checked (CLI11 alone took `x.fft` after --optput for a missing input), with
// the options it is closest to; exit 2 and nothing written.
TEST(CliHabits, UnknownOptionsAreNamedWithTheClosestOnes) {
    Fixture fx;
    struct Case {
        std::string args, message;
    };
    for (const Case& c : {Case{"compress --optput x.fft in.tck", "unknown option --optput (did you mean --output?); see fiblet compress --help"},
                          Case{"compress in.tck --optput=x.fft", "unknown option --optput (did you mean --output?)"},
                          Case{"compress in.tck -o x.fft --foce", "unknown option --foce (did you mean --force?)"},
                          Case{"compress in.tck --out x.fft", "unknown option --out (did you mean --output or --output-dir?)"},
                          Case{"decompress in.fft -o x.tck --jsn", "unknown option --jsn (did you mean --json?); see fiblet decompress --help"},
                          Case{"compress --hlep", "unknown option --hlep (did you mean --help?)"},
                          Case{"--verison", "unknown option --verison (did you mean --version?); see fiblet --help"},
                          Case{"compress in.tck -o x.fft -forse", "'-forse': not an option of fiblet compress (did you mean --force?)"},
                          Case{"compress in.tck -o x.fft -k", "unknown option -k; see fiblet compress --help"},
                          Case{"compress in.tck -o x.fft --zzzzzz", "unknown option --zzzzzz; see fiblet compress --help"}}) {
        const auto r = run_in(fx.dir, c.args);
        EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
        EXPECT_TRUE(mentions(r, "fiblet: error: " + c.message)) << c.args << "\n" << r.output;
        EXPECT_FALSE(mentions(r, "Path does not exist")) << c.args << "\n" << r.output;
        EXPECT_FALSE(fs::exists(fx.dir.file("x.fft")) || fs::exists(fx.dir.file("x.tck"))) << c.args;
    }
    // Only close names are offered: nothing like --zzzzzz, and no single letter for -k.
    EXPECT_FALSE(mentions(run_in(fx.dir, "compress in.tck -o x.fft --zzzzzz"), "did you mean"));
    EXPECT_EQ(std::distance(fs::directory_iterator(fx.dir.path()), fs::directory_iterator{}), 2);
    // An option's value and an operand after -- are not options, whatever they look like.
    EXPECT_EQ(run_in(fx.dir, "compress -q in.tck -o --odd.fft").status, 0);
    EXPECT_EQ(FftFile(fx.dir.file("--odd.fft")).header().fibers, 3u);
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("--in.tck"));
    EXPECT_EQ(run_in(fx.dir, "compress -q -o dashes.fft -- --in.tck").status, 0);
    EXPECT_TRUE(fs::exists(fx.dir.file("dashes.fft")));
}

// MRtrix3's order, `compress IN OUT.fft`: the last operand, a .fft name that
// does not exist yet, is the output when no -o, --output-dir or -r says
// otherwise; two existing inputs are still two inputs.
TEST(CliHabits, CompressTakesMrtrixOrderInputThenOutput) {
    Fixture fx;
    const auto r = run_in(fx.dir, "compress -q in.tck out.fft");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(run_in(fx.dir, "verify -q out.fft").status, 0);
    const auto decoded = run_in(fx.dir, "decompress -q out.fft -o back.tck");
    EXPECT_EQ(decoded.status, 0) << decoded.output;
    EXPECT_EQ(read_tck_fibers(fx.dir.file("back.tck")).size(), 3u);
    // After -- too, and with the options before the operands.
    const auto dashed = run_in(fx.dir, "compress -q -j1 -- in.tck out2.fft");
    EXPECT_EQ(dashed.status, 0) << dashed.output;
    EXPECT_EQ(FftFile(fx.dir.file("out2.fft")).header().fibers, 3u);

    // Two existing inputs: two outputs, each beside its input.
    fs::create_directories(fx.dir.file("two"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("two/a.tck"));
    fs::copy_file(fx.dir.file("in.tck"), fx.dir.file("two/b.tck"));
    const auto two = run_in(fx.dir, "compress -q two/a.tck two/b.tck");
    EXPECT_EQ(two.status, 0) << two.output;
    EXPECT_EQ(FftFile(fx.dir.file("two/a.fft")).header().fibers, 3u);
    EXPECT_EQ(FftFile(fx.dir.file("two/b.fft")).header().fibers, 3u);

    // With -o given, a second operand stays an input (which does not exist: exit 2, nothing written).
    const auto with_o = run_in(fx.dir, "compress -q in.tck other.fft -o x.fft");
    EXPECT_EQ(with_o.status, 2) << with_o.output;
    EXPECT_TRUE(mentions(with_o, "other.fft")) << with_o.output;
    EXPECT_FALSE(fs::exists(fx.dir.file("x.fft")) || fs::exists(fx.dir.file("other.fft")));
    // Three operands are not MRtrix3's order either.
    EXPECT_EQ(run_in(fx.dir, "compress -q in.tck two/a.tck three.fft").status, 2);
    EXPECT_FALSE(fs::exists(fx.dir.file("three.fft")));
    EXPECT_TRUE(mentions(run_in(fx.dir, "compress --help"), "MRtrix3's order"));
}

// The output's name says its container, as fiblet.save: -o x.fftz is the
// zstd container without -z, -z -o x.fft and other names are refused
// before anything is written.
TEST(CliHabits, CompressWritesTheContainerItsOutputNames) {
    Fixture fx;
    const auto z = run_in(fx.dir, "compress -q in.tck -o named.fftz");
    ASSERT_EQ(z.status, 0) << z.output;
    EXPECT_EQ(detect_tractogram_format(fx.dir.file("named.fftz")), TractogramFormat::fftz);
    const auto mrtrix = run_in(fx.dir, "compress -q in.tck positional.fftz");
    ASSERT_EQ(mrtrix.status, 0) << mrtrix.output;
    EXPECT_EQ(detect_tractogram_format(fx.dir.file("positional.fftz")), TractogramFormat::fftz);
    EXPECT_EQ(detect_tractogram_format(fx.dir.file("in.fft")), TractogramFormat::fft);
    for (const std::string& args : {std::string("-z -o plain.fft"), std::string("-o out.tck"), std::string("-o out")}) {
        const auto bad = run_in(fx.dir, "compress -q in.tck " + args);
        EXPECT_EQ(bad.status, 2) << args << ": " << bad.output;
        EXPECT_TRUE(mentions(bad, ".fftz")) << bad.output;
    }
    EXPECT_FALSE(fs::exists(fx.dir.file("plain.fft")) || fs::exists(fx.dir.file("out.tck")) || fs::exists(fx.dir.file("out")));
    // A device has no name to keep: -o /dev/null takes either container.
    EXPECT_EQ(run_in(fx.dir, "compress -q in.tck -o /dev/null").status, 0);
    EXPECT_EQ(run_in(fx.dir, "compress -q -z in.tck -o /dev/null").status, 0);
}

// decompress too: a .fft/.fftz name or an unknown extension would have got
// a .tck's bytes; refused before anything is written (exit 2), .fft
// pointing at extract, which writes .fft files.
TEST(CliHabits, DecompressWritesOnlyWhatItsOutputNames) {
    Fixture fx;
    for (const std::string& name : {std::string("out.fft"), std::string("out.fftz"), std::string("out.xyz"), std::string("out")}) {
        const auto bad = run_in(fx.dir, "decompress -q in.fft -o " + name);
        EXPECT_EQ(bad.status, 2) << name << ": " << bad.output;
        EXPECT_TRUE(mentions(bad, ".tck, .trk or .trx")) << bad.output;
        EXPECT_EQ(mentions(bad, "fiblet extract"), name.find(".fft") != std::string::npos) << bad.output;
        EXPECT_FALSE(fs::exists(fx.dir.file(name))) << name;
    }
    ASSERT_EQ(run_in(fx.dir, "extract -q in.fft -o copy.fft").status, 0);
    EXPECT_EQ(detect_tractogram_format(fx.dir.file("copy.fft")), TractogramFormat::fft);
    EXPECT_EQ(run_in(fx.dir, "decompress -q in.fft -o /dev/null").status, 0);
}

// The man page's and docs/cli.md's examples use only options their
// subcommand has (each --option and -x in it appears in that help).
TEST(CliHabits, ExamplesUseOnlyRealOptions) {
    const auto page = test::run_cli("help --man").output;
    ASSERT_NE(page.find(".SH EXAMPLES"), std::string::npos);
    std::size_t examples = 0;
    for (std::size_t at = 0; (at = page.find("\n.B fiblet ", at)) != std::string::npos; ++at) {
        std::string line = page.substr(at + 4, page.find('\n', at + 1) - at - 4);
        for (std::size_t d; (d = line.find("\\-")) != std::string::npos;) line.replace(d, 2, "-");
        if (line.find(" [OPTIONS]") != std::string::npos) continue;  // a synopsis line
        ++examples;
        std::istringstream words(line);
        std::string word, sub, help;
        while (words >> word) {
            if (word == "&&") sub.clear();
            else if (word == "fiblet") continue;
            else if (sub.empty()) sub = word, help = test::run_cli(sub + " --help").output;
            else if (word.size() > 1 && word[0] == '-' && !std::isdigit(static_cast<unsigned char>(word[1]))) {
                EXPECT_NE(help.find(word), std::string::npos) << sub << " has no " << word << " (" << line << ")";
            }
        }
    }
    EXPECT_GE(examples, 6u);
}
