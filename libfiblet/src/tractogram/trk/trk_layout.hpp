// Internal: byte offsets of the fields of the 1000-byte TrackVis header.
#pragma once

#include <cstddef>

namespace fiblet::detail::trk {

inline constexpr std::size_t kHeaderSize = 1000;
inline constexpr std::size_t kDim = 6, kVoxelSize = 12, kOrigin = 24;
inline constexpr std::size_t kNScalars = 36, kScalarNames = 38;
inline constexpr std::size_t kNProperties = 238, kPropertyNames = 240;
inline constexpr std::size_t kVoxToRas = 440, kVoxelOrder = 948;
inline constexpr std::size_t kNCount = 988, kVersion = 992, kHdrSize = 996;
inline constexpr std::size_t kNameBytes = 20, kMaxNames = 10;

}  // namespace fiblet::detail::trk
