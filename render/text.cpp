#include "render/text.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "render/font5x7.h"
#include "render/renderer.h"

#ifdef ODEMAG_HAVE_FREETYPE
#include <ft2build.h>
#include FT_FREETYPE_H
#endif

namespace odemag {
namespace {

// UTF-8 to code points; a malformed byte gives U+FFFD.
std::u32string decode_utf8(const std::string& s) {
  std::u32string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    int extra = 0;
    char32_t cp = 0;
    if (b < 0x80) {
      cp = b;
    } else if ((b & 0xe0) == 0xc0) {
      cp = b & 0x1f, extra = 1;
    } else if ((b & 0xf0) == 0xe0) {
      cp = b & 0x0f, extra = 2;
    } else if ((b & 0xf8) == 0xf0) {
      cp = b & 0x07, extra = 3;
    } else {
      out.push_back(0xfffd);
      ++i;
      continue;
    }
    bool ok = i + static_cast<std::size_t>(extra) < s.size();
    for (int k = 1; ok && k <= extra; ++k) {
      const auto c = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      if ((c & 0xc0) != 0x80) ok = false;
      else cp = (cp << 6) | (c & 0x3f);
    }
    if (!ok) {
      out.push_back(0xfffd);
      ++i;
      continue;
    }
    out.push_back(cp);
    i += static_cast<std::size_t>(extra) + 1;
  }
  return out;
}

std::string encode_utf8(const std::u32string& s) {
  std::string out;
  for (char32_t cp : s) {
    if (cp < 0x80) {
      out.push_back(static_cast<char>(cp));
    } else if (cp < 0x800) {
      out.push_back(static_cast<char>(0xc0 | (cp >> 6)));
      out.push_back(static_cast<char>(0x80 | (cp & 0x3f)));
    } else if (cp < 0x10000) {
      out.push_back(static_cast<char>(0xe0 | (cp >> 12)));
      out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3f)));
      out.push_back(static_cast<char>(0x80 | (cp & 0x3f)));
    } else {
      out.push_back(static_cast<char>(0xf0 | (cp >> 18)));
      out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3f)));
      out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3f)));
      out.push_back(static_cast<char>(0x80 | (cp & 0x3f)));
    }
  }
  return out;
}

// What the 5x7 font can show of a string: one char per code point.
std::string to_ascii(const std::u32string& s) {
  std::string out;
  for (char32_t cp : s) out.push_back(cp >= 0x20 && cp < 0x7f ? static_cast<char>(cp) : '?');
  return out;
}

#ifdef ODEMAG_HAVE_FREETYPE
std::uint8_t channel(float v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}
#endif

}  // namespace

#ifdef ODEMAG_HAVE_FREETYPE
std::string text_font_file() { return ODEMAG_FONT_FILE; }
#else
std::string text_font_file() { return ""; }
#endif

struct TextFont::Impl {
  int pixel_size = 9;
  int scale = 1;  // bitmap fallback
  int ascent = 7, descent = 1, line_height = 9;
#ifdef ODEMAG_HAVE_FREETYPE
  struct Glyph {
    FT_UInt index = 0;
    int left = 0, top = 0, w = 0, h = 0, advance = 0;
    std::vector<std::uint8_t> coverage;  // w x h, top row first
  };
  FT_Library library = nullptr;
  FT_Face face = nullptr;
  bool kerning = false;
  mutable std::unordered_map<char32_t, Glyph> glyphs;

  ~Impl() {
    if (face != nullptr) FT_Done_Face(face);
    if (library != nullptr) FT_Done_FreeType(library);
  }

  bool open() {
    if (FT_Init_FreeType(&library) != 0) {
      library = nullptr;
      return false;
    }
    if (FT_New_Face(library, ODEMAG_FONT_FILE, 0, &face) != 0) {
      face = nullptr;
      return false;
    }
    if (FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixel_size)) != 0) return false;
    const FT_Size_Metrics& m = face->size->metrics;
    ascent = static_cast<int>((m.ascender + 63) >> 6);
    descent = static_cast<int>((-m.descender + 63) >> 6);
    line_height = std::max(ascent + descent, static_cast<int>((m.height + 63) >> 6));
    kerning = FT_HAS_KERNING(face);
    return true;
  }

  const Glyph& glyph(char32_t cp) const {
    const auto found = glyphs.find(cp);
    if (found != glyphs.end()) return found->second;
    Glyph g;
    FT_UInt index = FT_Get_Char_Index(face, cp);
    if (index == 0 && cp != U'?') return glyph(U'?');
    if (FT_Load_Glyph(face, index, FT_LOAD_RENDER | FT_LOAD_TARGET_LIGHT) == 0) {
      const FT_GlyphSlot slot = face->glyph;
      const FT_Bitmap& bm = slot->bitmap;
      g.index = index;
      g.left = slot->bitmap_left;
      g.top = slot->bitmap_top;
      g.advance = static_cast<int>((slot->advance.x + 32) >> 6);
      if (bm.pixel_mode == FT_PIXEL_MODE_GRAY && bm.buffer != nullptr) {
        g.w = static_cast<int>(bm.width);
        g.h = static_cast<int>(bm.rows);
        g.coverage.resize(static_cast<std::size_t>(g.w) * static_cast<std::size_t>(g.h));
        const int levels = std::max(1, bm.num_grays - 1);
        for (int r = 0; r < g.h; ++r) {
          const unsigned char* row = bm.buffer + static_cast<std::ptrdiff_t>(r) * bm.pitch;
          for (int c = 0; c < g.w; ++c)
            g.coverage[static_cast<std::size_t>(r * g.w + c)] = static_cast<std::uint8_t>(row[c] * 255 / levels);
        }
      }
    }
    return glyphs.emplace(cp, std::move(g)).first->second;
  }

  int kern(FT_UInt previous, FT_UInt next) const {
    if (!kerning || previous == 0 || next == 0) return 0;
    FT_Vector d{0, 0};
    if (FT_Get_Kerning(face, previous, next, FT_KERNING_DEFAULT, &d) != 0) return 0;
    return static_cast<int>(d.x >> 6);
  }
