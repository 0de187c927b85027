// ODF glyphs of a GlyphSet, ray cast in their bounding boxes (glyph_ray.*):
// an overlay of the fibers' frame.
#pragma once

#include "gl/gl_objects.hpp"
#include "overlays/odf_glyphs/glyph_set.hpp"
#include "overlays/overlay.hpp"

namespace fiblet::viewer {

// The root finder's step tolerance in glyph units (the bounding radius is 1).
inline constexpr float kGlyphRootTolerance = 1e-6f;

class OdfGlyphsOverlay final : public Overlay {
public:
    explicit OdfGlyphsOverlay(const GlyphSet& glyphs);
    void draw(const Camera& camera, const RenderOptions& options) override;
    std::optional<std::array<Vec3f, 2>> bounds() const override { return bounds_; }
    std::size_t glyph_count() const { return glyphs_; }

private:
    std::optional<std::array<Vec3f, 2>> bounds_;  // the glyphs' boxes; nothing without glyphs
    GlProgram program_;
    GlBuffer coefficients_, centers_;
    std::size_t glyphs_ = 0;
    int lmax_ = 0, coefficients_per_glyph_ = 1;
};

}  // namespace fiblet::viewer
