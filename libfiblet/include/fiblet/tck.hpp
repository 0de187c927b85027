// fiblet — MRtrix3 .tck streamline files: a streaming reader and a writer.
//
// Format (MRtrix3 "tracks" file): the text line "mrtrix tracks", then
// "key: value" lines up to "END"; "file: . OFFSET" gives the byte offset of
// the data, "datatype:" one of Float32LE/Float32BE/Float64LE/Float64BE.
// The data is a sequence of xyz triplets; a NaN triplet ends a streamline,
// an Inf triplet ends the data.
//
// The reader never holds more than one chunk of the file plus the current
// streamline, so inputs of any size stream in bounded memory.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/geometry.hpp"

namespace fiblet {

enum class TckDataType { float32le, float32be, float64le, float64be };

const char* tck_datatype_name(TckDataType t) noexcept;
inline int tck_datatype_size(TckDataType t) noexcept {
    return (t == TckDataType::float32le || t == TckDataType::float32be) ? 4 : 8;
}

// Header of a .tck file. All key/value properties are kept in file order
// (repeated keys, such as command_history, stay separate entries), except
// "file" and "datatype", which are parsed into their own fields.
struct TckHeader {
    std::vector<std::pair<std::string, std::string>> properties;
    TckDataType datatype = TckDataType::float32le;
    std::uint64_t data_offset = 0;

    // First value of a key, if present.
    std::optional<std::string> get(const std::string& key) const;
    // Replaces every entry of `key` by one entry (appended if absent).
    void set(const std::string& key, const std::string& value);
    void erase(const std::string& key);
    // "count:" parsed as an integer, if present and valid.
    std::optional<std::uint64_t> count() const;
    // "step_size:" parsed as a positive finite number, if present and valid.
    std::optional<double> step_size() const;
};

// Parses the header of a .tck file (throws Error{tck_format|io}).
TckHeader read_tck_header(const std::string& path);

// An MRtrix3 track scalar file (.tsf, tcksample's output): the values of
// each streamline's points (Float64 files narrowed to float). Throws
// Error{tck_format} when malformed (the .tck header rules; NaN after each
// streamline, then Inf or the end of the file; finite values), Error{unsupported} for a
// datatype other than Float32/64 LE/BE, Error{io}.
std::vector<std::vector<float>> read_track_scalars(const std::string& path);

struct TckReadOptions {
    // Size of each read from disk: small enough that the chunk is still in
    // the CPU's L2 cache when it is parsed (compress of the medium
    // tractogram 2-3 % faster than with 4 MB; 128 kB no faster again).
    std::size_t chunk_bytes = 256u << 10;
    // A "count:" that disagrees with the data is an error unless this is set
    // (a truncated or hand-edited file would otherwise lose fibers silently).
    bool allow_count_mismatch = false;
    // A streamline of more points is Error{unsupported} (0: no limit), so
    // that one absurd streamline cannot take all memory.
    std::size_t max_points = 0;
};

// Streaming reader: next() returns one streamline at a time.
class TckReader {
public:
    explicit TckReader(const std::string& path, TckReadOptions options = {});
    ~TckReader();
    TckReader(TckReader&&) noexcept;
    TckReader& operator=(TckReader&&) noexcept;

    const TckHeader& header() const;
    const std::string& path() const;

    // Reads the next streamline into `points` (cleared first). Returns false
    // at the end of the data. Throws Error{tck_format} on a truncated file,
    // a partial NaN/Inf triplet, or a count mismatch at the end.
    bool next(std::vector<Vec3f>& points);

    std::uint64_t streamlines_read() const;
    std::uint64_t points_read() const;
    // Bytes of the data section consumed so far, and the data section size
    // (for progress reporting).
    std::uint64_t bytes_consumed() const;
    std::uint64_t data_bytes() const;

    // Back to the first streamline (for multi-pass encoding).
    void rewind();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Writes a .tck file (Float32LE) atomically: data goes to a temporary file in
// the destination directory, renamed over `path` by finish(). Destroying the
// writer without finish() removes the temporary and leaves no output.
// `count` is patched in the header at finish() (written with fixed width).
class TckWriter {
public:
    // `properties` are written in order after "mrtrix tracks" (any "count",
    // "file", "datatype" or "END" keys among them are ignored: the writer
    // owns those). Throws Error{exists} if `path` exists and !overwrite.
    TckWriter(const std::string& path, const std::vector<std::pair<std::string, std::string>>& properties,
              bool overwrite);
    ~TckWriter();
    TckWriter(const TckWriter&) = delete;
    TckWriter& operator=(const TckWriter&) = delete;

    void write(std::span<const Vec3f> streamline);
    // Same, from a flat float array of 3*n values.
    void write(const float* xyz, std::size_t n_points);
    // Streamlines i = 0 .. offsets.size() - 2 of a chunk: points offsets[i]
    // to offsets[i + 1] - 1 of xyz (3 floats each), handed to the kernel
    // where they lie, with their separators (no copy: writev).
    // Refuses a non-finite coordinate (Error{invalid_input}, nothing of the
    // chunk written).
    void write_chunk(const float* xyz, std::span<const std::uint64_t> offsets);
    // The same for points the caller proved finite (decodes_finite()):
    // without that pass over them.
    void write_finite_chunk(const float* xyz, std::span<const std::uint64_t> offsets);
    void finish();

    std::uint64_t count() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fiblet
