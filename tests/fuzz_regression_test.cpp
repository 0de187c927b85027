// The fuzz targets (fuzz/fuzz_targets.hpp) run in the normal test suite, with
// any compiler: on every input that once broke them (fuzz/regressions/TARGET/)
// and on small shared and hand-damaged files, so their invariants (results
// independent of chunk sizes and decoders, compress output that reads back,
// only fiblet::Error on bad input) are checked on every build.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "../fuzz/fuzz_targets.hpp"
#include "../fuzz/image_target.hpp"
#include "../fuzz/structure_mutator.hpp"
#include "image_source.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

using Target = void (*)(const std::uint8_t*, std::size_t);

void run(Target target, const std::string& bytes, const std::string& name) {
    try {
        target(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    } catch (const fuzz::HarnessFailure& e) {
        ADD_FAILURE() << name << ": invariant broken: " << e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << name << ": unexpected exception: " << e.what();
    }
}

// Every file of fuzz/regressions/TARGET; the number replayed.
int replay_regressions(const std::string& target_name, Target target) {
    const fs::path dir = fs::path(FIBLET_TESTS_DIR) / ".." / "fuzz" / "regressions" / target_name;
    int n = 0;
    if (!fs::is_directory(dir)) return 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (!e.is_regular_file() || e.path().extension() == ".md") continue;
        run(target, test::read_file(e.path().string()), e.path().string());
        ++n;
    }
    return n;
}

std::vector<std::string> small_shared_tck() {
    std::vector<std::string> files;
    if (!test::shared_data_available()) return files;
    for (const auto& e : fs::directory_iterator(test::shared_data("conformance")))
        if (e.path().extension() == ".tck") files.push_back(e.path().string());
    files.push_back(test::shared_data("bundles/AF_L.tck"));
    files.push_back(test::shared_data("bundles/cingulum-1.tck"));
    return files;
}

}  // namespace

TEST(FuzzRegression, TckTargets) {
    const int n = replay_regressions("tck_reader_fuzz", fuzz::tck_target) +
                  replay_regressions("compress_fuzz", fuzz::compress_target);
    for (const std::string& f : small_shared_tck()) {
        const std::string bytes = test::read_file(f);
        run(fuzz::tck_target, bytes, f);
        run(fuzz::compress_target, bytes, f);
        // Truncated anywhere: the same invariants.
        for (std::size_t cut : {bytes.size() / 3, bytes.size() - 1, bytes.size() - 13})
            if (cut < bytes.size()) run(fuzz::tck_target, bytes.substr(0, cut), f + " (cut)");
    }
    RecordProperty("regressions", n);
}

TEST(FuzzRegression, StreamlineSourceTarget) {
    const int n = replay_regressions("streamline_source_fuzz", fuzz::streamline_source_target);
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    for (const char* name : {"conformance/complex.trk", "conformance/complex_big_endian.trk", "conformance/standard.LPS.trk",
                             "bundles/AF_L.trk"}) {
        const std::string good = test::read_file(test::shared_data(name));
        run(fuzz::streamline_source_target, good, name);
        // Cut anywhere in the header or data, and bytes flipped: the same invariants.
        for (std::size_t cut = 0; cut < good.size(); cut += 37) run(fuzz::streamline_source_target, good.substr(0, cut), name);
        for (std::size_t i = 0; i < good.size(); i += 29) {
            std::string bad = good;
            bad[i] = char(bad[i] ^ (1 << (i % 8)));
            run(fuzz::streamline_source_target, bad, std::string(name) + " with byte " + std::to_string(i) + " flipped");
        }
    }
    RecordProperty("regressions", n);
}

