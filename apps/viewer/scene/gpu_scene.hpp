// A .fft file on the GPU: its blocks uploaded as fiblet's reader holds them
// (8-bit: as in the file, 76 bytes each for 60 points; 16-bit: version 16's
// fixed-size layout, version 17's packed blocks expanded to it; never decoded
// on the CPU), the local frames of its direction code (256, or 181^2 / 256^2
// for 16-bit codes), and small tables built from the fiber LUT (fiber of
// each block, points of each fiber). The last point of every fiber, which the
// level of detail needs, is decoded once on the GPU at load.
//
// A scene holds every fiber of its file, or a subset of them (a file larger
// than the GPU memory budget: scene/fiber_streaming.hpp chooses which).
// Fiber indices are the scene's (0..fiber_count()); file_fiber() maps them
// to the file's, which every input and output of the viewer uses.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "fiblet_viewer/gpu_decoder.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/geometry.hpp"
#include "gl/gl_objects.hpp"
#include "scene/gpu_programs.hpp"

namespace fiblet {
class BlockIndex;  // fiblet/block_index.hpp
}

namespace fiblet::viewer {

// An axis-aligned box around every block's bounding sphere (world mm).
struct SceneBounds {
    Vec3f min{-1, -1, -1}, max{1, 1, 1};
    Vec3f center() const { return {(min.x + max.x) / 2, (min.y + max.y) / 2, (min.z + max.z) / 2}; }
    float radius() const;  // of the sphere around the box
};

// Some of a file's fibers: their file indices (ascending, no repeats) and
// the file's block index, which gives every fiber's point count without
// reading its blocks.
struct FiberSubset {
    std::vector<std::uint64_t> fibers;
    std::shared_ptr<const BlockIndex> index;
};

class GpuScene {
public:
    // Reads and validates the blocks of every fiber, or of `subset`'s, (point
    // counts) and uploads them; `decoder` (default: default_decoder())
    // decodes the fibers' last points. Throws fiblet::Error{fft_format} on
    // bad blocks, {unsupported} when the blocks exceed the driver's largest
    // storage buffer.
    GpuScene(const FftFile& file, const GpuPrograms& programs, std::optional<GpuDecoder> decoder = {},
             std::optional<FiberSubset> subset = {});
    // A scene of the same file holding `subset`'s fibers (every fiber
    // without one), with `attributes_of`'s colours, opacities, radii and
    // point values.
    GpuScene(const GpuScene& attributes_of, const FftFile& file, const GpuPrograms& programs,
             std::optional<FiberSubset> subset);
    // Holds `subset`'s fibers instead (every fiber without one), keeping the
    // colours, opacities, radii and point values set so far; a new
    // generation(). `file` is the scene's file.
    void reside(const FftFile& file, const GpuPrograms& programs, std::optional<FiberSubset> subset);
    // Changes with every reside() and differs between scenes: what caches
    // built from a scene's blocks compare.
    std::uint64_t generation() const { return generation_; }

    const FftHeader& header() const { return header_; }
    std::uint32_t block_count() const { return std::uint32_t(block_points_.size()); }
    std::uint64_t fiber_count() const { return fiber_ids_.size(); }
    // The file's fibers: how many, whether the scene holds them all, the
    // file index of scene fiber `index`, and the scene indices of file
    // fibers (those held, ascending).
    std::uint64_t file_fiber_count() const { return header_.fibers; }
    bool holds_every_fiber() const { return !index_; }
    std::uint64_t file_fiber(std::uint64_t index) const { return index_ ? file_fibers_[index] : index; }
    std::vector<std::uint32_t> scene_fibers(const std::vector<std::uint32_t>& file_indices) const;
    std::uint64_t segment_count() const { return segments_; }  // of all fibers, drawn in full
    // Around the fibers; a scene holding part of a file: the file's (its
    // block index's boxes), so that cameras and grids fitted to the part hold
    // every fiber of the file.
    const SceneBounds& bounds() const { return bounds_; }
    // First points of the blocks (all of them, or an even sample of 65536),
    // world mm: what a camera fits to frame the fibers rather than their box.
    const std::vector<Vec3f>& sample_points() const { return sample_points_; }

    // Scene fiber `index`: its ID as stored in its blocks, its number of
    // points and its nominal length: (points - 1) steps, the last one
    // shortened to the fiber's true end (ENDS chunk).
    std::uint32_t fiber_id(std::uint64_t index) const { return fiber_ids_[index]; }
    std::uint32_t fiber_points(std::uint64_t index) const { return fiber_points_[index]; }
    // Points held by block `b` (its flags, validated at load).
    std::uint32_t block_points(std::uint32_t b) const { return block_points_[b]; }
    double fiber_length_mm(std::uint64_t index) const;

