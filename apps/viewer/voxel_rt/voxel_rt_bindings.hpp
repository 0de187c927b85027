// Binding points of the voxel ray tracer's own buffers: numbered after the
// shared ones (gpu_bindings.hpp) with room for those to grow, given to its
// shaders as #defines next to gpu_binding_defines().
#pragma once

#include <string>

namespace fiblet::viewer::voxel_rt {

namespace binding {
inline constexpr unsigned kPoints = 20;     // resident decoded segments (BlockDecoder's slot layout), part 0
inline constexpr unsigned kCells = 21;      // per voxel: occupancy (high 16 bits, 1/128) | count (low 16)
inline constexpr unsigned kOffsets = 22;    // per voxel: first entry of its fragment list (voxels + 1)
inline constexpr unsigned kFragments = 23;  // unused: the fragment lists are buffer textures (below)
inline constexpr unsigned kCursor = 24;     // per voxel: fill cursor of the second voxelization pass
inline constexpr unsigned kChunks = 25;     // prefix sum: per chunk of voxels
inline constexpr unsigned kSolid = 26;      // culling: per voxel, eroded occupancy full (1) or not (0)
inline constexpr unsigned kVisible = 27;    // culling: visibility pyramid, every level (finest first)
// The resident segments split over several storage buffers (one buffer is
// limited to GL_MAX_SHADER_STORAGE_BLOCK_SIZE: llvmpipe 128 MiB): part 0 at
// kPoints, parts 1.. at kMorePoints + part - 1. Eight parts: with them the
// trace's fragment shader uses 15 of the 16 storage blocks llvmpipe (and
// NVIDIA) offer a stage.
inline constexpr unsigned kPointParts = 8;
inline constexpr unsigned kMorePoints = 28;
inline constexpr unsigned kHighest = kMorePoints + kPointParts - 2;
// The fragment lists: up to kFragmentParts buffers of R32UI, not storage
// buffers (the trace's fragment shader has no storage block left; a buffer
// texture holds GL_MAX_TEXTURE_BUFFER_SIZE texels, llvmpipe 128 M = 512 MiB).
// The trace reads them as buffer textures on units kFragmentUnit.., the
// second voxelization pass writes them as image buffers on image units 0...
inline constexpr unsigned kFragmentParts = 4;
inline constexpr unsigned kFragmentUnit = 2;
// The occupancy pyramid of empty-space skipping (levels 1.., R8UI): a buffer
// texture on this unit for the trace, an image buffer on image unit 0 while
// it is built.
inline constexpr unsigned kOccupiedUnit = kFragmentUnit + kFragmentParts;
}  // namespace binding

// gpu_binding_defines() and BINDING_VRT_* for this module's bindings.
std::string voxel_rt_defines();

}  // namespace fiblet::viewer::voxel_rt
