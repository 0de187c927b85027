// TRX writer: a zip of stored entries through libzip. Positions wait in an
// anonymous temporary file; libzip writes the archive to a temporary beside
// `path` and renames it at zip_close.
#include <zip.h>

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include "fiblet/error.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/trx.hpp"

namespace fiblet {
namespace {

std::string header_json(const TractogramSpace& s, std::uint64_t fibers, std::uint64_t points) {
    nlohmann::json j;
    j["VOXEL_TO_RASMM"] = nlohmann::json::array();
    for (int r = 0; r < 4; ++r)
        j["VOXEL_TO_RASMM"].push_back({s.voxel_to_rasmm[std::size_t(4 * r)], s.voxel_to_rasmm[std::size_t(4 * r + 1)],
                                       s.voxel_to_rasmm[std::size_t(4 * r + 2)], s.voxel_to_rasmm[std::size_t(4 * r + 3)]});
    j["DIMENSIONS"] = {s.dimensions[0], s.dimensions[1], s.dimensions[2]};
    j["NB_STREAMLINES"] = fibers;
    j["NB_VERTICES"] = points;
    return j.dump();
}

std::string entry_name(const StreamlineField& f) {
    return f.name + (f.components > 1 ? "." + std::to_string(f.components) : "") + "." + field_type_name(f.type);
}

}  // namespace

struct TrxWriter::Impl {
    std::string path;
    bool overwrite;
    SinkHeader header;
    std::FILE* positions = nullptr;  // owned until handed to libzip
    std::vector<std::uint64_t> offsets{0};
    std::vector<std::uint8_t> converted;  // one streamline's positions as float16/float64
    bool finished = false;

    ~Impl() {
        if (positions) std::fclose(positions);
    }

    [[noreturn]] void zip_failed(zip_t* z, const std::string& what) {
        const std::string msg = path + ": cannot write the TRX zip (" + what + "): " + zip_strerror(z);
        zip_discard(z);
        throw Error(Errc::io, msg);
    }

    void add(zip_t* z, const std::string& name, zip_source_t* src) {
        if (!src) zip_failed(z, name);
        const zip_int64_t i = zip_file_add(z, name.c_str(), src, ZIP_FL_ENC_UTF_8);
        if (i < 0) {
            zip_source_free(src);
            zip_failed(z, name);
        }
        if (zip_set_file_compression(z, zip_uint64_t(i), ZIP_CM_STORE, 0) != 0) zip_failed(z, name);
    }

    void add_buffer(zip_t* z, const std::string& name, const void* data, std::size_t size) {
        add(z, name, zip_source_buffer(z, data, size, 0));
    }

    void finish() {
        const std::uint64_t fibers = offsets.size() - 1, points = offsets.back();
        if (!header.fields.empty() && (fibers != header.fibers || points != header.points))
            throw Error(Errc::invalid_argument, path + ": the streamlines written do not match the fields' rows");
        if (std::fflush(positions) != 0) throw Error(Errc::io, path + ": writing positions: " + std::strerror(errno));
        AtomicOutputFile::check_destination(path, overwrite);
        int err = 0;
        zip_t* z = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
        if (!z) throw Error(Errc::io, path + ": cannot create the TRX zip (libzip error " + std::to_string(err) + ")");
        const std::string json = header_json(header.space.value_or(TractogramSpace{}), fibers, points);
        add_buffer(z, "header.json", json.data(), json.size());
        std::rewind(positions);
        const std::size_t size = field_type_size(header.positions_type);
        zip_source_t* src = zip_source_filep(z, positions, 0, zip_int64_t(points * 3 * size));
        if (src) positions = nullptr;  // libzip closes it
        add(z, std::string("positions.3.") + field_type_name(header.positions_type), src);
        if (header.offsets_type == FieldType::uint32) {
            std::vector<std::uint32_t> narrow(offsets.begin(), offsets.end());  // checked to fit at write()
            converted.resize(narrow.size() * 4);
            std::memcpy(converted.data(), narrow.data(), converted.size());
            add_buffer(z, "offsets.uint32", converted.data(), converted.size());
        } else {
            add_buffer(z, "offsets.uint64", offsets.data(), offsets.size() * 8);
        }
        for (const StreamlineField& f : header.fields) add_buffer(z, entry_name(f), f.bytes.data(), f.bytes.size());
        if (zip_close(z) != 0) zip_failed(z, "closing");
        finished = true;
    }
};

TrxWriter::TrxWriter(const std::string& path, const SinkHeader& header, bool overwrite)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.path = path;
    m.overwrite = overwrite;
    AtomicOutputFile::check_destination(path, overwrite);
    for (const StreamlineField& f : header.fields) {
        const std::string problem = check_streamline_field(f, header.fibers, header.points);
        if (!problem.empty()) throw Error(Errc::invalid_input, path + ": " + problem);
    }
    const FieldType p = header.positions_type, o = header.offsets_type;
    if (!is_float_type(p) ||
        (o != FieldType::uint32 && o != FieldType::uint64))
        throw Error(Errc::invalid_argument, path + ": TRX positions are float16/32/64 and offsets uint32/64, not " +
                                                field_type_name(p) + "/" + field_type_name(o));
    m.header = header;
    m.positions = std::tmpfile();
    if (!m.positions) throw Error(Errc::io, path + ": cannot create a temporary file: " + std::strerror(errno));
}

TrxWriter::~TrxWriter() = default;

void TrxWriter::write(const float* xyz, std::size_t n_points) {
    Impl& m = *impl_;
    if (m.finished) throw Error(Errc::invalid_argument, m.path + ": TrxWriter used after finish()");
    const std::uint64_t end = m.offsets.back() + n_points;
    if (m.header.offsets_type == FieldType::uint32 && end > std::numeric_limits<std::uint32_t>::max())
        throw Error(Errc::unsupported, m.path + ": more than 2^32 - 1 points: uint32 offsets cannot hold them");
    const void* data = xyz;
    std::size_t size = 4;
    if (m.header.positions_type == FieldType::float64) {
        size = 8;
        m.converted.resize(n_points * 3 * 8);
        for (std::size_t i = 0; i < 3 * n_points; ++i) {
            const double d = xyz[i];
            std::memcpy(&m.converted[i * 8], &d, 8);
        }
        data = m.converted.data();
    } else if (m.header.positions_type == FieldType::float16) {
        size = 2;
        m.converted.resize(n_points * 3 * 2);
        for (std::size_t i = 0; i < 3 * n_points; ++i) {
            const std::uint16_t h = float_to_half(xyz[i]);
            std::memcpy(&m.converted[i * 2], &h, 2);
        }
        data = m.converted.data();
    }
    if (n_points && std::fwrite(data, 3 * size, n_points, m.positions) != n_points)
        throw Error(Errc::io, m.path + ": writing positions: " + std::strerror(errno));
    m.offsets.push_back(end);
}

void TrxWriter::finish() {
    if (!impl_->finished) impl_->finish();
}

}  // namespace fiblet
