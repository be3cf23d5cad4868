// Built-in 5x7 bitmap font for printable ASCII (0x20..0x7e), drawn by hand:
// frame captions in builds without FreeType (render/text.h).
#pragma once

#include <array>
#include <cstdint>

namespace odemag::font5x7 {

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kAdvance = 6;      // glyph width plus one column of spacing
inline constexpr int kLineHeight = 9;   // glyph height plus two rows of spacing

// Rows top to bottom; bit 4 of each row is the leftmost column. Characters
// outside printable ASCII give the glyph of '?'.
const std::array<std::uint8_t, kGlyphHeight>& glyph(char c);

}  // namespace odemag::font5x7
