// The image reader (fiblet/image.hpp) on files written by MRtrix3's
// mrconvert from a generated source: NIfTI-1, NIfTI-2, gzip, .mif in other
// layouts and datatypes. Values must come back exactly and the voxel ->
// world transform as `mrinfo -transform -spacing` reports it; malformed
// images are refused with Error{image_format}.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <sstream>

#include "fiblet/error.hpp"
#include "fiblet/image.hpp"
#include "image_source.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

// A small rotation about z and x with a translation, voxel sizes that differ
// per axis: every entry of the transform matters.
SourceImage oblique_source(std::vector<std::int64_t> dims) {
    SourceImage s;
    s.dims = std::move(dims);
    s.vox = {1.5, 2.0, 2.5};
    const double a = 0.2, b = -0.1;
    const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
    // Rz(a) * Rx(b)
    s.transform = {{{ca, -sa * cb, sa * sb, -12.5}, {sa, ca * cb, -ca * sb, 7.25}, {0, sb, cb, 30.0}}};
    s.fill([](auto i, auto j, auto k, auto v) { return float(i + 10 * j + 100 * k + 1000 * v); });
    return s;
}

// `mrinfo -transform` (image -> scanner, unit axes) times `mrinfo -spacing`.
std::optional<Affine3x4> mrinfo_voxel_to_world(const std::string& path) {
    const auto t = run_command("mrinfo -transform " + path + " 2>/dev/null");
    const auto s = run_command("mrinfo -spacing " + path + " 2>/dev/null");
    if (t.status != 0 || s.status != 0) return std::nullopt;
    std::istringstream ts(t.output), ss(s.output);
    Affine3x4 m{};
    for (auto& row : m)
        for (double& x : row) ts >> x;
    std::array<double, 3> vox{};
    for (double& v : vox) ss >> v;
    if (!ts || !ss) return std::nullopt;
    for (auto& row : m)
        for (int c = 0; c < 3; ++c) row[c] *= vox[c];
    return m;
}

void expect_affine_near(const Affine3x4& got, const Affine3x4& want, double tol, const std::string& what) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[r][c], want[r][c], tol) << what << " (" << r << "," << c << ")";
}

class ImageReader : public ::testing::Test {
protected:
    void SetUp() override {
        if (!have_mrtrix()) GTEST_SKIP() << "MRtrix3 (mrconvert, mrinfo) not installed";
    }
    TempDir dir_;
};

TEST_F(ImageReader, ReadsWhatMrconvertWrites) {
    const SourceImage src = oblique_source({5, 4, 3, 2});
    const std::string source = dir_.file("source.mif");
    src.write_mif(source);
    struct Case {
        std::string name, options;
    };
    const std::vector<Case> cases = {
        {"nifti1.nii", ""},
        {"nifti1.nii.gz", "-datatype int16"},
        {"nifti2.nii", "-config NIfTIAlwaysUseVer2 true -datatype float64"},
        {"nifti2.nii.gz", "-config NIfTIAlwaysUseVer2 true -datatype uint16"},
        {"plain.mif", ""},
        {"strided.mif", "-strides -1,3,2,4 -datatype float64"},
        {"volumes_first.mif", "-strides 2,3,4,1 -datatype int32be"},
        {"reversed.mif", "-strides -4,-3,-2,-1 -datatype uint16le"},
        {"source-copy.mif", "-datatype float32be"},
    };
    for (const Case& c : cases) {
        const std::string path = dir_.file(c.name);
        ASSERT_TRUE(mrconvert(source, path, c.options)) << c.name;
        const Image img = read_image(path);
        ASSERT_EQ(img.dims, src.dims) << c.name;
        EXPECT_EQ(img.volumes(), 2) << c.name;
        ASSERT_EQ(img.values, src.values) << c.name;
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(img.spacing[a], src.vox[a], 1e-6) << c.name;
        // Stored as float32 in NIfTI: agreement to float precision.
        expect_affine_near(img.voxel_to_world, src.voxel_to_world(), 2e-5, c.name + " vs the source");
        if (const auto mr = mrinfo_voxel_to_world(path))
            expect_affine_near(img.voxel_to_world, *mr, 2e-5, c.name + " vs mrinfo");
        else
            EXPECT_NE(c.name.find("nifti2"), std::string::npos) << "mrinfo could not read " << c.name;
    }
}

