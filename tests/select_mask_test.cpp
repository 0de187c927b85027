// Image masks as regions (fiblet/image_mask.hpp): the voxel rule is
// MRtrix3 tckedit's (probed point by point with tckedit itself), box tests
// are conservative, selections through the block index equal the
// decode-everything reference, and `fiblet extract --include MASK` gives
// exactly tckedit's fibers on masks written by mrconvert.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "fiblet/compress.hpp"
#include "fiblet/fiber_regions.hpp"
#include "fiblet/image_mask.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"
#include "select/block_bits.hpp"
#include "image_source.hpp"
#include "select_reference.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

// An oblique grid of 2.5 x 2 x 3 mm voxels whose values exercise the
// rounding rule: 0, ±0.3, 0.5, 0.7, 1, -1, NaN, Inf.
SourceImage probe_mask() {
    SourceImage s;
    s.dims = {9, 8, 7};
    s.vox = {2.5, 2.0, 3.0};
    const double a = 0.35, ca = std::cos(a), sa = std::sin(a);
    s.transform = {{{ca, 0, sa, -9.0}, {0, 1, 0, -6.5}, {-sa, 0, ca, -8.0}}};
    const float values[] = {0,    0.3f, -0.3f, 0.5f, 0.7f, 1, -1, std::numeric_limits<float>::quiet_NaN(),
                            0.49f, 2,   std::numeric_limits<float>::infinity(), -0.5f, 0};
    s.fill([&](auto i, auto j, auto k, auto) { return values[(i * 7 + j * 3 + k * 5) % 13]; });
    return s;
}

// A random world point in or just around the image's grid.
Vec3f around_grid(const SourceImage& s, std::mt19937& rng) {
    std::array<double, 3> v{};
    for (int a = 0; a < 3; ++a) v[a] = std::uniform_real_distribution<double>(-1.5, double(s.dims[a]) + 0.5)(rng);
    const auto w = transform_point(s.voxel_to_world(), v);
    return {float(w[0]), float(w[1]), float(w[2])};
}

class ImageMaskTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (!have_mrtrix()) GTEST_SKIP() << "MRtrix3 (mrconvert, tckedit) not installed";
    }
    TempDir dir_;
};

// tckedit decides, for two-point streamlines at random positions (both
// points the same), which lie in the mask: ImageMask::contains must agree.
TEST_F(ImageMaskTest, VoxelRuleIsTckedits) {
    const SourceImage src = probe_mask();
    const std::string source = dir_.file("probe.mif");
    src.write_mif(source);
    std::mt19937 rng(7);
    std::vector<Vec3f> probes(20000);
    for (Vec3f& p : probes) p = around_grid(src, rng);
    const std::string tck = dir_.file("probes.tck");
    {
        TckWriter w(tck, {}, true);
        for (const Vec3f& p : probes) {
            const Vec3f two[2] = {p, p};
            w.write(two);
        }
        w.finish();
    }
    ASSERT_TRUE(mrconvert(source, dir_.file("probe.nii.gz")));
    ASSERT_TRUE(mrconvert(source, dir_.file("probe-strided.mif"), "-strides -2,3,-1"));
    for (const std::string name : {"probe.mif", "probe.nii.gz", "probe-strided.mif"}) {
        const std::string path = dir_.file(name);
        const std::string out = dir_.file(name + ".tck");
        ASSERT_EQ(run_command("tckedit -quiet -force -nthreads 0 " + tck + " " + out + " -include " + path + " 2>&1").status, 0);
        const auto kept = test::read_tck_fibers(out);
        const auto mask = ImageMask::read(path);
        std::vector<Vec3f> ours;
        for (const Vec3f& p : probes)
            if (mask->contains(p)) ours.push_back(p);
        ASSERT_EQ(kept.size(), ours.size()) << name;
        for (std::size_t i = 0; i < ours.size(); ++i) EXPECT_EQ(kept[i][0], ours[i]) << name << " probe " << i;
        EXPECT_GT(ours.size(), probes.size() / 5) << name;  // the probes do fall in the mask
        EXPECT_LT(ours.size(), probes.size() * 4 / 5) << name;
    }
}

