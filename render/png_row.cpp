// Puts PNG images side by side on a white background, for the pictures in
// docs/images (docs/images/make_images.sh); no ImageMagick needed.
//
//   odemag_png_row OUTPUT.png INPUT.png... [--gap PIXELS]
//
// Images are top-aligned; the output is as tall as the tallest input.
// Exit status 0 on success, 1 when an input cannot be read or the output
// cannot be written, 2 on a usage error.
#include <png.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "render/png_writer.h"

namespace {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
};

// Any PNG libpng reads, as RGB8 composed over white.
bool read_rgb(const std::string& path, Image* image, std::string* error) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    *error = png.message;
    return false;
  }
  png.format = PNG_FORMAT_RGB;
  image->width = static_cast<int>(png.width);
  image->height = static_cast<int>(png.height);
  image->rgb.resize(PNG_IMAGE_SIZE(png));
  const png_color white{255, 255, 255};
  if (!png_image_finish_read(&png, &white, image->rgb.data(), 0, nullptr)) {
    *error = png.message;
    png_image_free(&png);
    return false;
  }
  return true;
}

int usage() {
  std::fprintf(stderr, "usage: odemag_png_row OUTPUT.png INPUT.png... [--gap PIXELS]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int gap = 4;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--gap") {
      if (i + 1 >= argc) return usage();
      char* end = nullptr;
      const long g = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || g < 0 || g > 1000) return usage();
      gap = static_cast<int>(g);
    } else if (a == "-h" || a == "--help") {
      usage();
      return 0;
    } else {
      paths.push_back(a);
    }
  }
  if (paths.size() < 2) return usage();
  std::vector<Image> images(paths.size() - 1);
  int width = 0, height = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    std::string error;
    if (!read_rgb(paths[i + 1], &images[i], &error)) {
      std::fprintf(stderr, "odemag_png_row: %s: %s\n", paths[i + 1].c_str(), error.c_str());
      return 1;
    }
    width += images[i].width + (i == 0 ? 0 : gap);
    height = std::max(height, images[i].height);
  }
  std::vector<std::uint8_t> out(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, 255);
  int x0 = 0;
  for (const Image& im : images) {
    for (int y = 0; y < im.height; ++y)
      std::memcpy(out.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x0)) * 3,
                  im.rgb.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) * 3,
                  static_cast<std::size_t>(im.width) * 3);
    x0 += im.width + gap;
  }
  std::string error;
  if (!odemag::write_png(paths[0], width, height, out, &error, 9)) {
    std::fprintf(stderr, "odemag_png_row: %s\n", error.c_str());
    return 1;
  }
  return 0;
}
