// Ambient occlusion for the rasterized styles (--ao with the raster
// engine): a volume built from one chord per block (chord_occlusion.hpp),
// sampled trilinearly half a voxel out along the surface's normal (zero for
// lines, which have none).
layout(binding = 7) uniform sampler3D uOcclusionVolume;
uniform bool uOcclusionOn;
uniform vec3 uOcclusionOrigin;  // world mm of the grid's corner
uniform float uOcclusionVoxelMm;
uniform float uOcclusionGridN;

float rasterOcclusion(vec3 world, vec3 outward) {
    if (!uOcclusionOn) return 0.0;
    vec3 g = (world - uOcclusionOrigin) / uOcclusionVoxelMm + 0.5 * outward;
    return texture(uOcclusionVolume, g / uOcclusionGridN).r;
}
