#include "voxel_rt/voxel_rt_bindings.hpp"

#include <fmt/core.h>

#include "gl/gpu_bindings.hpp"
#include "voxel_rt/voxel_pyramid.hpp"

namespace fiblet::viewer::voxel_rt {

std::string voxel_rt_defines() {
    std::string s = gpu_binding_defines();
    auto def = [&](const char* name, unsigned v) { s += fmt::format("#define {} {}\n", name, v); };
    def("BINDING_VRT_POINTS", binding::kPoints);
    def("BINDING_VRT_CELLS", binding::kCells);
    def("BINDING_VRT_OFFSETS", binding::kOffsets);
    def("BINDING_VRT_FRAGMENTS", binding::kFragments);
    def("BINDING_VRT_CURSOR", binding::kCursor);
    def("BINDING_VRT_CHUNKS", binding::kChunks);
    def("BINDING_VRT_SOLID", binding::kSolid);
    def("BINDING_VRT_VISIBLE", binding::kVisible);
    def("VRT_FRAGMENT_UNIT", binding::kFragmentUnit);
    def("VRT_OCCUPIED_UNIT", binding::kOccupiedUnit);
    def("VRT_PYRAMID_LEVELS", unsigned(kMaxPyramidLevels));
    for (unsigned part = 1; part < binding::kPointParts; ++part)
        s += fmt::format("#define BINDING_VRT_POINTS{} {}\n", part, binding::kMorePoints + part - 1);
    return s;
}

}  // namespace fiblet::viewer::voxel_rt
