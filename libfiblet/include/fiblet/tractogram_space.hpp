// fiblet — the reference image space of a tractogram (.trk and TRX headers):
// the voxel-to-RAS+ affine, the grid dimensions, voxel sizes and order.
//
// Points are always kept in world RAS+ millimetres (as .tck and TRX store
// them); the space only matters to write a .trk (which stores "voxmm"
// coordinates) and to give a .trk or TRX back the header it came with. It
// travels through a .fft as PROP properties (formats/fft-space.md).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fiblet {

using Affine = std::array<double, 16>;  // 4x4, row-major

inline constexpr Affine kIdentityAffine{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

struct TractogramSpace {
    Affine voxel_to_rasmm = kIdentityAffine;
    std::array<int, 3> dimensions{1, 1, 1};
    std::array<double, 3> voxel_sizes{1, 1, 1};
    std::string voxel_order = "RAS";  // three of L/R, P/A, I/S

    // A space from an affine alone (TRX): voxel sizes are the column norms,
    // the voxel order the affine's axis codes.
    static TractogramSpace from_affine(const Affine& a, std::array<int, 3> dimensions);
};

// The space of a reference image (NIfTI or .mif: its voxel-to-world
// affine, as MRtrix3 reads it, and its first three dimensions), the
// reference tckconvert and DIPY take for a .tck. Throws as read_image does.
TractogramSpace space_of_image(const std::string& path);

// The axis codes of an affine ("RAS", "LPS", ...), as nibabel's
// aff2axcodes; nullopt when the axes cannot be told apart.
std::optional<std::string> affine_axis_codes(const Affine& a);

// The affine that maps a .trk file's "voxmm" coordinates to RAS+ mm, as
// nibabel computes it (nibabel.streamlines.trk.get_affine_trackvis_to_rasmm):
// scale by 1/voxel size, shift by half a voxel (TrackVis puts 0 at a voxel's
// corner), reorient from the header's voxel order to the affine's, apply the
// affine; rounded to float32 as nibabel does. Throws Error{invalid_input}
// when the voxel order or the affine has no clear axes.
Affine trk_voxmm_to_rasmm(const TractogramSpace& s);
Affine affine_inverse(const Affine& a);  // throws Error{invalid_input} if singular

// PROP keys: "voxel_to_rasmm" (16 numbers, row-major), "dimensions",
// "voxel_sizes", "voxel_order".
void add_space_properties(std::vector<std::pair<std::string, std::string>>& properties, const TractogramSpace& s);
// The space stored by add_space_properties; nullopt when there is none
// (a .tck source). Throws Error{invalid_input} naming `name` on bad values.
std::optional<TractogramSpace> space_from_properties(
    const std::vector<std::pair<std::string, std::string>>& properties, const std::string& name);
bool is_space_property(const std::string& key) noexcept;

}  // namespace fiblet