#endif
  bool ft() const {
#ifdef ODEMAG_HAVE_FREETYPE
    return face != nullptr;
#else
    return false;
#endif
  }
};

TextFont::TextFont(int pixel_size) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.pixel_size = std::clamp(pixel_size, 4, 512);
  m.scale = std::max(1, static_cast<int>(std::lround(m.pixel_size / 9.0)));
#ifdef ODEMAG_HAVE_FREETYPE
  if (m.open()) return;
  // The font did not load: fall back to the bitmap font.
  if (m.face != nullptr) FT_Done_Face(m.face);
  m.face = nullptr;
#endif
  m.ascent = font5x7::kGlyphHeight * m.scale;
  m.descent = m.scale;
  m.line_height = font5x7::kLineHeight * m.scale;
}

TextFont::~TextFont() = default;
TextFont::TextFont(TextFont&&) noexcept = default;
TextFont& TextFont::operator=(TextFont&&) noexcept = default;

bool TextFont::freetype() const { return impl_->ft(); }
int TextFont::pixel_size() const { return impl_->pixel_size; }
int TextFont::ascent() const { return impl_->ascent; }
int TextFont::descent() const { return impl_->descent; }
int TextFont::line_height() const { return impl_->line_height; }

int TextFont::width_of(const std::string& text) const {
  const Impl& m = *impl_;
  const std::u32string cps = decode_utf8(text);
  if (!m.ft()) {
    if (cps.empty()) return 0;
    return static_cast<int>(cps.size()) * font5x7::kAdvance * m.scale - m.scale;
  }
  int x = 0;
#ifdef ODEMAG_HAVE_FREETYPE
  unsigned previous = 0;
  for (char32_t cp : cps) {
    const auto& g = m.glyph(cp);
    x += m.kern(previous, g.index) + g.advance;
    previous = g.index;
  }
#endif
  return x;
}

int TextFont::draw(std::vector<std::uint8_t>& rgb, int width, int height, int x, int baseline,
                   const std::string& text, const RenderColor& color) const {
  const Impl& m = *impl_;
  if (width <= 0 || height <= 0 ||
      rgb.size() < static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    return x;
  const std::u32string cps = decode_utf8(text);
  if (!m.ft()) {
    return draw_text_rgb(rgb, width, height, x, baseline - font5x7::kGlyphHeight * m.scale, to_ascii(cps), color,
                         m.scale);
  }
#ifdef ODEMAG_HAVE_FREETYPE
  const int c[3] = {channel(color[0]), channel(color[1]), channel(color[2])};
  unsigned previous = 0;
  for (char32_t cp : cps) {
    const auto& g = m.glyph(cp);
    x += m.kern(previous, g.index);
    previous = g.index;
    const int x0 = x + g.left, y0 = baseline - g.top;
    for (int r = 0; r < g.h; ++r) {
      const int py = y0 + r;
      if (py < 0 || py >= height) continue;
      for (int col = 0; col < g.w; ++col) {
        const int px = x0 + col;
        if (px < 0 || px >= width) continue;
        const int a = g.coverage[static_cast<std::size_t>(r * g.w + col)];
        if (a == 0) continue;
        std::uint8_t* dst =
            rgb.data() + (static_cast<std::size_t>(py) * static_cast<std::size_t>(width) + static_cast<std::size_t>(px)) * 3;
        for (int k = 0; k < 3; ++k) dst[k] = static_cast<std::uint8_t>((dst[k] * (255 - a) + c[k] * a + 127) / 255);
      }
    }
    x += g.advance;
  }
#endif
  return x;
}

std::vector<std::string> TextFont::wrap(const std::string& text, int max_width) const {
  max_width = std::max(1, max_width);
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string paragraph = text.substr(start, end - start);
    start = end + 1;
    // Words of the paragraph, greedily filled into lines.
    std::string current;
    std::size_t i = 0;
    bool any = false;
    while (i < paragraph.size()) {
      if (paragraph[i] == ' ') {
        ++i;
        continue;
      }
      const std::size_t j = std::min(paragraph.find(' ', i), paragraph.size());
      std::string word = paragraph.substr(i, j - i);
      i = j;
      const std::string candidate = current.empty() ? word : current + " " + word;
      if (width_of(candidate) <= max_width) {
        current = candidate;
        continue;
      }
      if (!current.empty()) lines.push_back(current), any = true;
      current.clear();
      // A word wider than a line: break it where it fills the line.
      std::u32string rest = decode_utf8(word);
      while (rest.size() > 1 && width_of(encode_utf8(rest)) > max_width) {
        std::size_t n = 1;
        while (n + 1 < rest.size() && width_of(encode_utf8(rest.substr(0, n + 1))) <= max_width) ++n;
        lines.push_back(encode_utf8(rest.substr(0, n)));
        any = true;
        rest = rest.substr(n);
      }
      current = encode_utf8(rest);
    }
    if (!current.empty() || !any) lines.push_back(current);
    if (end == text.size()) break;
  }
  return lines;
}

bool text_uses_freetype() {
  static const bool available = TextFont(12).freetype();
  return available;
}

}  // namespace odemag
