// fiblet — the dtypes of a TRX source's arrays that a .fft cannot store as
// they were, recorded in PROP by compress and given back by decompress
// (formats/fft-data.md, "Source dtypes"):
//   trx_positions_dtype  float16 | float32 | float64 (points are decoded as float32)
//   trx_offsets_dtype    uint32 | uint64 (the .fft keeps point counts)
//   source_dtype         "<dtype> <array name>", one per per-point array of a
//                        resampled input (interpolated, stored as float32)
#pragma once

#include <string>
#include <vector>

#include "fiblet/streamline_field.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_format.hpp"

namespace fiblet {

// A TRX source's positions and offsets dtypes, as PROP keys.
void add_trx_dtype_properties(Properties& properties, FieldType positions, FieldType offsets);
// An array stored in another type than its source's (a resampled input's per-point array).
void add_source_dtype_property(Properties& properties, const std::string& array, FieldType source);
// True for the keys above (a .tck output does not get them as header lines).
bool is_source_dtype_property(const std::string& key) noexcept;

// An array whose output dtype differs from its source's, and why.
struct DtypeChange {
    std::string array;  // "positions", "offsets", "dpv/fa"
    FieldType from, to;
    std::string why;
};

// Sets what a `format` output of `header` (its properties from a .fft)
// writes: for TRX, the recorded positions and offsets dtypes, and each
// recorded floating-point array converted back to its source dtype (values
// as decoded; float16 rounds to nearest). Returns what does not come back
// in its source dtype (integer arrays that were interpolated stay float32;
// a .trk holds float32 only; a .tck, float32 points). Keys with values it
// does not know are ignored (a .tck source's header may hold anything).
std::vector<DtypeChange> restore_source_dtypes(SinkHeader& header, TractogramFormat format);

}  // namespace fiblet
