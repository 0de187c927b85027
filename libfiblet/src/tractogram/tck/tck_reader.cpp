// Streaming MRtrix3 .tck reader: reads the data section chunk by chunk with pread().
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <optional>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "tractogram/tck/track_header.hpp"
#include "core/pass_digest.hpp"
#include "core/append_points.hpp"
#include "core/points_avx2.hpp"
#include "core/streamline_label.hpp"
#include "io/open_inputs.hpp"
#include "io/regular_input.hpp"

namespace fiblet {
namespace {

static_assert(sizeof(Vec3f) == 12, "Vec3f must be three packed floats: points are memcpy'd from the file");

constexpr std::uint32_t kExp32 = 0x7f800000u;  // all-ones exponent: Inf or NaN

// 0 or 1 (an integer, so that three results combine with a branch-free |).
inline unsigned nonfinite_bits(std::uint32_t b) { return (b & kExp32) == kExp32; }

#ifdef FIBLET_POINTS_AVX2
// The points of p[0, n) (12-byte float32 triplets) before the first one
// holding a NaN or Inf, eight at a time (three loads of eight floats); the
// scalar test finds it inside the eight.
__attribute__((target("avx2"))) std::size_t finite_run_avx2(const char* p, std::size_t n) {
    const __m256i exponent = _mm256_set1_epi32(std::int32_t(kExp32));
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        __m256i any = _mm256_setzero_si256();
        for (int j = 0; j < 3; ++j) {
            const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 12 * i + 32 * j));
            any = _mm256_or_si256(any, _mm256_cmpeq_epi32(_mm256_and_si256(v, exponent), exponent));
        }
        if (!_mm256_testz_si256(any, any)) break;
    }
    return i;
}
#endif

enum class Kind { point, separator, end, bad };

// A triplet is a point (all finite), a streamline separator (all NaN), the end of
// the data (all Inf, either sign: MATLAB writes -Inf), or malformed.
inline Kind classify(int n_nan, int n_inf) {
    if (n_nan == 0 && n_inf == 0) return Kind::point;
    if (n_nan == 3) return Kind::separator;
    if (n_inf == 3) return Kind::end;
    return Kind::bad;
}

// Decodes one triplet of any datatype into doubles (float32 converts exactly).
inline void decode_triplet(const char* p, TckDataType t, double out[3]) {
    for (int i = 0; i < 3; ++i) out[i] = detail::decode_track_value(p + i * tck_datatype_size(t), t);
}

}  // namespace

struct TckReader::Impl {
    std::string path;
    TckReadOptions options;
    TckHeader header;
    int fd = -1;
    std::size_t triplet = 12;
    std::uint64_t data_begin = 0, data_end = 0;
    std::uint64_t next_read = 0;  // file offset of the next chunk
    // Chunks are whole multiples of the triplet size, so only the last one can
    // end inside a point: no triplet ever straddles two chunks.
    // Held as points, read and parsed as bytes: a float32le run is then
    // appended to a fiber as the points it is (no zero-filled resize first;
    // runs start at multiples of 12 bytes).
    std::unique_ptr<Vec3f[]> chunk_points;
    char* chunk() const { return reinterpret_cast<char*>(chunk_points.get()); }
    std::size_t chunk_cap = 0, chunk_len = 0, chunk_pos = 0;
    std::uint64_t streamlines = 0, points = 0;
    bool at_end = false;  // end marker seen (or empty data section)
    detail::InputRegistration input;  // no output of this process may replace the file
    // Multi-pass readers (compress) must see the same data on every pass: the
    // file as opened, and each complete pass's bytes and counts (see check_pass).
    struct stat opened {};
    detail::PassDigest pass_hash;
    struct Pass {
        std::uint64_t digest, streamlines, points;
    };
    std::optional<Pass> first_pass;
    bool pass_checked = false;

    ~Impl() {
        if (fd >= 0) ::close(fd);
    }

    std::uint64_t consumed() const { return (next_read - data_begin) - (chunk_len - chunk_pos); }
    std::uint64_t file_pos() const { return data_begin + consumed(); }

    [[noreturn]] void changed(const std::string& how) const {
        throw Error(Errc::io, path + ": the file changed while it was being read (" + how +
                                  "): it is being written or was replaced; read it again once it is complete");
    }

    [[noreturn]] void fail(const std::string& what) const {
        throw Error(Errc::tck_format, path + ": invalid .tck data: " + what);
    }

    [[noreturn]] void fail_bad_triplet() const {
        fail("NaN/Inf inside a coordinate at " + detail::streamline_label(streamlines) + ", byte " + std::to_string(file_pos()));
    }