TEST_F(ImageMaskTest, BoxTestsAreConservative) {
    const SourceImage src = probe_mask();
    src.write_mif(dir_.file("m.mif"));
    const auto mask = ImageMask::read(dir_.file("m.mif"));
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> size(0.01f, 2.0f), t(0.0f, 1.0f);
    int outside = 0, inside = 0;
    for (int n = 0; n < 4000; ++n) {
        const Vec3f lo = around_grid(src, rng);
        const Aabb box{lo, {lo.x + size(rng), lo.y + size(rng), lo.z + size(rng)}};
        const ImageMask::Overlap o = mask->classify(box);
        outside += o == ImageMask::Overlap::outside, inside += o == ImageMask::Overlap::inside;
        for (int s = 0; s < 200; ++s) {
            const Vec3f p{box.min.x + t(rng) * (box.max.x - box.min.x), box.min.y + t(rng) * (box.max.y - box.min.y),
                          box.min.z + t(rng) * (box.max.z - box.min.z)};
            if (o == ImageMask::Overlap::outside) {
                ASSERT_FALSE(mask->contains(p)) << n;
            } else if (o == ImageMask::Overlap::inside) {
                ASSERT_TRUE(mask->contains(p)) << n;
            }
        }
    }
    EXPECT_GT(outside, 100);  // both answers are given, not only "partial"
    EXPECT_GT(inside, 100);
    // An unbounded box (an escaped block's) meets the mask.
    const float big = 1e30f;
    EXPECT_EQ(mask->classify({{-big, -big, -big}, {big, big, big}}), ImageMask::Overlap::partial);
}

// contains_any takes four points at a time in vector lanes: it answers as
// contains() of each point would, on points around the grid, on voxel
// halves (where the rounding rule decides) and on non-finite points.
TEST_F(ImageMaskTest, ContainsAnyIsContainsOfEachPoint) {
    const SourceImage src = probe_mask();
    src.write_mif(dir_.file("m.mif"));
    const auto mask = ImageMask::read(dir_.file("m.mif"));
    std::mt19937 rng(5);
    auto on_a_half = [&] {  // one voxel coordinate at i + 0.5
        std::array<double, 3> v{};
        for (int a = 0; a < 3; ++a) v[a] = std::uniform_real_distribution<double>(-1.5, double(src.dims[a]) + 0.5)(rng);
        const int a = int(rng() % 3);
        v[a] = std::floor(v[a]) + 0.5;
        const auto w = transform_point(src.voxel_to_world(), v);
        return Vec3f{float(w[0]), float(w[1]), float(w[2])};
    };
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    std::size_t yes = 0, no = 0;
    for (int run = 0; run < 20000; ++run) {
        std::vector<Vec3f> points(rng() % 13);
        for (Vec3f& p : points) {
            const unsigned kind = rng() % 16;
            p = kind < 9 ? around_grid(src, rng) : kind < 15 ? on_a_half() : Vec3f{nan, inf, -inf};
        }
        bool any = false;
        for (const Vec3f& p : points) any = any || mask->contains(p);
        ASSERT_EQ(mask->contains_any(reinterpret_cast<const float*>(points.data()), points.size()), any) << "run " << run;
        (any ? yes : no) += 1;
    }
    EXPECT_GT(yes, 1000u);
    EXPECT_GT(no, 1000u);
}

TEST_F(ImageMaskTest, EmptyMaskIsRefused) {
    SourceImage src;
    src.dims = {3, 3, 3};
    src.fill([](auto, auto, auto, auto) { return 0.4f; });
    src.write_mif(dir_.file("empty.mif"));
    EXPECT_EQ(error_of([&] { ImageMask::read(dir_.file("empty.mif")); }), Errc::invalid_argument);
}

