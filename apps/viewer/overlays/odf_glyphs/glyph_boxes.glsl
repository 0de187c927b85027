// Per glyph: its centre (world mm) and bounding radius (mm, one glyph unit),
// and the half sizes of its box in glyph units (GlyphSet::extents).
struct GlyphBox {
    vec4 centerRadius;
    vec4 extents;
};
layout(std430, binding = BINDING_GLYPH_CENTERS) readonly buffer GlyphBoxes { GlyphBox glyphBoxes[]; };