    void check_count() const {
        if (options.allow_count_mismatch) return;
        const auto c = header.count();
        if (c && *c != streamlines)
            throw Error(Errc::tck_format,
                        path + ": header says count: " + std::to_string(*c) + " but the data holds " +
                            std::to_string(streamlines) + " streamlines (truncated or edited file?)",
                        Remedy::allow_count_mismatch);
    }

    void check_length(const std::vector<Vec3f>& out) const {
        if (options.max_points && out.size() > options.max_points)
            throw Error(Errc::unsupported, path + ": " + detail::streamline_label(streamlines) + " has more than " +
                                               std::to_string(options.max_points) + " points");
    }

    // Reads the next chunk; false when the data section is exhausted.
    bool refill() {
        if (next_read >= data_end) return false;
        if (!chunk_points) chunk_points.reset(new Vec3f[(chunk_cap + sizeof(Vec3f) - 1) / sizeof(Vec3f)]);
        const std::size_t want = std::size_t(std::min<std::uint64_t>(chunk_cap, data_end - next_read));
        std::size_t got = 0;
        while (got < want) {
            const ssize_t n = ::pread(fd, chunk() + got, want - got, off_t(next_read + got));
            if (n < 0) {
                if (errno == EINTR) continue;
                throw Error(Errc::io, path + ": read failed: " + std::strerror(errno));
            }
            if (n == 0) break;  // the file shrank under us: treat as its end
            got += std::size_t(n);
        }
        if (got < want) {
            // Shorter than at open: cut by someone else, not a truncated file to diagnose.
            struct stat now {};
            if (::fstat(fd, &now) == 0 && now.st_size != opened.st_size)
                changed("it is " + std::to_string(now.st_size) + " bytes now, " + std::to_string(opened.st_size) +
                        " when opened");
            data_end = next_read + got;
        }
        pass_hash.update(chunk(), got);
        chunk_len = got;
        chunk_pos = 0;
        next_read += got;
        return got > 0;
    }

    // Appends the run of finite float32le points at the cursor; stops at the first special triplet.
    void scan_float32le(std::vector<Vec3f>& out) {
        const char* p = chunk() + chunk_pos;
        const std::size_t n = (chunk_len - chunk_pos) / 12;
        std::size_t i = 0;
#ifdef FIBLET_POINTS_AVX2
        if (detail::use_avx2_loops()) i = finite_run_avx2(p, n);
#endif
        for (; i < n; ++i) {
            std::uint32_t a, b, c;
            std::memcpy(&a, p + 12 * i, 4);
            std::memcpy(&b, p + 12 * i + 4, 4);
            std::memcpy(&c, p + 12 * i + 8, 4);
            if (nonfinite_bits(a) | nonfinite_bits(b) | nonfinite_bits(c)) break;
        }
        if (i == 0) return;
        const Vec3f* run = chunk_points.get() + chunk_pos / sizeof(Vec3f);
        detail::append_points(out, run, i);
        chunk_pos += i * 12;
    }

    // Classifies the triplet at the cursor; for a point, stores it in `v`.
    Kind read_triplet(Vec3f& v) {
        double d[3];
        decode_triplet(chunk() + chunk_pos, header.datatype, d);
        int n_nan = 0, n_inf = 0;
        for (double x : d) n_nan += std::isnan(x), n_inf += std::isinf(x);
        const Kind k = classify(n_nan, n_inf);
        if (k == Kind::point) {
            v = Vec3f{float(d[0]), float(d[1]), float(d[2])};
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw Error(Errc::invalid_input, path + ": coordinate beyond the float32 range at " +
                                                     detail::streamline_label(streamlines) + ", byte " +
                                                     std::to_string(file_pos()));
        }
        return k;
    }

    bool next(std::vector<Vec3f>& out) {
        out.clear();
        if (at_end) {
            end_pass();
            return false;
        }
        const bool fast = header.datatype == TckDataType::float32le;
        for (;;) {
            if (chunk_pos == chunk_len && !refill()) {
                if (data_end == data_begin) {  // no data at all: a file with zero streamlines
                    at_end = true;
                    end_pass();
                    return false;
                }
                fail("no end-of-data marker (Inf triplet) after " + std::to_string(streamlines) +
                     " streamlines (truncated?)");
            }
            if (chunk_len - chunk_pos < triplet)
                fail("truncated in the middle of a point at " + detail::streamline_label(streamlines) + ", byte " + std::to_string(file_pos()));
            if (fast) {
                scan_float32le(out);
                check_length(out);
                if (chunk_len - chunk_pos < triplet) continue;  // run reached the end of the chunk
            }
            Vec3f v;
            const Kind k = read_triplet(v);
            if (k == Kind::bad) fail_bad_triplet();
            chunk_pos += triplet;
            switch (k) {
                case Kind::point:
                    out.push_back(v);
                    check_length(out);
                    break;
                case Kind::separator:
                    ++streamlines;
                    points += out.size();
                    return true;
                case Kind::end:
                    at_end = true;  // anything after the marker is ignored
                    if (!out.empty()) {  // last streamline closed by the marker itself
                        ++streamlines;
                        points += out.size();
                        return true;
                    }
                    end_pass();
                    return false;
                case Kind::bad:
                    break;
            }
        }
    }

