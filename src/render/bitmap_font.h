// A 5 x 7 pixel bitmap font for text drawn over images (annotation labels): printable ASCII, the degree
// sign and the superscript two; anything else draws as '?'. Each glyph sits in a 6 x 9 cell (one column
// of spacing, one row above and below), drawn at an integer scale.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace pointrast {

inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7;
inline constexpr int kGlyphCellWidth = 6, kGlyphCellHeight = 9;

// The 7 rows of a glyph, top first; bit 4 of a row is its leftmost pixel.
struct Glyph {
  uint8_t rows[kGlyphHeight];
  bool pixel(int x, int y) const { return (rows[y] >> (kGlyphWidth - 1 - x)) & 1; }
};

// The glyphs of a UTF-8 text, one per character ('\n' included as a line break marker: index kNewline).
inline constexpr uint32_t kNewline = 0xFFFFFFFFu;
std::vector<uint32_t> decodeText(std::string_view utf8);
// The glyph of a code point (the '?' glyph for one the font lacks).
const Glyph& glyph(uint32_t codePoint);

// Size in pixels of the text's cells at scale 1: the longest line's cells x the lines.
struct TextSize {
  int width = 0, height = 0;
};
TextSize textSize(std::string_view utf8);

} // namespace pointrast
