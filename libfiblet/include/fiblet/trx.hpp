// fiblet — TRX tractograms (github.com/tee-ar-ex/trx-spec): a zip archive
// (stored or deflated, read through libzip) or a directory holding
// header.json (VOXEL_TO_RASMM, DIMENSIONS, NB_STREAMLINES, NB_VERTICES),
// positions.3.{float16,float32,float64} in RAS+ mm, offsets.{uint32,uint64}
// (with or without the final NB_VERTICES sentinel), and optional dps/, dpv/,
// groups/, dpg/ arrays, all little-endian.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fiblet/streamline_io.hpp"

namespace fiblet {

class TrxReader final : public StreamlineSource {
public:
    // Reads header.json and the offsets, and checks every array's size
    // (throws Error{trx_format|unsupported|io}). Positions stream.
    TrxReader(const std::string& path, const SourceOptions& options = {});
    ~TrxReader() override;

    TractogramFormat format() const override { return TractogramFormat::trx; }
    const std::string& path() const override;
    const TractogramSpace& space() const;
    std::uint64_t streamline_count() const;
    std::uint64_t point_count() const;
    Properties properties() const override;
    bool next(std::vector<Vec3f>& points) override;
    void rewind() override;
    std::vector<StreamlineField> take_fields() override;
    std::uint64_t bytes_consumed() const override;
    std::uint64_t data_bytes() const override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Writes a TRX zip (entries stored, uncompressed) with positions and
// offsets (with the sentinel) in the header's positions_type and
// offsets_type (float32 and uint64 by default), and the fields as dps/, dpv/,
// groups/, dpg/ entries. Positions go to a temporary file until finish();
// libzip writes the archive to a temporary and renames it over `path`.
class TrxWriter final : public StreamlineSink {
public:
    TrxWriter(const std::string& path, const SinkHeader& header, bool overwrite);
    ~TrxWriter() override;
    void write(const float* xyz, std::size_t n_points) override;
    void finish() override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fiblet