// Masks over the phantom tractogram: a ball of 1 / 0.6 / 0.4 shells (float
// NIfTI), a thick oblique slab (bit .mif, reversed strides), a ball in uint8.
class MaskSelection : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!shared_data_available() || !have_mrtrix()) return;
        dir_ = new TempDir;
        CompressOptions o;
        o.threads = 2;
        compress_file(shared_data("small-sdstream.tck"), dir_->file("s.fft"), o);
        const FftFile file(dir_->file("s.fft"));
        decoded_ = new DecodedFile(decode_everything(file));
        QueryGenerator gen(*decoded_, 11);
        ball(gen.some_point(), 2.0, 9.0, dir_->file("ball.mif"));
        ASSERT_TRUE(mrconvert(dir_->file("ball.mif"), dir_->file("ball.nii.gz")));
        ball(gen.some_point(), 1.0, 7.0, dir_->file("ball2.mif"));
        ASSERT_TRUE(mrconvert(dir_->file("ball2.mif"), dir_->file("ball2.nii"), "-datatype uint8"));
        slab(dir_->file("slab-src.mif"));
        ASSERT_TRUE(mrconvert(dir_->file("slab-src.mif"), dir_->file("slab.mif"), "-datatype bit -strides -1,-2,3"));
    }
    static void TearDownTestSuite() {
        delete decoded_;
        delete dir_;
        decoded_ = nullptr, dir_ = nullptr;
    }
    void SetUp() override {
        if (!dir_) GTEST_SKIP() << "shared test data or MRtrix3 not found";
    }
    // Grid of `vox` mm over the phantom; 1 within r/2 of c, 0.6 within 3r/4, 0.4 within r.
    static void ball(Vec3f c, double vox, double r, const std::string& path) {
        SourceImage s;
        const auto n = std::int64_t(std::ceil(90 / vox));
        s.dims = {n, n, n};
        s.vox = {vox, vox, vox};
        s.transform = {{{1, 0, 0, -45}, {0, 1, 0, -45}, {0, 0, 1, -45}}};
        s.fill([&](auto i, auto j, auto k, auto) {
            const double dx = -45 + i * vox - c.x, dy = -45 + j * vox - c.y, dz = -45 + k * vox - c.z;
            const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
            return d <= r / 2 ? 1.0f : d <= 0.75 * r ? 0.6f : d <= r ? 0.4f : 0.0f;
        });
        s.write_mif(path);
    }
    static void slab(const std::string& path) {
        SourceImage s;
        s.dims = {40, 36, 30};
        s.vox = {2.5, 2.5, 3};
        const double a = 0.3, ca = std::cos(a), sa = std::sin(a);
        s.transform = {{{ca, -sa, 0, -40}, {sa, ca, 0, -55}, {0, 0, 1, -45}}};
        s.fill([](auto i, auto, auto, auto) { return float(i >= 18 && i <= 20); });
        s.write_mif(path);
    }
    static std::string fft() { return dir_->file("s.fft"); }
    static inline TempDir* dir_ = nullptr;
    static inline DecodedFile* decoded_ = nullptr;
};

TEST_F(MaskSelection, IndexSelectionEqualsReference) {
    const FftFile file(fft());
    const BlockIndex index = BlockIndex::load(file);
    const auto ball = Region::image(ImageMask::read(dir_->file("ball.nii.gz")));
    const auto ball2 = Region::image(ImageMask::read(dir_->file("ball2.nii")));
    const auto slab = Region::image(ImageMask::read(dir_->file("slab.mif")));
    std::vector<Query> queries(6);
    queries[0].include = {ball};
    queries[1].include = {ball, ball2};
    queries[2].include = {ball}, queries[2].exclude = {slab};
    queries[3].exclude = {slab};
    queries[4].include = {slab}, queries[4].roi_mode = RoiMode::blocks;
    queries[5].include = {ball2}, queries[5].exclude = {slab}, queries[5].roi_mode = RoiMode::blocks;
    for (std::size_t i = 0; i < queries.size(); ++i) {
        std::vector<SelectedRun> runs;
        SelectionStats stats;
        const Streamlines got = select_streamlines(file, index, queries[i], &runs, &stats);
        const ReferenceSelection ref = reference_select(file, *decoded_, queries[i]);
        expect_same_selection(ref, got, runs, "query " + std::to_string(i));
        EXPECT_FALSE(runs.empty()) << i;
        if (i < 2) {
            EXPECT_LT(stats.blocks_decoded, file.header().blocks / 2) << i;  // the index kept most blocks out
        }
    }
}

