// fiblet_bench_table: one row of the rate-distortion-speed table per run
// (scripts/bench_table.sh runs each row in its own process, so that the peak
// RSS it prints is that row's). Prints one JSON object.
//
//   decode FILE.fft [--decoder NAME] [--threads N] [--repeat R] [--cold 1] [--chunk-blocks B]
//       every fiber of the file decoded into float32 xyz + offsets, into
//       buffers allocated (and touched) beforehand: best of R. --cold 1
//       drops the file from the page cache before each run (read from disk).
//   tck-parse FILE.tck [--repeat R] [--cold 1]   fiblet's TckReader, into memory
//   zstd FILE.tck --level L [--repeat R] the .tck through libzstd (one thread)
//   float16 FILE.tck [--repeat R]        positions rounded to half precision
//   sequential FILE.tck [--repeat R]     fiblet recurrence over whole fibers
//   floor FILE.fft [--threads N] [--repeat R]
//       what N threads of the pool can do at all on this machine, for the
//       decode row's output size (12 bytes a point + 8 a fiber): write it
//       into fresh memory (first-touch page faults; 4 kB pages and
//       MADV_HUGEPAGE), into memory faulted in beforehand (store
//       bandwidth), and a register-only loop of fixed work (compute).
//       Each split into 4 tasks a thread, as decode splits its chunks.
//
// Decode timings of the .tck-based baselines include parsing the .tck (the
// zstd row: decompression + the tck-parse time, measured in the same run).
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>
#include <time.h>
#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/parallel.hpp"

namespace fb = fiblet::bench;
using namespace fiblet;

namespace {

double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Best wall-clock time of `repeat` runs; `cpu` gets the least process CPU
// time of a run (all threads), which on a loaded machine is closer to what
// a quiet one would show for one thread.
double best_seconds(int repeat, const std::function<void()>& run, double* cpu = nullptr) {
    double best = std::numeric_limits<double>::infinity(), best_cpu = best;
    for (int i = 0; i < std::max(repeat, 1); ++i) {
        const double c0 = process_cpu_seconds();
        const auto t0 = std::chrono::steady_clock::now();
        run();
        best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        best_cpu = std::min(best_cpu, process_cpu_seconds() - c0);
    }
    if (cpu) *cpu = best_cpu;
    return best;
}

// Drops a file's pages from the page cache (clean pages only), so that the
// next read comes from the disk: the "cold" rows.
void evict(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) throw std::runtime_error("cannot open " + path);
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    ::close(fd);
}

long peak_rss_kib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
}

std::string read_bytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot read " + path);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// Minimal JSON object, keys in order.
struct Json {
    std::string body;
    Json& num(const char* k, double v) {
        char b[64];
        std::snprintf(b, sizeof b, "%.9g", v);
        return raw(k, b);
    }
    Json& str(const char* k, const std::string& v) { return raw(k, "\"" + v + "\""); }
    Json& raw(const char* k, const std::string& v) {
        body += (body.empty() ? "{" : ", ") + std::string("\"") + k + "\": " + v;
        return *this;
    }
    void print() const { std::printf("%s}\n", body.c_str()); }
};

void decode_row(const std::string& path, const std::map<std::string, std::string>& opt, int repeat, bool cold) {
    const FftFile file(path);
    const FftHeader& h = file.header();
    DecodeOptions o;
    o.decoder = parse_decoder(opt.count("decoder") ? opt.at("decoder") : "auto");
    o.threads = opt.count("threads") ? unsigned(std::stoul(opt.at("threads"))) : 0;
    if (opt.count("chunk-blocks")) o.chunk_blocks = std::stoul(opt.at("chunk-blocks"));
    std::vector<float> xyz(3 * h.points, 1.0f);  // touched: no page faults in the timing
    std::vector<std::uint64_t> offsets(h.fibers + 1, 1);
    std::uint64_t points = 0;
    double cpu = 0;
    const double s =
        best_seconds(repeat, [&] {
            if (cold) evict(path);
            points = decode_fibers_into(file, 0, h.fibers, xyz, offsets, o);
        }, &cpu);
    Json()
        .str("row", "decode")
        .str("decoder", decoder_name(o.decoder))
        .num("cold", cold)
        .num("threads", o.threads)
        .num("points", double(points))
        .num("fibers", double(h.fibers))
        .num("bytes", double(file.file_size()))
        .num("decode_seconds", s)
        .num("decode_cpu_seconds", cpu)
        .num("peak_rss_kib", double(peak_rss_kib()))
        .print();
}

