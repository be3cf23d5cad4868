// Text for odemag renderings: DejaVu Sans through FreeType, anti-aliased and
// blended into RGB8 images, when the build found both (render/
// CMakeLists.txt); otherwise the built-in 5x7 bitmap font (font5x7.h), which
// has printable ASCII only and no descenders.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "render/colors.h"

namespace odemag {

// True when TextFont draws with FreeType: the build has FreeType and the font
// file it found at configure time (text_font_file()) loads.
bool text_uses_freetype();
// The font file found at configure time; "" in a build without FreeType.
std::string text_font_file();

// One font at one pixel size. Strings are UTF-8; the bitmap fallback shows
// characters outside printable ASCII as '?'. Caches glyphs: use from one
// thread at a time.
class TextFont {
 public:
  // pixel_size: the em size in pixels (FreeType); the fallback draws the 5x7
  // font scaled by max(1, round(pixel_size / 9)).
  explicit TextFont(int pixel_size);
  ~TextFont();
  TextFont(TextFont&&) noexcept;
  TextFont& operator=(TextFont&&) noexcept;
  TextFont(const TextFont&) = delete;
  TextFont& operator=(const TextFont&) = delete;

  bool freetype() const;
  int pixel_size() const;
  int ascent() const;       // pixels above the baseline
  int descent() const;      // pixels below the baseline, >= 0
  int line_height() const;  // baseline to baseline

  // Advance width of one line, pixels.
  int width_of(const std::string& text) const;

  // Draws one line with its baseline at row `baseline`, starting at column x,
  // clipped to the width x height image (tightly packed RGB8, top row
  // first); glyph coverage is blended over what is there. Returns the x just
  // after the text.
  int draw(std::vector<std::uint8_t>& rgb, int width, int height, int x, int baseline,
           const std::string& text, const RenderColor& color) const;

  // Splits text into lines at most max_width pixels wide: at spaces, within
  // words longer than a line, and at '\n'. Never returns an empty vector for
  // non-empty text.
  std::vector<std::string> wrap(const std::string& text, int max_width) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace odemag
