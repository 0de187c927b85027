// What a scene is drawn with besides its file's fibers, as the command line
// names it: where the per-fiber colours come from (scene/fiber_colors.hpp
// reads them) and what is drawn over the fibers (--odf, --image, --slab;
// overlays/overlay_sources.hpp makes the overlays once a GL context exists).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace fiblet::viewer {

// Where a scene's per-fiber colours come from (at most one source): a text
// file, or for values "dps/NAME", the file's own per-streamline data; or
// per-point values (point_values_path: a .tsf or "dpv/NAME").
struct FiberColorSource {
    std::string colors_path, values_path;
    std::optional<std::array<float, 2>> value_range;
    std::string point_values_path;
    bool empty() const { return colors_path.empty() && values_path.empty() && point_values_path.empty(); }
};

// Whether a values source is such a name ("dps/" and more); a file of that
// name, when one exists, is read instead.
bool is_data_field_name(const std::string& values);

// The SH basis of an --odf image (overlays/sh_basis/sh_basis.hpp).
enum class ShBasis { mrtrix, descoteaux07 };
std::optional<ShBasis> parse_sh_basis(const std::string& name);  // "mrtrix" (or "tournier"), "descoteaux07"

inline constexpr int kMaxShLmax = 12;

// A slice of an image's voxel grid, "axis:index" on the command line (axis
// x, y or z of the voxel grid, or 0, 1, 2; overlays/image_slice_spec.hpp).
struct SliceSpec {
    int axis = 2;             // voxel axis across the slice
    std::int64_t index = -1;  // voxel index along it; -1: the middle
};

// Parses "axis:index" (or "axis" alone: the middle slice); throws
// fiblet::Error{invalid_argument} naming `option`.
SliceSpec parse_slice_spec(const std::string& text, const char* option);

struct OverlaySources {
    std::string odf_path;  // SH image: glyphs
    SliceSpec odf_slice;
    float odf_scale = 1;
    int odf_lmax = -1;  // -1: the image's
    ShBasis sh_basis = ShBasis::mrtrix;
    std::string image_path;  // background slice
    SliceSpec image_slice;
    float slab_mm = 0;  // fibers within slab_mm / 2 of the slice (the image's, else the glyphs'); 0: all
    bool any() const { return !odf_path.empty() || !image_path.empty(); }
};

}  // namespace fiblet::viewer