TEST_F(ImageReader, BitMasksAndIntensityScaling) {
    SourceImage src;
    src.dims = {7, 5, 3};
    src.fill([](auto i, auto j, auto k, auto) { return float((i * 3 + j * 5 + k) % 4 == 0); });
    const std::string source = dir_.file("mask.mif"), bit = dir_.file("bit.mif"), u8 = dir_.file("u8.nii");
    src.write_mif(source);
    ASSERT_TRUE(mrconvert(source, bit, "-datatype bit"));
    ASSERT_TRUE(mrconvert(source, u8, "-datatype uint8"));
    EXPECT_NE(read_file(bit).find("datatype: Bit"), std::string::npos);
    EXPECT_EQ(read_image(bit).values, src.values);
    EXPECT_EQ(read_image(u8).values, src.values);

    // Intensity scaling, checked against MRtrix's own reading (mrconvert to
    // float32, then mrdump):
    // integer data is scaled, float data is used as stored. The "scaling:"
    // line goes into .mif headers written by mrconvert.
    SourceImage raw;
    raw.dims = {4, 3, 2};
    raw.fill([](auto i, auto j, auto k, auto) { return float(i + 4 * j + 12 * k); });
    raw.write_mif(dir_.file("raw.mif"));
    for (const std::string type : {"int16", "uint8", "float32"}) {
        const std::string plain = dir_.file("plain-" + type + ".mif"), scaled = dir_.file("scaled-" + type + ".mif");
        ASSERT_TRUE(mrconvert(dir_.file("raw.mif"), plain, "-datatype " + type));
        std::string text = read_file(plain);
        const std::size_t file_line = text.find("\nfile: . ") + 1;
        const std::size_t data = std::stoul(text.substr(file_line + 8));
        std::string header = text.substr(0, file_line) + "scaling: -3,0.5\n";
        // "file: . N\nEND\n" where N is where that line ends: the width of N that fits.
        for (std::size_t width = 1; width < 8; ++width) {
            const std::size_t end = header.size() + 8 + width + 5;
            if (std::to_string(end).size() == width) {
                header += "file: . " + std::to_string(end) + "\nEND\n";
                break;
            }
        }
        write_file(scaled, header + text.substr(data));
        // MRtrix's values, through float32 (mrdump alone prints in the stored type).
        const std::string as_float = dir_.file("as-float-" + type + ".mif");
        ASSERT_TRUE(mrconvert(scaled, as_float, "-datatype float32"));
        const auto reference = run_command("mrdump " + as_float + " 2>&1");
        ASSERT_EQ(reference.status, 0) << reference.output;
        std::istringstream in(reference.output);
        std::vector<float> expected;
        for (float v; in >> v;) expected.push_back(v);
        const bool integer = type != "float32";
        ASSERT_EQ(expected.size(), raw.values.size()) << type;
        EXPECT_EQ(expected[5], integer ? -3.0f + 0.5f * raw.values[5] : raw.values[5]) << "MRtrix reads " << type;
        EXPECT_EQ(read_image(scaled).values, expected) << scaled;
        const std::string nii = dir_.file("scaled-" + type + ".nii");  // scl_slope / scl_inter
        ASSERT_TRUE(mrconvert(scaled, nii, "-datatype " + type));
        EXPECT_EQ(read_image(nii).values, expected) << nii;
    }
}

