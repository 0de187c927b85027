// Writes the seed corpora of the fuzz targets (scripts/fuzz.sh runs it):
//   fiblet_fuzz_seeds SHARED_DATA_DIR OUT_DIR
// OUT_DIR/tck_reader_fuzz and compress_fuzz: the small shared .tck files
// (conformance files, valid and invalid, and the real bundles) and hand-made
// edge files;
// OUT_DIR/fft_file_fuzz: those compressed, in several layouts (8- and 16-bit
// codes, both block indexes), with and without the fiblet trailer; OUT_DIR/decode_blocks_fuzz: their blocks with
// the parameters header of that target; OUT_DIR/streamline_source_fuzz: the
// shared .trk files and TRX zips written from them.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/trk.hpp"
#include "fiblet/trx.hpp"

namespace fs = std::filesystem;
using namespace fiblet;

namespace {

constexpr std::size_t kMaxSeedBytes = 16 << 10;  // scripts/fuzz.sh's -max_len

std::string read_file(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

void write_file(const fs::path& p, const std::string& bytes) {
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
}

template <class T>
void append_raw(std::string& s, T v, bool big_endian = false) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    if (big_endian) std::reverse(b, b + sizeof v);
    s.append(b, sizeof v);
}

// A .tck with the given datatype; fibers of xyz triplets; `end` the end marker value.
std::string make_tck(const std::vector<std::vector<double>>& fibers, const std::string& datatype,
                     const std::string& extra_header = "", double end = HUGE_VAL) {
    const bool f64 = datatype.rfind("Float64", 0) == 0, be = datatype.size() > 2 && datatype.substr(datatype.size() - 2) == "BE";
    std::string data;
    auto put = [&](double v) {
        if (f64) append_raw(data, v, be);
        else append_raw(data, float(v), be);
    };
    const double nan = std::nan("");
    for (const auto& f : fibers) {
        for (double v : f) put(v);
        put(nan), put(nan), put(nan);
    }
    put(end), put(end), put(end);
    const std::string head = "mrtrix tracks\n" + extra_header + "datatype: " + datatype + "\nfile: . ";
    std::size_t offset = head.size() + 5 + 1;
    while (std::to_string(offset).size() != offset - head.size() - 5) ++offset;
    return head + std::to_string(offset) + "\nEND\n" + data;
}

std::vector<double> helix(int points, double step, double x0, double bend) {
    std::vector<double> f;
    double x = x0, y = 0, z = 0, a = 0;
    for (int i = 0; i < points; ++i) {
        f.insert(f.end(), {x, y, z});
        a += bend;
        x += step * std::cos(a) * 0.8, y += step * std::sin(a) * 0.8, z += step * 0.6;
    }
    return f;
}

void hand_made_tck(const fs::path& dir) {
    const std::vector<std::vector<double>> small = {helix(5, 0.5, 0, 0.1), helix(1, 0.5, 3, 0), helix(70, 0.5, -2, 0.05)};
    for (const char* dt : {"Float32LE", "Float32BE", "Float64LE", "Float64BE"})
        write_file(dir / (std::string("edge-small-") + dt + ".tck"), make_tck(small, dt, "count: 3\nstep_size: 0.5\n"));
    write_file(dir / "edge-empty-fibers.tck", make_tck({{}, helix(3, 0.1, 0, 0), {}, {}}, "Float32LE"));
    write_file(dir / "edge-single-points.tck", make_tck({{1, 2, 3}, {4, 5, 6}, {1, 2, 3}}, "Float32LE"));
    write_file(dir / "edge-zero-fibers.tck", make_tck({}, "Float32LE", "count: 0\n"));
    write_file(dir / "edge-coincident-points.tck", make_tck({{1, 1, 1, 1, 1, 1, 1, 1, 1}, helix(4, 0.1, 0, 0)}, "Float32LE"));
    write_file(dir / "edge-huge-coordinates.tck",
               make_tck({{-3e38, 0, 0, 3e38, 0, 0}, {0, -3e38, 1e38, 0, 3e38, -1e38}}, "Float32LE"));
    write_file(dir / "edge-float64-beyond-float32.tck", make_tck({{0, 0, 0, 1e300, 0, 0}}, "Float64LE"));
    write_file(dir / "edge-tiny-coordinates.tck", make_tck({{1e-38, 0, 0, 2e-38, 0, 0, 3e-38, 0, 0}}, "Float32LE"));
    write_file(dir / "edge-variable-step.tck",
               make_tck({{0, 0, 0, 0.1, 0, 0, 0.5, 0, 0, 0.55, 0, 0, 1.5, 0, 0}, helix(20, 0.3, 1, 0.2)}, "Float32LE",
                        "step_size: 0.3\n"));
    write_file(dir / "edge-minus-inf-end.tck", make_tck({helix(4, 0.2, 0, 0.1)}, "Float32LE", "", -HUGE_VAL));
    write_file(dir / "edge-count-mismatch.tck", make_tck({helix(4, 0.2, 0, 0.1)}, "Float32LE", "count: 7\n"));
    write_file(dir / "edge-sharp-turns.tck",
               make_tck({{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}}, "Float32LE"));
    std::string partial_nan = make_tck({{0, 0, 0, 1, 0, 0}}, "Float32LE");
    const float nan = std::nanf("");
    std::memcpy(partial_nan.data() + partial_nan.size() - 12 - 12 - 8, &nan, 4);
    write_file(dir / "edge-partial-nan.tck", partial_nan);
    std::string crlf = make_tck({helix(3, 0.2, 0, 0)}, "Float32LE", "method: test\r\ncommand_history: a\nb c\n");
    write_file(dir / "edge-multiline-crlf-header.tck", crlf);
    const std::string good = make_tck(small, "Float32LE");
    write_file(dir / "edge-truncated-mid-point.tck", good.substr(0, good.size() - 17));
}

// Compresses `tck` into `fft` with `options`; false if it fails or is too big.
bool compress_seed(const fs::path& tck, const fs::path& fft, CompressOptions options) {
    options.overwrite = true;
    options.threads = 1;
    try {
        compress_file(tck.string(), fft.string(), options);
    } catch (const Error&) {
        return false;
    }
    if (fs::file_size(fft) > kMaxSeedBytes) {
        fs::remove(fft);
        return false;
    }
    return true;
}

// The decode_blocks_fuzz input closest to a file's parameters (see fuzz_targets.hpp).
std::string blocks_seed(const fs::path& fft) {
    const FftFile f(fft.string(), {.verify_checksums = false});
    const FftHeader& h = f.header();
    auto u16 = [](double v) { return std::uint16_t(std::clamp(std::lround(v), 0l, 65535l)); };
    std::string s;
    if (h.direction_bits() == 16 && h.points_per_block > 129) return {};  // beyond the target's range
    s += char((h.direction_bits() == 16 ? 0x80 : 0) | (h.points_per_block - 2));
    append_raw(s, u16(h.ratio * 32768.0 - 1));
    append_raw(s, u16(h.step * 65536.0));
    append_raw(s, u16((std::log2(h.scaling) + 20.0) / 40.0 * 65536.0));
    for (float o : h.offset)
        append_raw(s, std::int16_t(std::clamp(std::lround(o / h.scaling * 1000.0), -32768l, 32767l)));
    const auto blocks = f.read_blocks(0, h.blocks);
    s.append(reinterpret_cast<const char*>(blocks.data()), std::min(blocks.size(), kMaxSeedBytes));
    return s;
}

// The shared .trk files, and each as a TRX zip (TrxWriter) holding its data.
int trk_and_trx_seeds(const fs::path& shared, const fs::path& dir) {
    fs::create_directories(dir);
    int n = 0;
    if (!fs::is_directory(shared / "conformance")) return n;
    for (const auto& e : fs::directory_iterator(shared / "conformance")) {
        if (e.path().extension() != ".trk") continue;
        fs::copy_file(e.path(), dir / e.path().filename(), fs::copy_options::overwrite_existing);
        TrkReader in(e.path().string());
        std::vector<std::vector<Vec3f>> fibers;
        std::vector<Vec3f> f;
        SinkHeader h;
        while (in.next(f)) fibers.push_back(f), h.points += f.size();
        h.fibers = fibers.size();
        h.fields = in.take_fields();
        h.space = in.header().space;
        TrxWriter out((dir / (e.path().stem().string() + ".trx")).string(), h, true);
        for (const auto& fiber : fibers) out.write(&fiber.data()->x, fiber.size());
        out.finish();
        n += 2;
    }
    return n;
}

// image_fuzz seeds: the first byte picks the name (0 .nii, 1 .nii.gz,
// 2 .mif), the rest is the file: a 2x2x2 float32 NIfTI-1 with an sform, a
// 4-D one, and .mif files with the data inline.
void image_seeds(const fs::path& dir) {
    auto put = [](std::string& b, std::size_t at, const void* v, std::size_t n) { std::memcpy(&b[at], v, n); };
    auto nifti = [&](std::vector<std::int16_t> dims) {
        std::string h(352, '\0');
        const std::int32_t size = 348;
        put(h, 0, &size, 4);
        std::int16_t dim[8] = {std::int16_t(dims.size()), 1, 1, 1, 1, 1, 1, 1};
        std::size_t voxels = 1;
        for (std::size_t i = 0; i < dims.size(); ++i) dim[i + 1] = dims[i], voxels *= std::size_t(dims[i]);
        put(h, 40, dim, sizeof dim);
        const std::int16_t datatype = 16, bitpix = 32, sform = 1;
        put(h, 70, &datatype, 2), put(h, 72, &bitpix, 2), put(h, 254, &sform, 2);
        const float pixdim[8] = {1, 1.5f, 1.5f, 2, 1, 1, 1, 1}, offset = 352, slope = 1;
        put(h, 76, pixdim, sizeof pixdim), put(h, 108, &offset, 4), put(h, 112, &slope, 4);
        const float srow[3][4] = {{1.5f, 0, 0, -10}, {0, 1.5f, 0, 5}, {0, 0, 2, 0}};
        put(h, 280, srow, sizeof srow);
        h.replace(344, 4, std::string("n+1\0", 4));
        for (std::size_t i = 0; i < voxels; ++i) {
            const float v = float(i % 3);
            h.append(reinterpret_cast<const char*>(&v), 4);
        }
        return h;
    };
    auto mif = [](const std::string& dim, const std::string& vox, const std::string& layout, std::size_t voxels) {
        std::string h = "mrtrix image\ndim: " + dim + "\nvox: " + vox + "\nlayout: " + layout +
                        "\ndatatype: Float32LE\ntransform: 1,0,0,0\ntransform: 0,1,0,0\ntransform: 0,0,1,0\nfile: . 256\nEND\n";
        h.resize(256, ' ');
        for (std::size_t i = 0; i < voxels; ++i) {
            const float v = float(i % 2);
            h.append(reinterpret_cast<const char*>(&v), 4);
        }
        return h;
    };
    auto seed = [&](const std::string& name, char format, const std::string& bytes) {
        std::ofstream(dir / name, std::ios::binary) << format << bytes;
    };
    seed("nifti-3d", '\0', nifti({2, 2, 2}));
    seed("nifti-4d", '\0', nifti({2, 2, 2, 3}));
    seed("mif-3d", '\2', mif("2,2,2", "1,1,1", "+0,+1,+2", 8));
    seed("mif-4d-reversed", '\2', mif("2,3,2,2", "1,2,1,1", "-2,+0,+1,+3", 24));
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s SHARED_DATA_DIR OUT_DIR\n", argv[0]);
        return 2;
    }
    const fs::path shared = argv[1], out = argv[2];
    const fs::path tck_dir = out / "tck_reader_fuzz", compress_dir = out / "compress_fuzz", fft_dir = out / "fft_file_fuzz", blocks_dir = out / "decode_blocks_fuzz";
    for (const auto& d : {tck_dir, compress_dir, fft_dir, blocks_dir}) fs::create_directories(d);

