// Recognising a tractogram file by its first bytes, then by its name.
#include "fiblet/tractogram_format.hpp"
#include "io/regular_input.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string_view>

namespace fiblet {
namespace {

std::string lower_extension(const std::string& path) {
    const auto slash = path.find_last_of('/');
    const std::string base = path.substr(slash == std::string::npos ? 0 : slash + 1);
    const auto dot = base.find_last_of('.');
    if (dot == std::string::npos) return "";
    std::string ext = base.substr(dot);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

bool starts_with(std::string_view head, std::string_view prefix) { return head.substr(0, prefix.size()) == prefix; }

bool is_directory(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

bool file_exists(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

TractogramFormat from_head(std::string_view head) {
    if (starts_with(head, "mrtrix tracks")) return TractogramFormat::tck;
    if (starts_with(head, "mrtrix image")) return TractogramFormat::tck_image;
    if (starts_with(head, "TRACK")) return TractogramFormat::trk;
    if (starts_with(head, "PK\x03\x04") || starts_with(head, "PK\x05\x06")) return TractogramFormat::zip_other;
    if (starts_with(head, "\x1f\x8b")) return TractogramFormat::gzip;
    if (starts_with(head, "# vtk DataFile")) return TractogramFormat::vtk;
    if (starts_with(head, "<?xml") && head.find("VTKFile") != std::string_view::npos) return TractogramFormat::vtp;
    if (starts_with(head, "<VTKFile")) return TractogramFormat::vtp;
    if (head.size() >= 12 && starts_with(head, std::string_view("\x50\x2a\x4d\x18", 4)) && head.substr(8, 4) == "FFTZ")
        return TractogramFormat::fftz;
    // NIfTI-1/2: header size 348 or 540 as the first word.
    if (head.size() >= 4 && (head.substr(0, 4) == std::string_view("\x5c\x01\0\0", 4) ||
                             head.substr(0, 4) == std::string_view("\x1c\x02\0\0", 4)))
        return TractogramFormat::nifti;
    // .fft: no magic, a version byte (2, or 16 for the 16-bit variant) then the header.
    if (head.size() >= 58 && (head[0] == 2 || head[0] == 16)) return TractogramFormat::fft;
    return TractogramFormat::unknown;
}

}  // namespace

TractogramFormat format_from_extension(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".tck") return TractogramFormat::tck;
    if (ext == ".trk") return TractogramFormat::trk;
    if (ext == ".trx") return TractogramFormat::trx;
    if (ext == ".fft") return TractogramFormat::fft;
    if (ext == ".fftz") return TractogramFormat::fftz;
    if (ext == ".vtk") return TractogramFormat::vtk;
    if (ext == ".vtp") return TractogramFormat::vtp;
    if (ext == ".mif" || ext == ".mih") return TractogramFormat::tck_image;
    if (ext == ".nii") return TractogramFormat::nifti;
    if (ext == ".gz") return TractogramFormat::gzip;
    return TractogramFormat::unknown;
}

TractogramFormat detect_tractogram_format(const std::string& path) {
    if (is_directory(path))
        return file_exists(path + "/header.json") ? TractogramFormat::trx : TractogramFormat::unknown;
    if (!detail::is_regular_input(path)) return TractogramFormat::unknown;  // never opened: no hang, nothing consumed
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return TractogramFormat::unknown;
    std::array<char, 64> buf{};
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), f);
    std::fclose(f);
    TractogramFormat t = from_head(std::string_view(buf.data(), n));
    // A zip is TRX when it is named so or holds header.json (the reader checks).
    if (t == TractogramFormat::zip_other && lower_extension(path) == ".trx") t = TractogramFormat::trx;
    if (t == TractogramFormat::unknown && n == 0) t = format_from_extension(path);
    return t;
}

std::uint64_t tractogram_bytes(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(path, ec)) {
        const auto n = fs::file_size(path, ec);
        return ec ? 0 : n;
    }
    std::uint64_t total = 0;
    for (fs::recursive_directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec)) total += it->file_size(ec);
    return total;
}

const char* tractogram_format_description(TractogramFormat f) noexcept {
    switch (f) {
        case TractogramFormat::tck: return "an MRtrix3 .tck tractogram";
        case TractogramFormat::trk: return "a TrackVis .trk tractogram";
        case TractogramFormat::trx: return "a TRX tractogram";
        case TractogramFormat::fft: return "a fiblet .fft file";
        case TractogramFormat::fftz: return "a zstd-compressed fiblet .fft file";
        case TractogramFormat::vtk: return "a VTK legacy file";
        case TractogramFormat::vtp: return "a VTK XML file";
        case TractogramFormat::tck_image: return "an MRtrix3 image (.mif/.mih), not a tractogram";
        case TractogramFormat::nifti: return "a NIfTI image, not a tractogram";
        case TractogramFormat::gzip: return "a gzip-compressed file (decompress it first)";
        case TractogramFormat::zip_other: return "a zip archive without TRX's header.json";
        case TractogramFormat::unknown: return "a file of unknown format";
    }
    return "a file of unknown format";
}

bool is_streamline_format(TractogramFormat f) noexcept {
    return f == TractogramFormat::tck || f == TractogramFormat::trk || f == TractogramFormat::trx;
}

}  // namespace fiblet
