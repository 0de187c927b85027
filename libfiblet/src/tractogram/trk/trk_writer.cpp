// TrackVis .trk writer (little-endian, version 2), through an AtomicOutputFile.
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/trk.hpp"
#include "tractogram/trk/trk_layout.hpp"

namespace fiblet {
namespace {

using namespace detail::trk;

template <class T>
void put(std::array<std::uint8_t, kHeaderSize>& h, std::size_t at, T v) {
    std::memcpy(&h[at], &v, sizeof v);  // hosts are little-endian
}

// nibabel's encode_value_in_name: "name", or "name\0N" for N > 1 values.
void put_name(std::array<std::uint8_t, kHeaderSize>& h, std::size_t at, const StreamlineField& f,
              const std::string& path) {
    const std::string name(f.short_name());
    const std::string encoded = f.components > 1 ? name + '\0' + std::to_string(f.components) : name;
    if (encoded.size() > kNameBytes)
        throw Error(Errc::unsupported, path + ": \"" + name + "\" with its value count is longer than the 20 bytes a .trk name holds");
    std::memcpy(&h[at], encoded.data(), encoded.size());
}

}  // namespace

struct TrkWriter::Impl {
    AtomicOutputFile out;
    Affine to_voxmm{};
    std::vector<const StreamlineField*> scalars, properties;
    std::uint32_t scalar_values = 0, property_values = 0;
    std::uint64_t fibers = 0, points = 0, expected_fibers = 0, expected_points = 0;
    std::vector<float> buffer;
    bool finished = false;

    Impl(const std::string& path, bool overwrite) : out(path, overwrite) {}

    void sort_fields(const SinkHeader& hdr) {
        for (const StreamlineField& f : hdr.fields) {
            const auto scope = f.scope();
            if (scope == FieldScope::point) scalars.push_back(&f), scalar_values += f.components;
            else if (scope == FieldScope::streamline) properties.push_back(&f), property_values += f.components;
            else
                throw Error(Errc::unsupported, out.path() + ": a .trk cannot hold \"" + f.name +
                                                   "\" (groups and per-group data): write a .trx instead");
            const std::string problem = check_streamline_field(f, hdr.fibers, hdr.points);
            if (!problem.empty()) throw Error(Errc::invalid_input, out.path() + ": " + problem);
        }
        if (scalars.size() > kMaxNames || properties.size() > kMaxNames)
            throw Error(Errc::unsupported, out.path() + ": a .trk holds at most 10 named scalars and 10 named properties");
        if (scalar_values > 32767 || property_values > 32767)
            throw Error(Errc::unsupported, out.path() + ": too many values per point or streamline for a .trk");
    }

    std::array<std::uint8_t, kHeaderSize> header(const TractogramSpace& s) const {
        std::array<std::uint8_t, kHeaderSize> h{};
        std::memcpy(&h[0], "TRACK", 5);
        for (std::size_t k = 0; k < 3; ++k) {
            if (s.dimensions[k] < 0 || s.dimensions[k] > 32767)
                throw Error(Errc::unsupported, out.path() + ": dimension " + std::to_string(s.dimensions[k]) + " does not fit a .trk");
            put(h, kDim + 2 * k, std::int16_t(s.dimensions[k]));
            put(h, kVoxelSize + 4 * k, float(s.voxel_sizes[k]));
        }
        put(h, kNScalars, std::int16_t(scalar_values));
        for (std::size_t i = 0; i < scalars.size(); ++i) put_name(h, kScalarNames + kNameBytes * i, *scalars[i], out.path());
        put(h, kNProperties, std::int16_t(property_values));
        for (std::size_t i = 0; i < properties.size(); ++i)
            put_name(h, kPropertyNames + kNameBytes * i, *properties[i], out.path());
        for (std::size_t i = 0; i < 16; ++i) put(h, kVoxToRas + 4 * i, float(s.voxel_to_rasmm[i]));
        std::memcpy(&h[kVoxelOrder], s.voxel_order.data(), std::min<std::size_t>(3, s.voxel_order.size()));
        put(h, kVersion, std::int32_t(2));
        put(h, kHdrSize, std::int32_t(kHeaderSize));
        return h;
    }

    void append_values(const std::vector<const StreamlineField*>& fields, std::uint64_t row) {
        for (const StreamlineField* f : fields)
            for (std::uint32_t c = 0; c < f->components; ++c) buffer.push_back(narrow_to_float(f->at(row, c)));
    }

    void write(const float* xyz, std::size_t n) {
        if (finished) throw Error(Errc::invalid_argument, out.path() + ": TrkWriter used after finish()");
        if (n > std::size_t(std::numeric_limits<std::int32_t>::max()) || fibers == std::numeric_limits<std::int32_t>::max())
            throw Error(Errc::unsupported, out.path() + ": more streamlines or points than a .trk counts");
        if ((scalar_values || property_values) && (fibers >= expected_fibers || points + n > expected_points))
            throw Error(Errc::invalid_argument, out.path() + ": more streamlines than the fields describe");
        buffer.clear();
        const Affine& a = to_voxmm;
        for (std::size_t i = 0; i < n; ++i) {
            const double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
            buffer.push_back(narrow_to_float(a[0] * x + a[1] * y + a[2] * z + a[3]));
            buffer.push_back(narrow_to_float(a[4] * x + a[5] * y + a[6] * z + a[7]));
            buffer.push_back(narrow_to_float(a[8] * x + a[9] * y + a[10] * z + a[11]));
            append_values(scalars, points + i);
        }
        append_values(properties, fibers);
        const auto count = std::int32_t(n);
        out.write(&count, 4);
        out.write(buffer.data(), 4 * buffer.size());
        ++fibers, points += n;
    }

    void finish() {
        if (finished) return;
        if ((scalar_values || property_values) && (fibers != expected_fibers || points != expected_points))
            throw Error(Errc::invalid_argument, out.path() + ": fewer streamlines written than the fields describe");
        const auto count = std::int32_t(fibers);
        out.write_at(&count, 4, kNCount);
        out.commit();
        finished = true;
    }
};

TrkWriter::TrkWriter(const std::string& path, const SinkHeader& header, bool overwrite)
    : impl_(std::make_unique<Impl>(path, overwrite)) {
    const TractogramSpace space = header.space.value_or(TractogramSpace{});
    impl_->expected_fibers = header.fibers;
    impl_->expected_points = header.points;
    impl_->sort_fields(header);
    try {
        impl_->to_voxmm = affine_inverse(trk_voxmm_to_rasmm(space));
    } catch (const Error& e) {
        throw Error(Errc::invalid_input, path + ": " + e.what());
    }
    const auto h = impl_->header(space);
    impl_->out.write(h.data(), h.size());
}

TrkWriter::~TrkWriter() = default;
void TrkWriter::write(const float* xyz, std::size_t n_points) { impl_->write(xyz, n_points); }
void TrkWriter::finish() { impl_->finish(); }

}  // namespace fiblet
