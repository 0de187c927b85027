// fiblet — reading and writing streamlines whatever the file format
// (.tck, .trk, TRX): what compress reads and decompress writes.
//
// A source streams one streamline at a time in world RAS+ millimetres and can
// start again (compress makes two or three passes); a sink takes the decoded
// streamlines in order. The format is chosen by the file's content (sources)
// or its extension (sinks), once, in open_streamline_source/sink.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/geometry.hpp"
#include "fiblet/streamline_field.hpp"
#include "fiblet/tractogram_format.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet {

using Properties = std::vector<std::pair<std::string, std::string>>;

class StreamlineSource {
public:
    virtual ~StreamlineSource() = default;
    virtual TractogramFormat format() const = 0;
    virtual const std::string& path() const = 0;
    // Header properties to keep (PROP chunk): a .tck's key/values; a .trk's or
    // TRX's space (add_space_properties).
    virtual Properties properties() const = 0;
    // The nominal step of the header ("step_size:" of a .tck), if any.
    virtual std::optional<double> step_size() const { return std::nullopt; }

    // Reads the next streamline into `points` (cleared first); false at the end.
    virtual bool next(std::vector<Vec3f>& points) = 0;
    virtual void rewind() = 0;
    // The per-streamline, per-point and group arrays, complete once next()
    // has returned false (a .trk holds them among the points). Moved out.
    virtual std::vector<StreamlineField> take_fields() { return {}; }

    // Progress: bytes of point data consumed so far and in all.
    virtual std::uint64_t bytes_consumed() const = 0;
    virtual std::uint64_t data_bytes() const = 0;
};

struct SourceOptions {
    bool allow_count_mismatch = false;  // a count field that disagrees with the data
    std::size_t max_points = 0;         // longest streamline accepted (0: no limit)
    // Bytes the source's data arrays (TRX dps/dpv/groups/dpg, decompressed)
    // may take in all, checked before each is read: Error{unsupported},
    // Remedy::max_memory (0: no limit).
    std::uint64_t max_memory = 0;
};

// Opens `path` as the format its content says (content of no known kind:
// as its extension says, so that the .tck, .trk or TRX reader reports what
// is wrong). Throws Error{io} when it cannot be read, Error{unsupported}
// naming the format when it is recognised but not a streamline format fiblet
// reads (a .fft, a VTK file, a gzip stream...), Error{invalid_input} when
// neither its content nor its name is recognised.
std::unique_ptr<StreamlineSource> open_streamline_source(const std::string& path, const SourceOptions& options = {});

// What a sink needs besides the points.
struct SinkHeader {
    Properties properties;                    // .tck header lines; source properties
    std::optional<TractogramSpace> space;     // .trk/TRX space (default: identity, RAS, 1 mm)
    std::vector<StreamlineField> fields;      // rows matching the streamlines written
    std::uint64_t fibers = 0, points = 0;     // what will be written (TRX header, field checks)
    FieldType positions_type = FieldType::float32;  // TRX: positions.3.<dtype> (float16/32/64)
    FieldType offsets_type = FieldType::uint64;     // TRX: offsets.<dtype> (uint32/64)
};

class StreamlineSink {
public:
    virtual ~StreamlineSink() = default;
    // One streamline of n points (3n floats), in order.
    virtual void write(const float* xyz, std::size_t n_points) = 0;
    // Streamlines i = 0 .. offsets.size() - 2: points offsets[i] to
    // offsets[i + 1] - 1 of xyz. The same as write() for each, which is what
    // a sink does unless it can write them at once (a .tck: writev).
    virtual void write_chunk(const float* xyz, std::span<const std::uint64_t> offsets) {
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
            write(xyz + 3 * offsets[i], std::size_t(offsets[i + 1] - offsets[i]));
    }
    // write_chunk() for points the caller proved finite (decodes_finite()):
    // a sink that would check them (a .tck) skips that pass.
    virtual void write_finite_chunk(const float* xyz, std::span<const std::uint64_t> offsets) {
        write_chunk(xyz, offsets);
    }
    // Whether write() and write_chunk() refuse a non-finite coordinate
    // (Error{invalid_input}, nothing of the call written): a .tck cannot
    // hold one (NaN separates its streamlines). Callers that would check
    // the points themselves can leave it to such a sink.
    virtual bool refuses_non_finite() const { return false; }
    // Completes the file (atomically); without it no output is left.
    virtual void finish() = 0;
};

// A sink for the format of `path`'s extension: .trk, .trx, and .tck for any
// other name (/dev/stdout...) but those of formats fiblet recognises and
// does not write (.vtk, .vtp, .nii, .mif: Error{unsupported}). A .tck holds
// points only and ignores the header's fields and space. Throws
// Error{exists} if `path` exists and !overwrite, Error{invalid_input} or
// Error{unsupported} for fields the format cannot hold.
std::unique_ptr<StreamlineSink> open_streamline_sink(const std::string& path, const SinkHeader& header, bool overwrite);

}  // namespace fiblet
