// fiblet — TrackVis .trk files: a streaming reader and a writer.
//
// Format (trackvis.org/docs/?subsect=fileformat): a 1000-byte header
// ("TRACK", dim, voxel_size, origin, n_scalars + 10 names, n_properties + 10
// names, vox_to_ras (version 2), voxel_order, ..., n_count, version,
// hdr_size = 1000), little- or big-endian (told by hdr_size); then per
// streamline an int32 point count, the points as float32 (x, y, z,
// n_scalars values) and n_properties float32. Points are "voxmm": voxel
// coordinates times voxel sizes, 0 at a voxel's corner. The reader gives
// them in RAS+ mm exactly as nibabel's load(...).streamlines does
// (trk_voxmm_to_rasmm); the writer stores the inverse.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet {

struct TrkHeader {
    TractogramSpace space;
    std::array<float, 3> origin{0, 0, 0};
    // Field names decoded as nibabel does: "name" or "name\0N" for N values.
    struct Named { std::string name; int count; };
    std::vector<Named> scalars, properties;
    int n_scalars = 0, n_properties = 0;
    std::uint32_t n_count = 0;  // 0: not recorded (read to the end)
    int version = 2;
    bool big_endian = false;
    std::uint64_t file_bytes = 0;
};

// Parses the header of a .trk file (throws Error{trk_format|unsupported|io}).
TrkHeader read_trk_header(const std::string& path);

class TrkReader final : public StreamlineSource {
public:
    TrkReader(const std::string& path, const SourceOptions& options = {});
    ~TrkReader() override;

    const TrkHeader& header() const;
    TractogramFormat format() const override { return TractogramFormat::trk; }
    const std::string& path() const override;
    Properties properties() const override;
    bool next(std::vector<Vec3f>& points) override;
    void rewind() override;
    // Scalars as "dpv/NAME" and properties as "dps/NAME" float32 fields.
    std::vector<StreamlineField> take_fields() override;
    std::uint64_t bytes_consumed() const override;
    std::uint64_t data_bytes() const override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Writes a little-endian version-2 .trk atomically. float "dpv/" fields
// become scalars and "dps/" fields properties (at most 10 names each, names
// up to 20 bytes); groups cannot be stored (Error{unsupported}).
class TrkWriter final : public StreamlineSink {
public:
    TrkWriter(const std::string& path, const SinkHeader& header, bool overwrite);
    ~TrkWriter() override;
    void write(const float* xyz, std::size_t n_points) override;
    void finish() override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fiblet