TEST_F(ImageReader, NiftiQformOnlyAndNoTransform) {
    // mrconvert writes both sform and qform; with the sform code cleared the
    // qform must give the same geometry (as MRtrix reads it).
    const SourceImage src = oblique_source({4, 3, 2});
    const std::string source = dir_.file("s.mif"), nii = dir_.file("s.nii");
    src.write_mif(source);
    ASSERT_TRUE(mrconvert(source, nii));
    std::string bytes = read_file(nii);
    const std::size_t sform_code = 254;  // NIfTI-1 header offset of sform_code (int16)
    ASSERT_EQ(bytes[sform_code], 1);
    bytes[sform_code] = 0;
    const std::string qform_only = dir_.file("qform.nii");
    write_file(qform_only, bytes);
    expect_affine_near(read_image(qform_only).voxel_to_world, src.voxel_to_world(), 1e-4, "qform only");
    if (const auto mr = mrinfo_voxel_to_world(qform_only))
        expect_affine_near(read_image(qform_only).voxel_to_world, *mr, 1e-5, "qform only vs mrinfo");

    // Neither: MRtrix's default, the grid centred on the origin.
    const std::size_t qform_code = 252;
    bytes[qform_code] = 0;
    const std::string none = dir_.file("none.nii");
    write_file(none, bytes);
    const auto mr = mrinfo_voxel_to_world(none);
    ASSERT_TRUE(mr);
    expect_affine_near(read_image(none).voxel_to_world, *mr, 1e-6, "no transform vs mrinfo");
}

// What `fn` writes to the process's stderr (file descriptor 2).
std::string stderr_of(const std::function<void()>& fn) {
    std::fflush(stderr);
    const int saved = ::dup(2);
    std::FILE* capture = std::tmpfile();
    ::dup2(fileno(capture), 2);
    fn();
    std::fflush(stderr);
    ::dup2(saved, 2);
    ::close(saved);
    std::string out;
    std::rewind(capture);
    for (int c; (c = std::fgetc(capture)) != EOF;) out += char(c);
    std::fclose(capture);
    return out;
}