void tck_parse_row(const std::string& path, int repeat, bool cold) {
    fb::Tractogram t;
    fb::read_tck(path, t);  // allocates the storage once
    double cpu = 0;
    const double s = best_seconds(repeat, [&] {
        if (cold) evict(path);
        fb::read_tck(path, t);
    }, &cpu);
    Json()
        .str("row", "tck-parse")
        .num("cold", cold)
        .num("points", double(t.points()))
        .num("fibers", double(t.fibers()))
        .num("bytes", double(read_bytes(path).size()))
        .num("decode_seconds", s)
        .num("decode_cpu_seconds", cpu)
        .num("peak_rss_kib", double(peak_rss_kib()))
        .print();
}

void zstd_row(const std::string& path, int level, int repeat) {
    const std::string raw = read_bytes(path);
    std::vector<char> packed(ZSTD_compressBound(raw.size()));
    std::size_t size = 0;
    const auto t0 = std::chrono::steady_clock::now();
    size = ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), level);
    const double encode = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (ZSTD_isError(size)) throw std::runtime_error(ZSTD_getErrorName(size));
    std::vector<char> back(raw.size(), 1);
    double unpack_cpu = 0, parse_cpu = 0;
    const double unpack = best_seconds(
        repeat,
        [&] {
            const std::size_t n = ZSTD_decompress(back.data(), back.size(), packed.data(), size);
            if (ZSTD_isError(n) || n != raw.size()) throw std::runtime_error("zstd round trip failed");
        },
        &unpack_cpu);
    if (!std::equal(back.begin(), back.end(), raw.begin())) throw std::runtime_error("zstd round trip differs");
    fb::Tractogram t;
    fb::read_tck(path, t);
    const double parse = best_seconds(repeat, [&] { fb::read_tck(path, t); }, &parse_cpu);
    Json()
        .str("row", "zstd")
        .num("level", level)
        .num("points", double(t.points()))
        .num("fibers", double(t.fibers()))
        .num("bytes", double(size))
        .num("encode_seconds", encode)
        .num("decompress_seconds", unpack)
        .num("parse_seconds", parse)
        .num("decode_seconds", unpack + parse)
        .num("decode_cpu_seconds", unpack_cpu + parse_cpu)
        .num("peak_rss_kib", double(peak_rss_kib()))
        .print();
}

// One row of a lossy baseline decoded in memory: size, speeds and errors.
void print_lossy_row(const char* row, const fb::Tractogram& t, double bytes, double encode, double decode,
                     double decode_cpu, const fb::PointErrors& e) {
    Json()
        .str("row", row)
        .num("points", double(t.points()))
        .num("fibers", double(t.fibers()))
        .num("bytes", bytes)
        .num("encode_seconds", encode)
        .num("decode_seconds", decode)
        .num("decode_cpu_seconds", decode_cpu)
        .num("max_error_um", e.max_mm * 1e3)
        .num("mean_error_um", e.mean_mm * 1e3)
        .num("peak_rss_kib", double(peak_rss_kib()))
        .print();
}

void float16_row(const std::string& path, int repeat) {
    fb::Tractogram t;
    fb::read_tck(path, t);
    std::vector<std::uint16_t> half(t.xyz.size(), 1);
    const double encode = best_seconds(repeat, [&] { fb::to_half(t.xyz.data(), half.data(), t.xyz.size()); });
    std::vector<float> back(t.xyz.size(), 1.0f);
    double cpu = 0;
    const double decode = best_seconds(repeat, [&] { fb::from_half(half.data(), back.data(), half.size()); }, &cpu);
    const fb::PointErrors e = fb::point_errors(t.xyz, back);
    print_lossy_row("float16", t, double(2 * half.size() + 8 * t.offsets.size()),  // + uint64 offsets, as TRX
                    encode, decode, cpu, e);
}

void sequential_row(const std::string& path, int repeat) {
    fb::Tractogram t;
    fb::read_tck(path, t);
    fb::SequentialCoded coded;
    const double encode = best_seconds(1, [&] { coded = fb::encode_sequential(t); });
    std::vector<float> back(t.xyz.size(), 1.0f);
    double cpu = 0;
    const double decode = best_seconds(repeat, [&] { fb::decode_sequential(coded, back.data()); }, &cpu);
    const fb::PointErrors e = fb::point_errors(t.xyz, back);
    print_lossy_row("sequential", t, double(coded.bytes.size()), encode, decode, cpu, e);
}

// Anonymous memory mapped without touching it (the pages fault in on first write).
class FreshMemory {
public:
    FreshMemory(std::size_t bytes, bool huge) : bytes_(bytes) {
        p_ = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p_ == MAP_FAILED) throw std::runtime_error("mmap failed");
        if (huge) ::madvise(p_, bytes, MADV_HUGEPAGE);
    }
    ~FreshMemory() { ::munmap(p_, bytes_); }
    FreshMemory(const FreshMemory&) = delete;
    FreshMemory& operator=(const FreshMemory&) = delete;
    std::uint8_t* data() const { return static_cast<std::uint8_t*>(p_); }

