// fiblet — per-streamline, per-point and group data in a .fft file: the DATA
// trailer chunk (formats/fft-data.md).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fiblet/fft_format.hpp"
#include "fiblet/streamline_field.hpp"

namespace fiblet {

inline constexpr std::array<char, 4> kStreamlineDataTag = {'D', 'A', 'T', 'A'};

TrailerChunk make_streamline_data_chunk(const std::vector<StreamlineField>& fields);
// Validates every field against the header's fibers and points (rows, names,
// group indices, no name twice). Throws Error{fft_format} naming `path`.
std::vector<StreamlineField> parse_streamline_data_chunk(const TrailerChunk& chunk, std::uint64_t fibers,
                                                         std::uint64_t points, const std::string& path);

}  // namespace fiblet
