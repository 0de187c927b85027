// The voxel ray tracer's GL programs, compiled once per engine.
#pragma once

#include "gl/gl_objects.hpp"

namespace fiblet::viewer::voxel_rt {

struct VoxelRtPrograms {
    // Throws fiblet::Error{unsupported} when the context lacks the storage
    // buffer bindings the module uses, or with the driver's log.
    VoxelRtPrograms();

    GlProgram voxelize;           // voxelize_capsules.comp.glsl (counts + occupancy, then fragment lists)
    GlProgram scan;               // scan_counts.comp.glsl
    GlProgram occupancy;          // occupancy_volume.comp.glsl
    GlProgram ambient_occlusion;  // ambient_occlusion.comp.glsl
    GlProgram trace;              // full_screen.vert.glsl + trace.frag.glsl
    GlProgram cull;               // cull_voxels.comp.glsl
    GlProgram occupied_pyramid;   // occupied_pyramid.comp.glsl (empty-space skipping)
    GlProgram chords;             // chord_segments.comp.glsl (occlusion without decoding)
};

}  // namespace fiblet::viewer::voxel_rt