private:
    void* p_;
    std::size_t bytes_;
};

// Writes `bytes` at p on `threads` threads, 4 contiguous tasks a thread.
void parallel_fill(std::uint8_t* p, std::size_t bytes, unsigned threads) {
    const std::size_t tasks = 4 * std::size_t(threads);
    parallel_for(tasks, threads, [&](std::size_t t) {
        const std::size_t a = bytes * t / tasks, b = bytes * (t + 1) / tasks;
        std::memset(p + a, int(t + 1), b - a);
    });
}

// A fixed amount of register-only work (four multiply-xorshift chains), split like the fills.
std::uint64_t parallel_compute(std::uint64_t steps, unsigned threads) {
    const std::size_t tasks = 4 * std::size_t(threads);
    std::vector<std::uint64_t> out(tasks);
    parallel_for(tasks, threads, [&](std::size_t t) {
        std::uint64_t x[4] = {t + 1, t + 2, t + 3, t + 4};
        for (std::uint64_t i = steps / tasks; i > 0; --i)
            for (std::uint64_t& v : x) v = (v ^ (v >> 29)) * 0xbf58476d1ce4e5b9u + 1;
        out[t] = x[0] ^ x[1] ^ x[2] ^ x[3];
    });
    std::uint64_t r = 0;
    for (const std::uint64_t v : out) r ^= v;
    return r;
}

void floor_row(const std::string& path, const std::map<std::string, std::string>& opt, int repeat) {
    const FftHeader h = FftFile(path).header();
    const unsigned threads = opt.count("threads") ? unsigned(std::stoul(opt.at("threads"))) : 1;
    const std::size_t bytes = 12 * std::size_t(h.points) + 8 * (std::size_t(h.fibers) + 1);
    double fresh_cpu = 0, huge_cpu = 0, touched_cpu = 0, compute_cpu = 0;
    const double fresh = best_seconds(repeat, [&] {
        FreshMemory m(bytes, false);
        parallel_fill(m.data(), bytes, threads);
    }, &fresh_cpu);
    const double huge = best_seconds(repeat, [&] {
        FreshMemory m(bytes, true);
        parallel_fill(m.data(), bytes, threads);
    }, &huge_cpu);
    FreshMemory touched_memory(bytes, false);
    std::memset(touched_memory.data(), 1, bytes);
    const double touched =
        best_seconds(repeat, [&] { parallel_fill(touched_memory.data(), bytes, threads); }, &touched_cpu);
    std::uint64_t sink = 0;
    const double compute = best_seconds(repeat, [&] { sink ^= parallel_compute(std::uint64_t{1} << 27, threads); },
                                        &compute_cpu);
    Json()
        .str("row", "floor")
        .num("threads", threads)
        .num("bytes", double(bytes))
        .num("fresh_seconds", fresh)  // the munmap of the fresh mappings is timed too
        .num("fresh_cpu_seconds", fresh_cpu)
        .num("fresh_huge_seconds", huge)
        .num("fresh_huge_cpu_seconds", huge_cpu)
        .num("touched_seconds", touched)
        .num("touched_cpu_seconds", touched_cpu)
        .num("compute_seconds", compute)
        .num("compute_cpu_seconds", compute_cpu)
        .num("compute_result", double(sink & 0xffff))  // keeps the loop
        .print();
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s decode|tck-parse|zstd|float16|sequential|floor FILE [--option value ...]\n", argv[0]);
        return 2;
    }
    const std::string mode = argv[1], path = argv[2];
    std::map<std::string, std::string> opt;
    for (int i = 3; i + 1 < argc; i += 2) {
        std::string key = argv[i];
        if (key.rfind("--", 0) != 0) {
            std::fprintf(stderr, "bad option %s\n", argv[i]);
            return 2;
        }
        opt[key.substr(2)] = argv[i + 1];
    }
    const int repeat = opt.count("repeat") ? std::stoi(opt["repeat"]) : 5;
    const bool cold = opt.count("cold") && opt["cold"] != "0";
    try {
        if (mode == "decode") decode_row(path, opt, repeat, cold);
        else if (mode == "tck-parse") tck_parse_row(path, repeat, cold);
        else if (mode == "zstd") zstd_row(path, opt.count("level") ? std::stoi(opt["level"]) : 3, repeat);
        else if (mode == "float16") float16_row(path, repeat);
        else if (mode == "sequential") sequential_row(path, repeat);
        else if (mode == "floor") floor_row(path, opt, repeat);
        else {
            std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
            return 2;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fiblet_bench_table: %s\n", e.what());
        return 1;
    }
    return 0;
}
