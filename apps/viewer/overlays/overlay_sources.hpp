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
#include "fiblet_viewer/render_options.hpp"
#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet::viewer {

// Reads the images and makes the overlays (slice first, then glyphs), and
// sets options.slab_* for --slab. Throws fiblet::Error (reading the
// images, invalid_argument for slices outside them or --slab without one).
std::vector<std::shared_ptr<Overlay>> make_overlays(const OverlaySources& sources, RenderOptions& options);

}  // namespace fiblet::viewer