    // Small shared files: every conformance .tck, the original-resolution bundles.
    if (fs::is_directory(shared)) {
        for (const auto& e : fs::directory_iterator(shared / "conformance"))
            if (e.path().extension() == ".tck") fs::copy_file(e.path(), tck_dir / ("shared-" + e.path().filename().string()), fs::copy_options::overwrite_existing);
        for (const char* b : {"AF_L", "CC_ForcepsMajor", "CST_R", "cingulum-1", "cingulum-2"})
            fs::copy_file(shared / "bundles" / (std::string(b) + ".tck"), tck_dir / ("shared-" + std::string(b) + ".tck"),
                          fs::copy_options::overwrite_existing);
    } else {
        std::fprintf(stderr, "fiblet_fuzz_seeds: no shared data at %s: hand-made seeds only\n", shared.c_str());
    }
    hand_made_tck(tck_dir);
    fs::create_directories(out / "image_fuzz");
    image_seeds(out / "image_fuzz");

    // .fft seeds: each .tck that compresses, with the default layout and
    // the extreme block sizes; the first also cut after its blocks (a file
    // without the fiblet trailer, as the official encoder writes).
    int n_fft = 0;
    for (const auto& e : fs::directory_iterator(tck_dir)) {
        const std::string stem = e.path().stem().string();
        for (std::uint32_t ppb : {60u, 2u, 63u}) {
            const fs::path fft = fft_dir / (stem + "-ppb" + std::to_string(ppb) + ".fft");
            CompressOptions options;
            options.points_per_block = ppb;
            if (!compress_seed(e.path(), fft, options)) continue;
            ++n_fft;
            if (ppb == 60) {
                const std::string bytes = read_file(fft);
                const FftFile f(fft.string());
                write_file(fft_dir / (stem + "-no-trailer.fft"), bytes.substr(0, f.header().file_bytes()));
                write_file(blocks_dir / (stem + ".blocks"), blocks_seed(fft));
            }
        }
        // The finer block index (formats/fft-index.md: version 4, a box per
        // block, rANS-coded).
        {
            CompressOptions options;
            options.index_format = BlockIndexFormat::block_boxes;
            if (compress_seed(e.path(), fft_dir / (stem + "-fine-index.fft"), options)) ++n_fft;
        }
        // The seekable zstd container (formats/fftz.md), small frames so a
        // seed holds several, transposed and not.
        for (const bool transpose : {true, false}) {
            const fs::path fftz = fft_dir / (stem + (transpose ? "-zstd.fftz" : "-zstd-plain.fftz"));
            CompressOptions options;
            options.zstd = ZstdOptions{.level = 3, .group_blocks = 4, .transpose = transpose};
            if (compress_seed(e.path(), fftz, options)) ++n_fft;
        }
        // The 16-bit variants (formats/fft16.md: packed version 17, with its
        // default and a short block; fixed-size version 16).
        for (std::uint32_t ppb : {0u, 7u, 1u}) {
            const bool fixed = ppb == 1;
            const fs::path fft = fft_dir / (stem + (fixed ? "-16bit-v16" : "-16bit-ppb" + std::to_string(ppb)) + ".fft");
            CompressOptions options;
            options.direction_bits = 16;
            options.points_per_block = fixed ? 0 : ppb;
            options.fixed_blocks16 = fixed;
            if (!compress_seed(e.path(), fft, options)) continue;
            ++n_fft;
            if (const std::string b = blocks_seed(fft); !b.empty() && !fixed)
                write_file(blocks_dir / (stem + "-16bit-ppb" + std::to_string(ppb) + ".blocks"), b);
            if (ppb == 0) {  // packed blocks end where the LUT says: cut there, as without a trailer
                const FftFile f(fft.string());
                write_file(fft_dir / (stem + "-16bit-no-trailer.fft"), read_file(fft).substr(0, f.header().file_bytes()));
            }
        }
    }
    fs::copy(tck_dir, compress_dir, fs::copy_options::overwrite_existing | fs::copy_options::recursive);
    std::printf("fiblet_fuzz_seeds: %zu .tck, %d .fft seeds in %s\n",
                std::size_t(std::distance(fs::directory_iterator(tck_dir), fs::directory_iterator())), n_fft,
                out.c_str());
    std::printf("fiblet_fuzz_seeds: %d .trk/.trx seeds\n", trk_and_trx_seeds(shared, out / "streamline_source_fuzz"));
    // The structure-aware trailer harness starts from the same files.
    fs::copy(fft_dir, out / "fft_trailer_fuzz", fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    return 0;
}
