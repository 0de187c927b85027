// Choosing the reader or writer for a file: by content for inputs, by
// extension for outputs. The .tck reader and writer are adapted here.
#include "fiblet/streamline_io.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/trk.hpp"
#include "fiblet/trx.hpp"
#include "io/regular_input.hpp"

namespace fiblet {
namespace {

class TckSource final : public StreamlineSource {
public:
    TckSource(const std::string& path, const SourceOptions& o)
        : reader_(path, {.allow_count_mismatch = o.allow_count_mismatch, .max_points = o.max_points}) {}
    TractogramFormat format() const override { return TractogramFormat::tck; }
    const std::string& path() const override { return reader_.path(); }
    Properties properties() const override { return reader_.header().properties; }
    std::optional<double> step_size() const override { return reader_.header().step_size(); }
    bool next(std::vector<Vec3f>& points) override { return reader_.next(points); }
    void rewind() override { reader_.rewind(); }
    std::uint64_t bytes_consumed() const override { return reader_.bytes_consumed(); }
    std::uint64_t data_bytes() const override { return reader_.data_bytes(); }

private:
    TckReader reader_;
};

class TckSink final : public StreamlineSink {
public:
    TckSink(const std::string& path, const SinkHeader& h, bool overwrite) : writer_(path, h.properties, overwrite) {}
    void write(const float* xyz, std::size_t n) override { writer_.write(xyz, n); }
    void write_chunk(const float* xyz, std::span<const std::uint64_t> offsets) override {
        writer_.write_chunk(xyz, offsets);
    }
    void write_finite_chunk(const float* xyz, std::span<const std::uint64_t> offsets) override {
        writer_.write_finite_chunk(xyz, offsets);
    }
    bool refuses_non_finite() const override { return true; }
    void finish() override { writer_.finish(); }

private:
    TckWriter writer_;
};

// An input that cannot be opened is an I/O error (errno's text), not a format.
void check_readable(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    if (S_ISDIR(st.st_mode))
        throw Error(Errc::io, path + ": is a directory (a TRX directory holds header.json)");
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    std::fclose(f);
}

}  // namespace

std::unique_ptr<StreamlineSource> open_streamline_source(const std::string& path, const SourceOptions& options) {
    detail::require_regular_input(path, true);
    TractogramFormat f = detect_tractogram_format(path);
    if (f == TractogramFormat::unknown) {
        check_readable(path);
        // Content of no known kind: the reader its name asks for says what is wrong with it.
        const TractogramFormat named = format_from_extension(path);
        if (is_streamline_format(named)) f = named;
    }
    switch (f) {
        case TractogramFormat::tck: return std::make_unique<TckSource>(path, options);
        case TractogramFormat::trk: return std::make_unique<TrkReader>(path, options);
        case TractogramFormat::trx:
        case TractogramFormat::zip_other: return std::make_unique<TrxReader>(path, options);  // TRX if it holds header.json
        case TractogramFormat::unknown:
            throw Error(Errc::invalid_input, path + ": not a tractogram fiblet recognises (.tck, .trk or TRX expected)");
        default:
            throw Error(Errc::unsupported, path + ": " + tractogram_format_description(f) +
                                               ": fiblet reads streamlines from .tck, .trk and TRX files");
    }
}

std::unique_ptr<StreamlineSink> open_streamline_sink(const std::string& path, const SinkHeader& header, bool overwrite) {
    const TractogramFormat f = format_from_extension(path);
    switch (f) {
        case TractogramFormat::trk: return std::make_unique<TrkWriter>(path, header, overwrite);
        case TractogramFormat::trx: return std::make_unique<TrxWriter>(path, header, overwrite);
        case TractogramFormat::vtk:
        case TractogramFormat::vtp:
        case TractogramFormat::nifti:
        case TractogramFormat::tck_image:
            throw Error(Errc::unsupported, path + ": fiblet writes streamlines to .tck, .trk and .trx files (" +
                                               tractogram_format_description(f) + " asked for by its name)");
        default: return std::make_unique<TckSink>(path, header, overwrite);  // .tck, and any other name (/dev/stdout)
    }
}

}  // namespace fiblet