    // Binds the scene's buffers to their binding points and sets the scene
    // uniforms (scene_buffers.glsl) of `program`.
    void bind(const GlProgram& program) const;

    // The attributes below are given for every fiber or point of the file
    // (file order) and hold for the fibers the scene holds.
    // Per-fiber colours (fiber_colors.hpp; one per fiber, file order) for
    // RenderOptions::fiber_colors. Throws fiblet::Error{invalid_argument}
    // on a count that is not file_fiber_count().
    void set_fiber_colors(const std::vector<std::array<float, 3>>& rgb);
    bool has_fiber_colors() const { return has_fiber_colors_; }
    // Per-fiber opacities in [0, 1] (one per fiber) for
    // RenderOptions::fiber_opacity: kept in the colours buffer's alpha
    // (fiber_colors.glsl), so they need no binding of their own. Throws
    // fiblet::Error{invalid_argument} on a count that is not
    // file_fiber_count() or a value outside [0, 1].
    void set_fiber_opacities(const std::vector<float>& alpha);
    bool has_fiber_opacities() const { return has_fiber_opacities_; }
    // Per-fiber tube radii in mm (> 0, one per fiber) for
    // RenderOptions::fiber_radii; throws fiblet::Error{invalid_argument}.
    void set_fiber_radii(const std::vector<float>& mm);
    bool has_fiber_radii() const { return !fiber_radii_mm_.empty(); }
    float min_fiber_radius() const { return min_radius_; }
    float max_fiber_radius() const { return max_radius_; }

    // Per-point values (point_values.hpp; every point of every fiber, file
    // order) for RenderOptions::point_values, uploaded beside the blocks:
    // point k of block b in slot b * pointsPerBlock + k (point_values.glsl).
    // Throws fiblet::Error{invalid_argument} on a count that is not the
    // file's point count.
    void set_point_values(std::vector<float> values);
    bool has_point_values() const { return has_point_values_; }
    std::array<float, 2> point_value_range() const { return point_value_range_; }  // min, max
    // Points of every fiber of the file.
    std::vector<std::uint32_t> file_fiber_point_counts() const;

    // GPU memory the scene's buffers hold.
    std::uint64_t gpu_bytes() const;

    // The last point of every fiber as decoded on the GPU at load (world mm).
    std::vector<Vec3f> read_fiber_ends() const;

private:
    void make_constant_buffers();
    void load_geometry(const FftFile& file, const GpuPrograms& programs);
    void upload_attributes();
    std::vector<float> held_fiber_values(const std::vector<float>& per_file_fiber, std::size_t width) const;
    void upload_point_values();

    FftHeader header_;
    GpuDecoder decoder_;
    std::uint64_t generation_ = 0;
    std::vector<std::uint64_t> file_fibers_;      // with a subset: scene fiber -> file fiber
    std::shared_ptr<const BlockIndex> index_;     // with a subset (null: every fiber): the file's point counts
    std::vector<std::uint32_t> fiber_ids_, fiber_points_;
    std::vector<std::uint16_t> block_points_;
    std::uint64_t segments_ = 0;
    SceneBounds bounds_;
    std::vector<Vec3f> sample_points_;
    GlBuffer blocks_, block_fiber_, fiber_points_buffer_, fiber_ends_, fiber_end_fraction_, local_frames_;
    std::vector<float> end_fraction_;  // per fiber, kept part of the last step (ENDS chunk; 1 without)
    GlBuffer fiber_colors_;            // one vec4 when there are neither colours nor opacities (a binding must hold a buffer)
    std::vector<float> fiber_rgba_;    // per file fiber: colour (white without) and opacity (1 without)
    bool has_fiber_colors_ = false, has_fiber_opacities_ = false;
    GlBuffer point_values_;            // one float when there are none
    std::vector<float> file_point_values_;  // every point of the file
    bool has_point_values_ = false;
    std::array<float, 2> point_value_range_{0, 1};
    GlBuffer fiber_radii_;             // one float when there are none
    std::vector<float> fiber_radii_mm_;     // per file fiber
    float min_radius_ = 0, max_radius_ = 0;
};

// Largest shader storage buffer of the current context, in bytes.
std::uint64_t max_storage_buffer_bytes();

}  // namespace fiblet::viewer