// The index walk tests a mask eight boxes at a time (index/box_tests.hpp:
// the mask's bounds in vector lanes, then ImageMask::classify box by box):
// the blocks it puts near a mask, and wholly inside, are exactly those whose
// own box classify() puts there.
TEST_F(MaskSelection, WalkAgreesWithClassifyBlockByBlock) {
    const FftFile file(fft());
    const BlockIndex index = BlockIndex::load(file);
    for (const char* name : {"ball.nii.gz", "ball2.nii", "slab.mif"}) {
        const auto mask = ImageMask::read(dir_->file(name));
        std::vector<std::uint64_t> inside;
        const std::vector<std::uint64_t> near = blocks_near(index, Region::image(mask), &inside);
        std::size_t near_count = 0, inside_count = 0;
        for (std::uint64_t b = 0; b < index.blocks(); ++b) {
            const ImageMask::Overlap o = mask->classify(index.block_box(b));
            const bool is_near = detail::has_bit(near, b), is_inside = detail::has_bit(inside, b);
            ASSERT_EQ(is_near, o != ImageMask::Overlap::outside) << name << " block " << b;
            ASSERT_EQ(is_inside, o == ImageMask::Overlap::inside) << name << " block " << b;
            near_count += is_near, inside_count += is_inside;
        }
        EXPECT_GT(near_count, 0u) << name;
        EXPECT_LT(near_count, index.blocks()) << name;  // the mask rules some blocks out
        if (std::string(name) == "ball.nii.gz") {
            EXPECT_GT(inside_count, 0u) << name;
        }
    }
}

TEST_F(MaskSelection, ExtractEqualsTckedit) {
    const std::string full = dir_->file("full.tck");
    ASSERT_EQ(run_cli("decompress " + fft() + " -o " + full + " -f").status, 0);
    const std::string ball = dir_->file("ball.nii.gz"), ball2 = dir_->file("ball2.nii"), slab = dir_->file("slab.mif");
    const std::vector<std::string> cases = {
        " -include " + ball, " -include " + ball + " -include " + ball2, " -include " + ball + " -exclude " + slab,
        " -exclude " + slab, " -include " + slab + " -include 0,0,0,15",
    };
    for (std::size_t i = 0; i < cases.size(); ++i) {
        std::string ours;  // fiblet's spelling: --include, --exclude
        for (const char c : cases[i]) ours += (c == '-' && !ours.empty() && ours.back() == ' ') ? "--" : std::string(1, c);
        const std::string a = dir_->file("tckedit" + std::to_string(i) + ".tck");
        const std::string b = dir_->file("fiblet" + std::to_string(i) + ".tck");
        ASSERT_EQ(run_command("tckedit -quiet -force -nthreads 0 " + full + " " + a + cases[i] + " 2>&1").status, 0)
            << cases[i];
        ASSERT_EQ(run_cli("extract -q " + fft() + " -o " + b + ours).status, 0) << ours;
        const auto expected = test::read_tck_fibers(a);
        EXPECT_FALSE(expected.empty()) << cases[i];
        EXPECT_EQ(test::read_tck_fibers(b), expected) << cases[i];
    }
}

TEST_F(MaskSelection, BadMasksExitWithTheirCodes) {
    const std::string out = dir_->file("bad.tck");
    const std::string garbage = dir_->file("garbage.nii");
    write_file(garbage, std::string(1000, 'x'));
    const auto malformed = run_cli("extract " + fft() + " -o " + out + " --include " + garbage);
    EXPECT_EQ(malformed.status, 4) << malformed.output;
    EXPECT_NE(malformed.output.find("garbage.nii"), std::string::npos) << malformed.output;
    EXPECT_EQ(run_cli("extract " + fft() + " -o " + out + " --include " + dir_->file("missing.nii")).status, 3);
    EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
