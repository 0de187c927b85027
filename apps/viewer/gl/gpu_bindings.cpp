#include "gl/gpu_bindings.hpp"

#include <fmt/core.h>

namespace fiblet::viewer {

std::string gpu_binding_defines() {
    std::string s;
    // Binding points are plain ints (layout qualifiers), decisions uints.
    auto def = [&](const char* name, unsigned v) { s += fmt::format("#define {} {}\n", name, v); };
    auto def_uint = [&](const char* name, unsigned v) { s += fmt::format("#define {} {}u\n", name, v); };
    def("BINDING_BLOCKS", binding::kBlocks);
    def("BINDING_BLOCK_FIBER", binding::kBlockFiber);
    def("BINDING_FIBER_POINTS", binding::kFiberPoints);
    def("BINDING_FIBER_ENDS", binding::kFiberEnds);
    def("BINDING_FINE_LIST", binding::kFineList);
    def("BINDING_COARSE_LIST", binding::kCoarseList);
    def("BINDING_COUNTERS", binding::kCounters);
    def("BINDING_POINTS", binding::kPoints);
    def("BINDING_DECISIONS", binding::kDecisions);
    def("BINDING_FIBER_END_FRACTION", binding::kFiberEndFraction);
    def("BINDING_GLYPH_COEFFICIENTS", binding::kGlyphCoefficients);
    def("BINDING_GLYPH_CENTERS", binding::kGlyphCenters);
    def("BINDING_TANGENTS", binding::kTangents);
    def("BINDING_TUBE_PIECES", binding::kTubePieces);
    def("BINDING_FIBER_COLORS", binding::kFiberColors);
    def("BINDING_FIBER_RADII", binding::kFiberRadii);
    def("BINDING_CHUNK_KEYS", binding::kChunkKeys);
    def("BINDING_CHUNK_HISTOGRAM", binding::kChunkHistogram);
    def("BINDING_SORTED_CHUNKS", binding::kSortedChunks);
    def("BINDING_SORTED_BLOCKS", binding::kSortedBlocks);
    def("BINDING_VOXLINE_SEGMENTS", binding::kVoxlineSegments);
    def("BINDING_VOXLINE_ORDERS", binding::kVoxlineOrders);
    def("BINDING_LOCAL_FRAMES", binding::kLocalFrames);
    def("BINDING_WIDE_FRAMES", binding::kWideFrames);
    def("BINDING_POINT_VALUES", binding::kPointValues);
    def_uint("DECISION_OUTSIDE_FRUSTUM", unsigned(BlockDecision::outside_frustum));
    def_uint("DECISION_COARSE", unsigned(BlockDecision::coarse));
    def_uint("DECISION_FINE", unsigned(BlockDecision::fine));
    def_uint("DECISION_NOT_SELECTED", unsigned(BlockDecision::not_selected));
    return s;
}

}  // namespace fiblet::viewer