TEST_F(ImageReader, MalformedImagesAreRefused) {
    const SourceImage src = oblique_source({6, 5, 4});
    const std::string source = dir_.file("good.mif"), nii = dir_.file("good.nii"), gz = dir_.file("good.nii.gz");
    src.write_mif(source);
    ASSERT_TRUE(mrconvert(source, nii));
    ASSERT_TRUE(mrconvert(source, gz));
    const std::string good_nii = read_file(nii), good_mif = read_file(source), good_gz = read_file(gz);

    auto variant = [&](const std::string& name, const std::string& bytes) {
        const std::string path = dir_.file(name);
        write_file(path, bytes);
        return path;
    };
    auto mif_with = [&](const std::string& from, const std::string& to) {
        std::string t = good_mif;
        t.replace(t.find(from), from.size(), to);
        return t;
    };
    const std::vector<std::pair<std::string, std::string>> malformed = {
        {"truncated.nii", good_nii.substr(0, good_nii.size() - 40)},
        {"header-only.nii", good_nii.substr(0, 200)},
        {"garbage.nii", std::string(2000, '\x7f')},
        {"zero-axis.nii", good_nii.substr(0, 44) + std::string(2, '\0') + good_nii.substr(46)},  // dim[2] = 0
        {"truncated.nii.gz", good_gz.substr(0, good_gz.size() / 2)},
        {"truncated.mif", good_mif.substr(0, good_mif.size() - 4)},
        {"no-end.mif", good_mif.substr(0, good_mif.find("END"))},
        {"bad-magic.mif", "mrtrix imagex\n" + good_mif.substr(13)},
        {"no-dim.mif", mif_with("dim: 6,5,4", "dims: 6,5,4")},
        {"bad-dim.mif", mif_with("dim: 6,5,4", "dim: 6,0,4")},
        {"bad-layout.mif", mif_with("layout: +0,+1,+2", "layout: +0,+0,+2")},
        {"short-layout.mif", mif_with("layout: +0,+1,+2", "layout: +0,+1")},
        {"bad-type.mif", mif_with("datatype: Float32LE", "datatype: Float33LE")},
        {"bad-vox.mif", mif_with("vox: 1.5,2,2.5", "vox: 1.5,x,2.5")},
        {"singular.mif", mif_with("transform: ", "transform: 0,0,0,0\ntransform: ")},
    };
    for (const auto& [name, bytes] : malformed) {
        const std::string path = variant(name, bytes);
        EXPECT_EQ(error_of([&] { read_image(path); }), Errc::image_format) << name;
    }
    // Said by fiblet in its error, not by libnifti on stderr ("** ERROR: ... bad dim[2]").
    std::string message;
    const std::string printed = stderr_of([&] {
        try {
            read_image(dir_.file("zero-axis.nii"));
        } catch (const Error& e) {
            message = e.what();
        }
    });
    EXPECT_NE(message.find("dim[2] is 0"), std::string::npos) << message;
    EXPECT_EQ(printed, "");
    EXPECT_EQ(error_of([&] { read_image(dir_.file("missing.nii")); }), Errc::io);
    EXPECT_EQ(error_of([&] { read_image(dir_.file("missing.mif")); }), Errc::io);
    EXPECT_EQ(error_of([&] { read_image(variant("image.png", "x")); }), Errc::unsupported);
    EXPECT_EQ(error_of([&] { read_image(variant("image.mif.gz", "x")); }), Errc::unsupported);
    const std::string complex_mif = dir_.file("complex.mif");
    ASSERT_TRUE(mrconvert(source, complex_mif, "-datatype cfloat32"));
    EXPECT_EQ(error_of([&] { read_image(complex_mif); }), Errc::unsupported);
    const std::string complex_nii = dir_.file("complex.nii");
    ASSERT_TRUE(mrconvert(source, complex_nii, "-datatype cfloat32"));
    EXPECT_EQ(error_of([&] { read_image(complex_nii); }), Errc::unsupported);
}

// Damaged images (cut anywhere, header bytes changed) are read or refused
// with a fiblet::Error, never a crash, a hang or another exception.
TEST_F(ImageReader, DamagedImagesThrowOnlyFibletErrors) {
    const SourceImage src = oblique_source({6, 5, 4, 2});
    const std::string source = dir_.file("good.mif");
    src.write_mif(source);
    std::mt19937 rng(5);
    for (const std::string name : {"good.nii", "good2.nii", "good.nii.gz", "strided.mif"}) {
        const std::string path = dir_.file(name);
        if (name == "good2.nii") ASSERT_TRUE(mrconvert(source, path, "-config NIfTIAlwaysUseVer2 true"));
        else if (name == "strided.mif") ASSERT_TRUE(mrconvert(source, path, "-strides -3,1,-2,4 -datatype int16be"));
        else ASSERT_TRUE(mrconvert(source, path));
        const std::string good = read_file(path);
        const std::size_t header = name.ends_with(".mif") ? good.find("END") + 4 : std::min<std::size_t>(good.size(), 560);
        auto survives = [&](const std::string& bytes, const std::string& what) {
            const std::string damaged = dir_.file("damaged-" + name);
            write_file(damaged, bytes);
            try {
                read_image(damaged);
            } catch (const Error&) {
            } catch (const std::exception& e) {
                ADD_FAILURE() << what << ": " << e.what();
            }
        };
        for (std::size_t cut = 0; cut < good.size(); cut += 1 + good.size() / 97) survives(good.substr(0, cut), name + " cut");
        for (int n = 0; n < 300; ++n) {
            std::string bad = good;
            const std::size_t at = std::uniform_int_distribution<std::size_t>(0, header - 1)(rng);
            bad[at] = char(std::uniform_int_distribution<int>(0, 255)(rng));
            survives(bad, name + " byte " + std::to_string(at));
        }
    }
}

}  // namespace
