// Binding points shared by the C++ side and the shaders: the shaders receive
// them as #defines (gpu_binding_defines), so both sides use one definition.
#pragma once

#include <string>

namespace fiblet::viewer {

namespace binding {
// Shader storage buffers.
inline constexpr unsigned kBlocks = 0;       // the raw blocks of the file, as uint words
inline constexpr unsigned kBlockFiber = 1;   // per block: index of its fiber in the file
inline constexpr unsigned kFiberPoints = 2;  // per fiber: number of points
inline constexpr unsigned kFiberEnds = 3;    // per fiber: last point (world mm), decoded once at load
inline constexpr unsigned kFineList = 4;     // blocks to decode and draw in full
inline constexpr unsigned kCoarseList = 5;   // blocks drawn as one segment (level of detail)
inline constexpr unsigned kCounters = 6;     // sizes of the two lists and their segment counts
inline constexpr unsigned kPoints = 7;       // decoded points, pointsPerBlock + 1 slots per block
inline constexpr unsigned kDecisions = 8;    // per block culling decision (tests, statistics)
inline constexpr unsigned kFiberEndFraction = 9;  // per fiber: fraction of its last step kept (ENDS chunk)
inline constexpr unsigned kTangents = 10;    // unit tangent of each decoded point, laid out as kPoints
inline constexpr unsigned kTubePieces = 11;  // techniques/tubes: quadratic pieces and their boxes
inline constexpr unsigned kFiberColors = 12;  // per fiber: RGB (vec4), when the scene has colours
inline constexpr unsigned kFiberRadii = 13;   // per fiber: tube radius (mm), when the scene has radii
inline constexpr unsigned kGlyphCoefficients = 14;  // overlays/odf_glyphs: SH coefficients, glyph units
inline constexpr unsigned kGlyphCenters = 15;       // overlays/odf_glyphs: centre, radius (mm) and box (glyph_boxes.glsl)
inline constexpr unsigned kWideFrames = 16;  // the levels^2 frames of a 16-bit direction code (DirectionTable16)
inline constexpr unsigned kPointValues = 17;  // per block: pointsPerBlock slots of per-point values (one float each)
inline constexpr unsigned kStorageCount = 18;
// Transparent frames (transparency/) reuse the binding points of buffers
// that no pass using them binds (no level of detail, no decisions; tube
// pieces and tangents only in the draw passes, after the sort), so that the
// viewer asks the driver for no more bindings.
inline constexpr unsigned kChunkKeys = kCoarseList;      // per chunk: its depth bucket
inline constexpr unsigned kChunkHistogram = kCounters;   // chunks per (bucket, lane), then their offsets
inline constexpr unsigned kSortedChunks = kDecisions;    // per sorted slot: block x chunks per block + chunk
inline constexpr unsigned kSortedBlocks = kTubePieces;   // per sorted slot: its block
inline constexpr unsigned kVoxlineSegments = kTangents;  // voxlines: both ends of every segment
inline constexpr unsigned kVoxlineOrders = kTubePieces;  // voxlines: the three axis orders of every voxel
// Uniform buffers.
inline constexpr unsigned kLocalFrames = 0;  // the 256 frames of the 8-bit direction code (DirectionTable)
}  // namespace binding

// Per-block decisions written by the culling pass.
enum class BlockDecision : unsigned {
    outside_frustum = 0,  // bounding sphere entirely outside one frustum plane
    coarse = 1,           // visible, under the level-of-detail size: one segment
    fine = 2,             // visible, decoded and drawn in full
    not_selected = 3,     // excluded by the fiber subset (ID / length)
};

// Layout of the counters buffer (uint each).
struct DrawCounters {
    unsigned fine_blocks = 0, coarse_blocks = 0, fine_segments = 0, coarse_segments = 0;
};

// "#define BINDING_BLOCKS 0\n..." for every binding point and decision code.
std::string gpu_binding_defines();

}  // namespace fiblet::viewer
