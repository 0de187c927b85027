// Streaming TrackVis .trk reader: points to RAS+ mm as nibabel gives them;
// scalars and properties gathered into fields on the first pass.
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "core/finite_points.hpp"
#include "core/streamline_label.hpp"
#include "fiblet/error.hpp"
#include "fiblet/trk.hpp"
#include "tractogram/trk/trk_layout.hpp"

namespace fiblet {

struct TrkReader::Impl {
    std::string path;
    SourceOptions options;
    TrkHeader header;
    Affine to_ras{};
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file{nullptr, &std::fclose};
    std::uint64_t streamlines = 0, consumed = 0;
    std::vector<float> values;  // one streamline's floats
    // Fields: one per named scalar and property, filled on the first pass.
    std::vector<StreamlineField> scalars, properties;
    bool first_pass = true, fields_taken = false;

    [[noreturn]] void bad(const std::string& what) const {
        throw Error(Errc::trk_format, path + ": not a valid TrackVis .trk file: " + what);
    }

    // Reads n bytes; false at a clean end of file (nothing read) if allowed.
    bool read(void* out, std::size_t n, bool end_allowed, const char* what) {
        const std::size_t got = std::fread(out, 1, n, file.get());
        consumed += got;
        if (got == n) return true;
        if (std::ferror(file.get())) throw Error(Errc::io, path + ": read failed: " + std::strerror(errno));
        if (got == 0 && end_allowed) return false;
        bad("truncated in " + detail::streamline_label(streamlines) + " (" + what + ")");
    }

    void swap_floats(float* v, std::size_t n) const {
        if (!header.big_endian) return;
        for (std::size_t i = 0; i < n; ++i) v[i] = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<std::uint32_t>(v[i])));
    }

    void open() {
        file.reset(std::fopen(path.c_str(), "rb"));
        if (!file) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
        std::setvbuf(file.get(), nullptr, _IOFBF, 1 << 20);
        if (std::fseek(file.get(), long(detail::trk::kHeaderSize), SEEK_SET) != 0)
            throw Error(Errc::io, path + ": seek failed: " + std::strerror(errno));
        streamlines = consumed = 0;
    }

    void append(std::vector<StreamlineField>& fields, const std::vector<TrkHeader::Named>& names, const float* v,
                std::size_t stride, std::size_t rows) {
        std::size_t col = 0;
        for (std::size_t i = 0; i < names.size(); ++i) {
            const std::size_t n = std::size_t(names[i].count);
            auto& bytes = fields[i].bytes;
            for (std::size_t r = 0; r < rows; ++r) {
                const std::size_t at = bytes.size();
                bytes.resize(at + 4 * n);
                std::memcpy(&bytes[at], v + r * stride + col, 4 * n);
            }
            col += n;
        }
    }

    bool count_reached() const { return header.n_count > 0 && streamlines == header.n_count; }

    void check_end() {
        if (options.allow_count_mismatch) return;
        if (header.n_count > 0 && streamlines != header.n_count)
            bad("n_count is " + std::to_string(header.n_count) + " but the data holds " + std::to_string(streamlines) +
                " streamlines");
        if (count_reached() && std::fgetc(file.get()) != EOF)
            bad("data continues after the n_count = " + std::to_string(header.n_count) + " streamlines");
    }

    bool next(std::vector<Vec3f>& points) {
        points.clear();
        if (count_reached()) {
            check_end();
            return finish_pass();
        }
        std::uint32_t raw;
        if (!read(&raw, 4, true, "point count")) {
            check_end();
            return finish_pass();
        }
        if (header.big_endian) raw = __builtin_bswap32(raw);
        const auto n = std::int32_t(raw);
        if (n < 0) bad(detail::streamline_label(streamlines) + " has a negative point count (" + std::to_string(n) + ")");
        const std::size_t stride = 3 + std::size_t(header.n_scalars);
        const std::size_t total = std::size_t(n) * stride + std::size_t(header.n_properties);
        // A count larger than the rest of the file is damage (exit 4 in every
        // command), not a reason to allocate nor a size fiblet lacks.
        if (header.file_bytes && 4 * std::uint64_t(total) > header.file_bytes)
            bad(detail::streamline_label(streamlines) + " claims " + std::to_string(n) + " points, more than the file holds");
        if (options.max_points && std::size_t(n) > options.max_points)
            throw Error(Errc::unsupported, path + ": " + detail::streamline_label(streamlines) + " has " +
                                               std::to_string(n) + " points (at most " +
                                               std::to_string(options.max_points) + " supported)");
        values.resize(total);
        if (total > 0) read(values.data(), 4 * total, false, "points");
        swap_floats(values.data(), total);
        points.resize(std::size_t(n));
        const Affine& a = to_ras;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const double x = values[i * stride], y = values[i * stride + 1], z = values[i * stride + 2];
            points[i] = {narrow_to_float(a[0] * x + a[1] * y + a[2] * z + a[3]),
                         narrow_to_float(a[4] * x + a[5] * y + a[6] * z + a[7]),
                         narrow_to_float(a[8] * x + a[9] * y + a[10] * z + a[11])};
        }
        if (const auto k = detail::first_non_finite(points))
            bad(detail::streamline_label(streamlines) + " " + detail::non_finite_point_message(points, *k));
        if (first_pass && header.n_scalars > 0 && n > 0)
            append(scalars, header.scalars, values.data() + 3, stride, points.size());
        if (first_pass && header.n_properties > 0)
            append(properties, header.properties, values.data() + std::size_t(n) * stride, 0, 1);
        ++streamlines;
        return true;
    }

    bool finish_pass() {
        first_pass = false;
        return false;
    }
};

namespace {
std::vector<StreamlineField> empty_fields(const std::vector<TrkHeader::Named>& names, const char* scope) {
    std::vector<StreamlineField> f;
    for (const auto& n : names) f.push_back({std::string(scope) + n.name, FieldType::float32, std::uint32_t(n.count), {}});
    return f;
}
}  // namespace

TrkReader::TrkReader(const std::string& path, const SourceOptions& options) : impl_(std::make_unique<Impl>()) {
    impl_->path = path;
    impl_->options = options;
    impl_->header = read_trk_header(path);
    impl_->to_ras = trk_voxmm_to_rasmm(impl_->header.space);
    impl_->scalars = empty_fields(impl_->header.scalars, "dpv/");
    impl_->properties = empty_fields(impl_->header.properties, "dps/");
    impl_->open();
}

TrkReader::~TrkReader() = default;
const TrkHeader& TrkReader::header() const { return impl_->header; }
const std::string& TrkReader::path() const { return impl_->path; }

Properties TrkReader::properties() const {
    Properties p;
    add_space_properties(p, impl_->header.space);
    return p;
}

bool TrkReader::next(std::vector<Vec3f>& points) { return impl_->next(points); }
void TrkReader::rewind() { impl_->open(); }

std::vector<StreamlineField> TrkReader::take_fields() {
    if (impl_->first_pass || impl_->fields_taken) return {};
    impl_->fields_taken = true;
    std::vector<StreamlineField> all = std::move(impl_->scalars);
    for (auto& f : impl_->properties) all.push_back(std::move(f));
    return all;
}

std::uint64_t TrkReader::bytes_consumed() const { return impl_->consumed; }
std::uint64_t TrkReader::data_bytes() const {
    return impl_->header.file_bytes > detail::trk::kHeaderSize ? impl_->header.file_bytes - detail::trk::kHeaderSize : 0;
}

}  // namespace fiblet