    void rewind() {
        next_read = data_begin;
        chunk_len = chunk_pos = 0;
        streamlines = points = 0;
        at_end = false;
        pass_hash.reset();
        pass_checked = false;
    }

    void end_pass() {
        check_count();
        if (pass_checked) return;
        pass_checked = true;
        check_pass();
    }

    // A pass over the data just ended: the file must still be the one opened
    // (size, modification time, inode, also at its path: not replaced), and
    // every pass must read the same bytes as the first one (an edit that
    // keeps size and time, or lands between the checks). Without this, the
    // passes of compress would disagree and write a file verify rejects.
    void check_pass() {
        struct stat now {};
        if (::fstat(fd, &now) != 0 || now.st_size != opened.st_size || now.st_mtim.tv_sec != opened.st_mtim.tv_sec ||
            now.st_mtim.tv_nsec != opened.st_mtim.tv_nsec)
            changed("its size or modification time is not the one it had when opened");
        if (::stat(path.c_str(), &now) != 0 || now.st_ino != opened.st_ino || now.st_dev != opened.st_dev)
            changed("another file now has its name");
        const Pass pass{pass_hash.digest(), streamlines, points};
        if (!first_pass) return void(first_pass = pass);
        if (pass.streamlines != first_pass->streamlines || pass.points != first_pass->points)
            changed("this pass read " + std::to_string(pass.streamlines) + " streamlines and " +
                    std::to_string(pass.points) + " points, the first " + std::to_string(first_pass->streamlines) +
                    " and " + std::to_string(first_pass->points));
        if (pass.digest != first_pass->digest) changed("this pass read other bytes than the first");
    }
};

TckReader::TckReader(const std::string& path, TckReadOptions options) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.path = path;
    m.options = options;
    detail::require_regular_input(path);
    m.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (m.fd < 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    struct stat& st = m.opened;
    if (::fstat(m.fd, &st) != 0) throw Error(Errc::io, path + ": cannot stat: " + std::strerror(errno));
    // The data is read in several passes and by offset: a pipe cannot be.
    if (!S_ISREG(st.st_mode))
        throw Error(Errc::io, path + ": not a regular file (a pipe or a device?): a .tck input is read more than "
                                     "once, save it to a file first");
    m.input = detail::InputRegistration(m.fd);
    m.header = read_tck_header(path);
    if (std::uint64_t(st.st_size) < m.header.data_offset)
        throw Error(Errc::tck_format, path + ": invalid .tck header: data offset is past the end of the file");
    m.triplet = 3 * std::size_t(tck_datatype_size(m.header.datatype));
    m.data_begin = m.next_read = m.header.data_offset;
    m.data_end = std::uint64_t(st.st_size);
    std::size_t cap = std::max(m.triplet, options.chunk_bytes / m.triplet * m.triplet);
    const std::uint64_t data = m.data_end - m.data_begin;
    if (data < cap) cap = std::max<std::size_t>(m.triplet, std::size_t((data + m.triplet - 1) / m.triplet * m.triplet));
    m.chunk_cap = cap;
    ::posix_fadvise(m.fd, off_t(m.data_begin), 0, POSIX_FADV_SEQUENTIAL);
}

TckReader::~TckReader() = default;
TckReader::TckReader(TckReader&&) noexcept = default;
TckReader& TckReader::operator=(TckReader&&) noexcept = default;

const TckHeader& TckReader::header() const { return impl_->header; }
const std::string& TckReader::path() const { return impl_->path; }
bool TckReader::next(std::vector<Vec3f>& points) { return impl_->next(points); }
std::uint64_t TckReader::streamlines_read() const { return impl_->streamlines; }
std::uint64_t TckReader::points_read() const { return impl_->points; }
std::uint64_t TckReader::bytes_consumed() const { return impl_->consumed(); }
std::uint64_t TckReader::data_bytes() const { return impl_->data_end - impl_->data_begin; }
void TckReader::rewind() { impl_->rewind(); }

}  // namespace fiblet