TEST(FuzzRegression, FftTargets) {
    int n = replay_regressions("fft_file_fuzz", fuzz::fft_target) +
            replay_regressions("fft_trailer_fuzz", fuzz::fft_target) +
            replay_regressions("decode_blocks_fuzz", fuzz::blocks_target);
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    compress_file(test::shared_data("bundles/AF_L.tck"), dir.file("a.fft"), {});
    CompressOptions wide;
    wide.direction_bits = 16;
    compress_file(test::shared_data("bundles/AF_L.tck"), dir.file("a16.fft"), wide);
    // Every 97th byte flipped in turn: checksum failures, malformed blocks,
    // broken headers and LUT entries, each through every decoder.
    for (const char* name : {"a.fft", "a16.fft"}) {
        const std::string good = test::read_file(dir.file(name));
        run(fuzz::fft_target, good, name);
        for (std::size_t i = 0; i < good.size(); i += 97) {
            std::string bad = good;
            bad[i] = char(bad[i] ^ (1 << (i % 8)));
            run(fuzz::fft_target, bad, std::string(name) + " with byte " + std::to_string(i) + " flipped");
        }
    }
    // The trailer harness's structure-aware mutations, one to three at a
    // time, of a plain file and of a .fftz container.
    CompressOptions zstd;
    zstd.zstd = ZstdOptions{.level = 3, .group_blocks = 8, .transpose = true};
    compress_file(test::shared_data("bundles/AF_L.tck"), dir.file("a.fftz"), zstd);
    for (const char* name : {"a.fft", "a.fftz"}) {
        const std::string good = test::read_file(dir.file(name));
        for (unsigned seed = 0; seed < 150; ++seed) {
            std::string bad = good;
            for (unsigned k = 0; k <= seed % 3; ++k) fuzz::mutate_structure(bad, seed * 7 + k);
            run(fuzz::fft_target, bad, std::string(name) + " mutated with seed " + std::to_string(seed));
        }
    }
    // The mutator itself on any bytes (it runs inside libFuzzer, where an
    // exception is a crash): cut and mutated files, many times over.
    for (const char* name : {"a.fft", "a.fftz"}) {
        const std::string good = test::read_file(dir.file(name));
        for (unsigned seed = 0; seed < 3000; ++seed) {
            std::string b = good.substr(0, (good.size() * (seed % 17 + 1)) / 17);
            for (unsigned k = 0; k < 1 + seed % 5; ++k) EXPECT_NO_THROW(fuzz::mutate_structure(b, seed * 31 + k));
        }
    }
    // The blocks target on the file's blocks, under a few parameter headers.
    const FftFile f(dir.file("a.fft"));
    const std::vector<std::uint8_t> blocks = f.read_blocks(0, f.header().blocks);
    for (const char* params : {"\x3a\xff\x0f\x00\x10\x00\xa0\x00\x00\x00\x00\x00\x00",
                               "\x00\x01\x00\xff\xff\xff\xff\x10\x80\x10\x80\x10\x80",
                               "\xfc\xff\x0f\x00\x10\x00\xa0\x00\x00\x00\x00\x00\x00"}) {  // 16-bit, 126 points
        std::string in(params, fuzz::kBlocksInputHeader);
        in.append(reinterpret_cast<const char*>(blocks.data()), blocks.size());
        run(fuzz::blocks_target, in, "blocks");
    }
    RecordProperty("regressions", n);
}

// The image readers' target (fuzz/image_target.hpp) on a real .mif, .nii
// and .nii.gz (mrconvert's), whole, cut anywhere and with bytes flipped.
TEST(FuzzRegression, ImageTarget) {
    const int n = replay_regressions("image_fuzz", fuzz::image_target);
    const test::TempDir dir;
    test::SourceImage img;
    img.dims = {4, 3, 2, 2};
    img.fill([](std::int64_t i, std::int64_t j, std::int64_t k, std::int64_t v) { return float(i + 2 * j - k + v); });
    img.write_mif(dir.file("a.mif"));
    std::vector<std::pair<char, std::string>> files{{'\2', dir.file("a.mif")}};
    if (test::have_mrtrix() && test::mrconvert(dir.file("a.mif"), dir.file("a.nii")) &&
        test::mrconvert(dir.file("a.mif"), dir.file("a.nii.gz")))
        files.insert(files.end(), {{'\0', dir.file("a.nii")}, {'\1', dir.file("a.nii.gz")}});
    for (const auto& [format, path] : files) {
        const std::string good = format + test::read_file(path);
        run(fuzz::image_target, good, path);
        for (std::size_t cut = 1; cut < good.size(); cut += 7) run(fuzz::image_target, good.substr(0, cut), path + " (cut)");
        for (std::size_t i = 1; i < good.size(); i += 11) {
            std::string bad = good;
            bad[i] = char(bad[i] ^ 0x5a);
            run(fuzz::image_target, bad, path + " (flipped)");
        }
    }
    RecordProperty("regressions", n);
    if (files.size() < 3) GTEST_SKIP() << "no mrconvert (MRtrix3) to make the NIfTI cases; the .mif ran";
}
