// TRX files from a zip archive (libzip) or a directory.
#include "tractogram/trx/trx_archive.hpp"

#include <zip.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "fiblet/error.hpp"

namespace fiblet::detail {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void bad(const std::string& path, const std::string& what) {
    throw Error(Errc::trx_format, path + ": not a valid TRX file: " + what);
}

class ZipStream final : public TrxEntryStream {
public:
    ZipStream(zip_file_t* f, std::string label) : f_(f), label_(std::move(label)) {}
    ~ZipStream() override { zip_fclose(f_); }
    void read(void* out, std::size_t size) override {
        auto* p = static_cast<std::uint8_t*>(out);
        while (size > 0) {
            const zip_int64_t got = zip_fread(f_, p, size);
            if (got < 0) bad(label_, std::string("zip read failed: ") + zip_file_strerror(f_));
            if (got == 0) bad(label_, "entry ends early");
            p += got, size -= std::size_t(got);
        }
    }

private:
    zip_file_t* f_;
    std::string label_;
};

class ZipArchive final : public TrxArchive {
public:
    explicit ZipArchive(const std::string& path) : path_(path) {
        int err = 0;
        zip_ = zip_open(path.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &err);
        if (!zip_) {
            zip_error_t e;
            zip_error_init_with_code(&e, err);
            const std::string what = zip_error_strerror(&e);
            zip_error_fini(&e);
            if (err == ZIP_ER_OPEN || err == ZIP_ER_READ) throw Error(Errc::io, path + ": cannot open: " + what);
            bad(path, "not a readable zip archive (" + what + ")");
        }
        std::error_code ec;
        file_size_ = fs::file_size(path, ec);
        if (ec) file_size_ = 0;
    }
    ~ZipArchive() override { zip_discard(zip_); }
    ZipArchive(const ZipArchive&) = delete;
    ZipArchive& operator=(const ZipArchive&) = delete;

    std::vector<std::string> entries() const override {
        std::vector<std::string> names;
        const zip_int64_t n = zip_get_num_entries(zip_, 0);
        for (zip_int64_t i = 0; i < n; ++i) {
            const char* name = zip_get_name(zip_, zip_uint64_t(i), 0);
            if (name && *name && name[std::strlen(name) - 1] != '/') names.emplace_back(name);
        }
        return names;
    }
    // The uncompressed size an entry claims, if the archive can hold it: a
    // central directory may claim anything, and a reader allocates what it claims.
    std::uint64_t size(const std::string& entry) const override {
        const zip_stat_t st = stat(entry);
        if (!(st.valid & ZIP_STAT_COMP_SIZE) || st.comp_size > file_size_ ||
            st.size > kMaxDeflateRatio * st.comp_size + (1u << 20))
            bad(path_, "entry " + entry + " claims " + std::to_string(st.size) + " bytes from " +
                           std::to_string(st.comp_size) + " stored in a " + std::to_string(file_size_) + "-byte archive");
        return st.size;
    }
    std::vector<std::uint8_t> read_all(const std::string& entry) const override {
        std::vector<std::uint8_t> bytes(size(entry));
        if (!bytes.empty()) stream(entry)->read(bytes.data(), bytes.size());
        return bytes;
    }
    std::unique_ptr<TrxEntryStream> stream(const std::string& entry) const override {
        zip_file_t* f = zip_fopen(zip_, entry.c_str(), 0);
        if (!f) bad(path_, "cannot read entry " + entry + ": " + zip_strerror(zip_));
        return std::make_unique<ZipStream>(f, path_ + ":" + entry);
    }

private:
    zip_stat_t stat(const std::string& entry) const {
        zip_stat_t st;
        zip_stat_init(&st);
        if (zip_stat(zip_, entry.c_str(), 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE))
            bad(path_, "no entry " + entry);
        return st;
    }
    static constexpr std::uint64_t kMaxDeflateRatio = 1032;  // deflate's best: 258 bytes from 2 bits
    std::string path_;
    zip_t* zip_ = nullptr;
    std::uint64_t file_size_ = 0;
};

class FileStream final : public TrxEntryStream {
public:
    FileStream(const std::string& path) : in_(path, std::ios::binary), path_(path) {
        if (!in_) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    }
    void read(void* out, std::size_t size) override {
        in_.read(static_cast<char*>(out), std::streamsize(size));
        if (std::size_t(in_.gcount()) != size) bad(path_, "file ends early");
    }

private:
    std::ifstream in_;
    std::string path_;
};

class DirectoryArchive final : public TrxArchive {
public:
    explicit DirectoryArchive(const std::string& path) : root_(path) {}
    std::vector<std::string> entries() const override {
        std::vector<std::string> names;
        std::error_code ec;
        for (fs::recursive_directory_iterator it(root_, ec), end; !ec && it != end; it.increment(ec))
            if (it->is_regular_file()) names.push_back(fs::relative(it->path(), root_).generic_string());
        if (ec) throw Error(Errc::io, root_.string() + ": cannot list: " + ec.message());
        std::sort(names.begin(), names.end());
        return names;
    }
    std::uint64_t size(const std::string& entry) const override {
        std::error_code ec;
        const auto s = fs::file_size(root_ / entry, ec);
        if (ec) throw Error(Errc::io, (root_ / entry).string() + ": " + ec.message());
        return s;
    }
    std::vector<std::uint8_t> read_all(const std::string& entry) const override {
        std::vector<std::uint8_t> bytes(size(entry));
        if (!bytes.empty()) stream(entry)->read(bytes.data(), bytes.size());
        return bytes;
    }
    std::unique_ptr<TrxEntryStream> stream(const std::string& entry) const override {
        return std::make_unique<FileStream>((root_ / entry).string());
    }

private:
    fs::path root_;
};

}  // namespace

std::unique_ptr<TrxArchive> TrxArchive::open(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return std::make_unique<DirectoryArchive>(path);
    return std::make_unique<ZipArchive>(path);
}

std::optional<TrxEntryName> parse_trx_entry_name(const std::string& entry) {
    const auto slash = entry.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "" : entry.substr(0, slash + 1);
    const std::string base = entry.substr(dir.size());
    const auto last = base.find_last_of('.');
    if (last == std::string::npos || last == 0) return std::nullopt;
    TrxEntryName n;
    n.dtype = base.substr(last + 1);
    std::string stem = base.substr(0, last);
    const auto dot = stem.find_last_of('.');
    if (dot != std::string::npos) {
        const std::string count = stem.substr(dot + 1);
        if (!count.empty() && count.size() <= 9 && std::all_of(count.begin(), count.end(), ::isdigit)) {
            n.components = std::uint32_t(std::stoul(count));
            stem = stem.substr(0, dot);
        }
    }
    if (stem.empty() || n.components == 0) return std::nullopt;
    n.name = dir + stem;
    return n;
}

}  // namespace fiblet::detail
