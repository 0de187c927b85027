// Small helpers shared by the tests: temporary directories, shared test data, raw files.
#pragma once

#include <stdlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "fiblet/checksum.hpp"
#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::test {

// ASan builds: their memory use makes RSS bounds meaningless.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

// The category of the fiblet::Error `fn` throws; nullopt when it throws none.
inline std::optional<Errc> error_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.code();
    }
    return std::nullopt;
}

// A fresh directory under /tmp, removed with its contents on destruction.
class TempDir {
public:
    TempDir() {
        std::string tmpl = "/tmp/fiblet-test-XXXXXX";
        if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
        path_ = tmpl;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::string& path() const { return path_; }
    // Path of `name` inside the directory.
    std::string file(const std::string& name) const { return path_ + "/" + name; }

private:
    std::string path_;
};

// Directory of the shared test data (FIBLET_SHARED_DIR "/data").
inline std::string shared_data_dir() { return std::string(FIBLET_SHARED_DIR) + "/data"; }

// Path of a file of the shared test data, e.g. shared_data("conformance/simple.tck").
inline std::string shared_data(const std::string& relpath) { return shared_data_dir() + "/" + relpath; }

inline bool shared_data_available() { return std::filesystem::is_directory(shared_data_dir()); }

// Writes `bytes` to `path` (replacing it).
inline void write_file(const std::string& path, std::string_view bytes) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    if (!f) throw std::runtime_error("cannot write " + path);
}

// Whole content of `path`.
inline std::string read_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot read " + path);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// The value of type T stored at byte `off` of `bytes` (host byte order).
template <class T>
T at(const std::string& bytes, std::size_t off) {
    T v;
    std::memcpy(&v, bytes.data() + off, sizeof v);
    return v;
}

// A small .tck at `path`: straight fibers of 70, 10 and 1 points at a 0.1 mm step.
// Every streamline of a .tck, in file order.
inline std::vector<std::vector<Vec3f>> read_tck_fibers(const std::string& path) {
    TckReader r(path);
    std::vector<std::vector<Vec3f>> all;
    for (std::vector<Vec3f> f; r.next(f);) all.push_back(f);
    return all;
}

inline void write_three_fiber_tck(const std::string& path) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f;
    for (int i = 0; i < 70; ++i) f.push_back({float(i) * 0.1f, 1.0f, 2.0f});
    w.write(f);
    f.resize(10);
    w.write(f);
    f.resize(1);
    w.write(f);
    w.finish();
}

// `fibers` helices of `points` points 0.1 mm apart along z, each turned by
// its index: many blocks over several checksum groups, for reading tests.
inline void write_helix_tck(const std::string& path, int fibers, std::size_t points) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(points);
    for (int i = 0; i < fibers; ++i) {
        for (std::size_t k = 0; k < f.size(); ++k) {
            const float t = 0.02f * float(k);
            f[k] = {10 * std::cos(t + float(i)), 10 * std::sin(t + float(i)), 0.1f * float(k) + 0.01f * float(i)};
        }
        w.write(f);
    }
    w.finish();
}

// `body` (the header, LUT and blocks of a file whose header is `h`), then
// `chunks` and a CSUM chunk that matches it all: what a writer would make of
// them (tests use it to give wrong values a correct checksum).
inline std::string with_checksummed_trailer(const std::string& body, const FftHeader& h,
                                            std::vector<TrailerChunk> chunks) {
    FftChecksumBuilder sums(h.block_bytes());
    sums.add_lut(body.data() + h.lut_offset(), h.blocks_offset() - h.lut_offset());
    sums.add_blocks(body.data() + h.blocks_offset(), h.file_bytes() - h.blocks_offset());
    const auto* head = reinterpret_cast<const std::uint8_t*>(body.data());
    chunks.push_back(sums.finish({head, std::size_t(h.lut_offset())}, chunks));
    const auto trailer = serialize_trailer(chunks, h.file_bytes());
    return body.substr(0, h.file_bytes()) + std::string(trailer.begin(), trailer.end());
}

}  // namespace fiblet::test
