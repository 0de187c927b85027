#include "overlays/overlay_sources.hpp"

#include <algorithm>

#include "fiblet/error.hpp"
#include "overlays/image_slice/image_slice_overlay.hpp"
#include "overlays/odf_glyphs/glyph_set.hpp"
#include "overlays/odf_glyphs/odf_glyphs_overlay.hpp"
#include "render/vec_ops.hpp"

namespace fiblet::viewer {

std::vector<std::shared_ptr<Overlay>> make_overlays(const OverlaySources& s, RenderOptions& options) {
    std::vector<std::shared_ptr<Overlay>> overlays;
    std::optional<WorldPlane> plane;
    if (!s.image_path.empty()) {
        const Image image = read_image(s.image_path);
        const std::int64_t index = slice_index(s.image_slice, image, "--slice");
        overlays.push_back(std::make_shared<ImageSliceOverlay>(make_slice_image(image, s.image_slice.axis, index)));
        plane = slice_plane(image, s.image_slice.axis, index);
    }
    if (!s.odf_path.empty()) {
        const Image image = read_image(s.odf_path);
        GlyphSetOptions g;
        g.axis = s.odf_slice.axis;
        g.index = slice_index(s.odf_slice, image, "--odf-slice");
        g.lmax = s.odf_lmax, g.basis = s.sh_basis, g.scale = s.odf_scale;
        overlays.push_back(std::make_shared<OdfGlyphsOverlay>(make_glyph_set(image, g)));
        if (!plane) plane = slice_plane(image, g.axis, g.index);
    }
    if (s.slab_mm > 0) {
        if (!plane) throw Error(Errc::invalid_argument, "--slab needs a slice: --image or --odf");
        options.slab_plane = {float(plane->normal[0]), float(plane->normal[1]), float(plane->normal[2]), float(plane->offset)};
        options.slab_half_width_mm = 0.5f * s.slab_mm;
    }
    return overlays;
}

Camera clip_planes_covering(const Camera& camera, const std::vector<std::shared_ptr<Overlay>>& overlays) {
    const Vec3f forward = normalized(sub(camera.target, camera.position));
    float lo = camera.near_mm, hi = camera.far_mm;
    bool widened = false;
    for (const auto& overlay : overlays) {
        const auto box = overlay ? overlay->bounds() : std::nullopt;
        if (!box) continue;
        float nearest = 0, farthest = 0;
        for (int c = 0; c < 8; ++c) {
            const Vec3f corner{(*box)[c & 1].x, (*box)[(c >> 1) & 1].y, (*box)[(c >> 2) & 1].z};
            const float depth = dot(sub(corner, camera.position), forward);
            nearest = c == 0 ? depth : std::min(nearest, depth);
            farthest = c == 0 ? depth : std::max(farthest, depth);
        }
        if (!(farthest > 0)) continue;  // behind the camera
        // 0.1 % beyond the box, as set_clip_planes leaves 1 % around the fibers.
        if (farthest * 1.001f > hi) hi = farthest * 1.001f, widened = true;
        if (nearest * 0.999f < lo) lo = nearest * 0.999f, widened = true;
    }
    if (!widened) return camera;
    Camera c = camera;
    c.far_mm = hi;
    c.near_mm = std::min(camera.near_mm, std::max(lo, 1e-4f * hi));
    return c;
}

}  // namespace fiblet::viewer
