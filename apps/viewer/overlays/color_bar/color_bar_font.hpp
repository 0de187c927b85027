// A 3x5-pixel bitmap font for the colour bar's labels: digits, letters
// (lower case drawn as capitals), and . - + _ / : and space. A glyph is 15
// bits, row 0 (top) in bits 14..12, the left column highest.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fiblet::viewer {

// The glyph of `c` (0 for a character the font lacks: a blank cell).
std::uint32_t glyph_bits(char c);

// `text`'s glyphs, one per character.
std::vector<std::uint32_t> glyph_line(const std::string& text);

}  // namespace fiblet::viewer
