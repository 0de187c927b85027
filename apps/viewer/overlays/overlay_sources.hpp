// What the command line asks to draw over the fibers (--odf, --image,
// --slab) and the overlays made from it once a GL context exists (render
// and view share this).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "overlays/image_slice_spec.hpp"
#include "overlays/overlay.hpp"
#include "overlays/sh_basis/sh_basis.hpp"
#include "render/render_options.hpp"

namespace fiblet::viewer {

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

// Reads the images and makes the overlays (slice first, then glyphs), and
// sets options.slab_* for --slab. Throws fiblet::Error (reading the
// images, invalid_argument for slices outside them or --slab without one).
std::vector<std::shared_ptr<Overlay>> make_overlays(const OverlaySources& sources, RenderOptions& options);

}  // namespace fiblet::viewer
